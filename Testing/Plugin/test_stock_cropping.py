"""Stock properties of ParaView's Volume representation on a Space Skipping Volume: Use
Cropping (with Cropping Origin and Scale) changes the image as it does for ParaView's own
Volume, and the two agree (PSNR); every builder keeps the cropped image of Naive; our Jittering
property changes the image and stays lossless."""
from paraview.simple import *
import ssptest

ssptest.load_plugin()
ok = ssptest.Checker()
reader, view, disp = ssptest.make_scene(builder="Naive", backend="CPU")


def shot(name):
    return ssptest.read_png(ssptest.render_to(view, name))


full = shot("crop_full.png")
bounds = reader.GetDataInformation().GetBounds()
disp.UseCropping = 1
disp.CroppingOrigin = [bounds[0] + 0.3 * (bounds[1] - bounds[0]), bounds[2], bounds[4]]
disp.CroppingScale = [0.5, 0.8, 0.9]
cropped = shot("crop_ours.png")
p_full = ssptest.psnr(full, cropped)
ok.check(p_full < 35.0, "Use Cropping changes the image (PSNR vs uncropped %.2f dB)" % p_full)
ok.check(ssptest.lit_fraction(cropped) < ssptest.lit_fraction(full),
         "cropping removes part of the volume (%.3f < %.3f lit)"
         % (ssptest.lit_fraction(cropped), ssptest.lit_fraction(full)))
for name in ["Grid", "KdTreeCPU", "LBVH", "DistanceGrid"]:
    disp.Builder = name
    p = ssptest.psnr(cropped, shot("crop_%s.png" % name))
    ok.check(p >= 50.0, "%s keeps Naive's cropped image (PSNR %.2f dB)" % (name, p))
disp.Builder = "Naive"

# ParaView's own Volume representation, same cropping.
disp.SetRepresentationType("Volume")
stock_cropped = shot("crop_stock.png")
disp.UseCropping = 0
stock_full = shot("crop_stock_full.png")
disp.UseCropping = 1
disp.SetRepresentationType("Space Skipping Volume")
p_stock = ssptest.psnr(stock_full, stock_cropped)
ok.check(p_stock < 35.0, "... as it does for ParaView's Volume (PSNR vs uncropped %.2f dB)" % p_stock)
p = ssptest.psnr(cropped, stock_cropped)
print("PSNR cropped SpaceSkip vs cropped ParaView 'Volume': %.2f dB" % p)
ok.check(p >= 40.0, "the cropped images agree with ParaView's Volume (PSNR %.2f >= 40 dB)" % p)

# Jittering at a coarse sample distance.
disp.UseCropping = 0
disp.SampleDistance = 2.0
plain = shot("jitter_off.png")
disp.Jittering = 1
jittered = shot("jitter_on.png")
p = ssptest.psnr(plain, jittered)
ok.check(25.0 < p < 60.0, "Jittering changes the image a little (PSNR %.2f dB)" % p)
disp.Builder = "Grid"
p = ssptest.psnr(jittered, shot("jitter_grid.png"))
ok.check(p >= 50.0, "jittered Grid == jittered Naive (PSNR %.2f dB)" % p)
ok.done()
