"""Stock 2-D transfer function of ParaView's Volume representation on a Space Skipping Volume:
Use Transfer 2D with a Transfer Function 2D box (value x gradient magnitude; ParaView's default
Use Gradient For Transfer 2D) on a float copy of the bundled shell. Turning it on changes the image
as it does for ParaView's own Volume, and the two representations agree (PSNR >= 40 dB) with it
off and on, for ParaView's default 10x10 function image and a finer one; every builder keeps
Naive's image with it on. Then a second array as the y axis (Use Gradient For Transfer 2D off,
Color Array 2 = a ramp along the shell's first axis): the same checks against ParaView's Volume."""
from paraview.simple import *
import ssptest

ssptest.load_plugin()
ok = ssptest.Checker()
view = ssptest.make_view(size=(240, 240))
# A 2-D function's opacity is per sample (VTK corrects it not for the sample distance), so the
# image depends on the sample distance itself: both at ParaView's Volume's (stock_sample_distance).
disp = ssptest.show_float_shell_vs_stock(view, 0.5, second="coordsX")
stock_distance = ssptest.stock_sample_distance()
disp.Shade = 0

tf2d = GetTransferFunction2D(ssptest.ARRAY)
disp.TransferFunction2D = tf2d
# x over the data's scalar range, y over the gradient magnitude up to a quarter of it (the range
# vtkGPUVolumeRayCastMapper normalises the magnitude with).
tf2d.AutomaticRescaleRangeMode = "Never"
tf2d.Range = [0.0, 255.0, 0.0, 63.75]
# One box: values 40..255 at gradient magnitudes from 30 per voxel up, orange, opacity 0.6. A box
# whose gradient edge lies below 20 per voxel agrees less on this steep shell (35.6 dB in an older
# run; 40.1 dB on 2026-11-29 with the stock Volume on Mesa and on NVIDIA's GL alike, so not the
# reference renderer's doing; cause not established): it is measured and printed below, not checked.
box = [40.0, 30.0, 215.0, 60.0, 1.0, 0.6, 0.2, 0.6]
tf2d.Boxes = box
tf2d.SMProxy.InvokeCommand("Build")  # what the GUI's 2-D editor does after an edit


versus = ssptest.VersusStock(view, disp, ok, "transfer2d")
shoot, both, changes = versus.shoot, versus.both, versus.changes


disp.UseTransfer2D = 0
off = both("off")
# With our default sample distance (half the smallest spacing) instead: measured, not checked.
disp.UseTransfer2D = 1
disp.SampleDistance = 0
default_distance = ssptest.psnr(shoot("on-default-distance", "Space Skipping Volume"),
                                shoot("on-default-distance", "Volume"))
print("2-D on with our default sample distance: PSNR vs Volume %.2f dB (the stock samples every "
      "%.4f)" % (default_distance, stock_distance))
disp.SetRepresentationType("Space Skipping Volume")
disp.SampleDistance = stock_distance
disp.UseTransfer2D = 0
warnings = ssptest.WarningCapture()
disp.UseTransfer2D = 1
disp.UseGradientForTransfer2D = 1
on = both("on-10x10")
changes("Use Transfer 2D", off, on)
tf2d.OutputDimensions = [64, 48]
tf2d.SMProxy.InvokeCommand("Build")
fine = both("on-64x48")
changes("a 64x48 function image instead of 10x10", on, fine, max_psnr=50.0)
disp.Shade = 1
disp.Ambient = 0.2
disp.Diffuse = 0.7
disp.Specular = 0.3
disp.SpecularPower = 20.0
both("on-shade")
disp.Shade = 0
tf2d.Boxes = [40.0, -30.0, 215.0, 50.0, 1.0, 0.6, 0.2, 0.6]
tf2d.SMProxy.InvokeCommand("Build")
low = ssptest.psnr(shoot("low-gradient", "Space Skipping Volume"), shoot("low-gradient", "Volume"))
disp.SetRepresentationType("Space Skipping Volume")
print("a box of gradient magnitudes below 20 per voxel: PSNR vs Volume %.2f dB (measured, not "
      "checked)" % low)
tf2d.Boxes = box
tf2d.SMProxy.InvokeCommand("Build")
log = warnings.stop()
ok.check("2-D" not in log, "no 2-D transfer-function warning while one is used (%s)"
         % (log.strip()[:160] or "none"))

# Every builder keeps Naive's image with the 2-D function on (skipping stays lossless).
disp.SetRepresentationType("Space Skipping Volume")
ref = fine[0]
builders = ["Grid", "DistanceGrid", "LBVHCPU", "KdTreeCPU", "Hybrid"]
ssptest.builders_keep_naive(view, disp, ok, ref, builders, "2-D", "transfer2d")

# A second array as the y axis: Use Gradient For Transfer 2D off, Color Array 2 "second" (the
# point's x coordinate). The function's y range is that array's range (what the mappers normalise
# it over); one box over the middle 40 % of it, values 40..255.
ylo, yhi = disp.Input.PointData["second"].GetRange()
tf2d.Range = [0.0, 255.0, ylo, yhi]
tf2d.Boxes = [40.0, ylo + 0.3 * (yhi - ylo), 215.0, 0.4 * (yhi - ylo), 1.0, 0.6, 0.2, 0.6]
tf2d.SMProxy.InvokeCommand("Build")
warnings = ssptest.WarningCapture()
disp.UseGradientForTransfer2D = 0
disp.ColorArray2Name = ["POINTS", "second"]
second = both("second-array")
changes("a second array as the y axis (against Use Transfer 2D off)", off, second)
gap = ssptest.psnr(second[0], fine[0])
ok.check(gap < 30.0, "the second array, not the gradient, is the y axis (PSNR %.1f dB to the gradient's image)" % gap)
disp.Shade = 1
both("second-array-shade")
disp.Shade = 0
log = warnings.stop()
ok.check("y axis" not in log and "second array" not in log,
         "no warning while a second array is the y axis (%s)" % (log.strip()[:160] or "none"))
ssptest.builders_keep_naive(view, disp, ok, second[0], builders, "second-array 2-D", "transfer2d_second")
ok.done()
