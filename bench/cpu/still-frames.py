"""Still frames of a dense Wavelet in ParaView (pvpython), Space Skipping Volume on the CPU backend
and, with --stock, ParaView's own Volume in the same process: shading with ParaView's light kit
(--shade, --specular; --positional adds a positional scene light, a spot of 40 degrees, to the
kit), ParaView's Use Cropping (--crop), a 2-D transfer function over the gradient magnitude
(--transfer2d: Use Transfer 2D, one box), the Wavelet's points as a rectilinear grid whose x steps
grow 1:3 along the axis (--rectilinear: ours draws it through its coordinates). Each frame follows a 2-degree turn of
the camera; the times are Render(view), waited for. To compare two builds of the plugin, run it
once per build (SPACESKIP_PLUGIN) in separate processes, alternated.

Usage (from the repository root, an X server on DISPLAY):
  PYTHONPATH=Testing/Plugin SPACESKIP_PLUGIN=build-cpu/lib/paraview-5.11/plugins/SpaceSkip/SpaceSkip.so \
  SPACESKIP_TEMP=/tmp/ss pvpython bench/cpu/still-frames.py [--size 256] [--frames 3] [--shade] \
  [--specular 0.2] [--positional] [--crop] [--transfer2d] [--rectilinear] [--stock]
"""
import argparse
import statistics
import time

from paraview.simple import *
import ssptest

parser = argparse.ArgumentParser()
parser.add_argument("--size", type=int, default=256)
parser.add_argument("--view", type=int, nargs=2, default=[800, 600])
parser.add_argument("--frames", type=int, default=3)
parser.add_argument("--shade", action="store_true", help="Shade on (ParaView's light kit)")
parser.add_argument("--specular", type=float, default=0.0, help="Specular (ParaView's default 0)")
parser.add_argument("--positional", action="store_true",
                    help="a positional scene light (spot, cone 40 degrees) beside the light kit")
parser.add_argument("--crop", action="store_true",
                    help="Use Cropping: origin at 0.3 of x, scale 0.5 x 0.8 x 0.9 of the bounds")
parser.add_argument("--transfer2d", action="store_true",
                    help="Use Transfer 2D: a box over values above the middle of the range and "
                         "gradient magnitudes above a tenth of the normalised range")
parser.add_argument("--rectilinear", action="store_true",
                    help="the Wavelet's points as a vtkRectilinearGrid, x steps growing 1:3")
parser.add_argument("--stock", action="store_true", help="ParaView's own Volume too, after ours")
args = parser.parse_args()
N = args.size

ssptest.load_plugin()
source, view, disp = ssptest.dense_wavelet_scene(N, args.view)
if args.rectilinear:
    from vtkmodules.vtkCommonCore import vtkDoubleArray
    from vtkmodules.vtkCommonDataModel import vtkRectilinearGrid
    Hide(source, view)
    source.UpdatePipeline()
    image = source.GetClientSideObject().GetOutputDataObject(0)
    ext = image.GetExtent()
    grid = vtkRectilinearGrid()
    grid.SetExtent(ext)
    for a, setter in enumerate((grid.SetXCoordinates, grid.SetYCoordinates, grid.SetZCoordinates)):
        c = vtkDoubleArray()
        lo, hi = ext[2 * a], ext[2 * a + 1]
        for i in range(lo, hi + 1):
            t = (i - lo) / float(hi - lo)
            c.InsertNextValue(lo + (hi - lo) * (0.5 * t + 0.5 * t * t) if a == 0 else float(i))
        setter(c)
    grid.GetPointData().ShallowCopy(image.GetPointData())
    source = TrivialProducer(registrationName="rectilinear wavelet")
    source.GetClientSideObject().SetOutput(grid)
    source.UpdatePipeline()
    disp = Show(source, view)
    ColorBy(disp, ("POINTS", "RTData"))
b = source.GetDataInformation().GetBounds()
if args.positional:
    spot = AddLight(view=view)
    spot.Coords = "Scene"
    spot.Type = "Positional"
    spot.Position = [b[1] + 0.5 * (b[1] - b[0]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5])]
    spot.FocalPoint = [0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5])]
    spot.ConeAngle = 40
    spot.Intensity = 0.8
if args.transfer2d:
    lo, hi = source.PointData["RTData"].GetRange()
    tf2d = GetTransferFunction2D("RTData")
    tf2d.AutomaticRescaleRangeMode = "Never"
    g = 0.25 * (hi - lo)  # vtkGPUVolumeRayCastMapper normalises the magnitude by a quarter of the range
    tf2d.Range = [lo, hi, 0.0, g]
    tf2d.Boxes = [0.5 * (lo + hi), 0.1 * g, 0.5 * (hi - lo), 0.9 * g, 1.0, 0.6, 0.2, 0.3]
    tf2d.SMProxy.InvokeCommand("Build")
what = "Wavelet %d^3%s%s%s%s%s%s, view %dx%d" % (N, ", shaded" if args.shade else "",
                                           ", specular %g" % args.specular if args.specular else "",
                                           ", positional spot" if args.positional else "",
                                           ", cropped" if args.crop else "",
                                           ", 2-D transfer function" if args.transfer2d else "",
                                           ", rectilinear (x steps 1:3)" if args.rectilinear else "",
                                           args.view[0], args.view[1])
for rep in ["Space Skipping Volume"] + (["Volume"] if args.stock else []):
    disp.SetRepresentationType(rep)
    if rep != "Volume":
        disp.Backend = "CPU"
    disp.Shade = 1 if args.shade else 0
    disp.Specular = args.specular
    if args.transfer2d:
        disp.TransferFunction2D = tf2d
        disp.UseTransfer2D = 1
        disp.UseGradientForTransfer2D = 1
    if args.crop:
        disp.UseCropping = 1
        disp.CroppingOrigin = [b[0] + 0.3 * (b[1] - b[0]), b[2], b[4]]
        disp.CroppingScale = [0.5, 0.8, 0.9]
    view.ResetCamera()
    Render(view)
    times = []
    for i in range(args.frames):
        GetActiveCamera().Azimuth(2.0)
        t0 = time.perf_counter()
        Render(view)
        times.append(time.perf_counter() - t0)
    print("%s, %s: median %.3f s (%s)" % (what, rep, statistics.median(times), " ".join("%.3f" % t for t in times)))
