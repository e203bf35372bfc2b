"""Transfer-function edits through ParaView's API trigger exactly the work the mapper promises
(read from the representation's statistics properties):
  re-render, no edit            -> nothing but a frame
  colour-only edit (LUT points) -> one colour-table update; no classification, no rebuild
  opacity edit, same occupancy  -> one classification; no rebuild
  opacity edit, new occupancy   -> one classification and one rebuild; occupancy drops
"""
from paraview.simple import *
import ssptest

ssptest.load_plugin()
ok = ssptest.Checker()
reader, view, disp = ssptest.make_scene(builder="Grid", backend="CPU")
lut = GetColorTransferFunction(ssptest.ARRAY)
pwf = GetOpacityTransferFunction(ssptest.ARRAY)

img0 = ssptest.read_png(ssptest.render_to(view, "tf_0.png"))
s0 = ssptest.stats(disp)
print("after the first render:", s0)
ok.check(s0["BuildCount"] == 1 and s0["ClassifyCount"] == 1,
         "first render: one classification, one build")

KEYS = ("ColorUpdateCount", "ClassifyCount", "BuildCount")


def step(label, expected, name):
    before = ssptest.stats(disp)
    img = ssptest.read_png(ssptest.render_to(view, name))
    after = ssptest.stats(disp)
    delta = {k: after[k] - before[k] for k in KEYS}
    ok.check(delta == expected, "%s: %s (expected %s)" % (label, delta, expected))
    ok.check(after["FrameCount"] > before["FrameCount"], "%s: a frame was drawn" % label)
    return img, after


# 1. Nothing edited: a new frame (the camera moved), no TF work.
view.CameraPosition = [p + 1.0 for p in view.CameraPosition]
step("camera move", {"ColorUpdateCount": 0, "ClassifyCount": 0, "BuildCount": 0}, "tf_1.png")

# 2. Colour only.
before_img = ssptest.read_png(ssptest.render_to(view, "tf_1b.png"))
lut.RGBPoints = [40.0, 0.1, 0.8, 0.2, 140.0, 0.9, 0.9, 0.2, 255.0, 0.9, 0.1, 0.9]
img2, s2 = step("colour-only edit",
                {"ColorUpdateCount": 1, "ClassifyCount": 0, "BuildCount": 0}, "tf_2.png")
ok.check(ssptest.psnr(before_img, img2) < 30.0, "colour edit changes the image (%.2f dB)"
         % ssptest.psnr(before_img, img2))

# 3. Opacity scaled, zero where it was zero: the occupied cells stay the same.
occ = s2["Occupancy"]
pwf.Points = [0.0, 0.0, 0.5, 0.0, 40.0, 0.0, 0.5, 0.0, 255.0, 0.8, 0.5, 0.0]
img3, s3 = step("opacity edit, same occupancy",
                {"ColorUpdateCount": 0, "ClassifyCount": 1, "BuildCount": 0}, "tf_3.png")
ok.check(s3["Occupancy"] == occ, "occupancy unchanged (%.4f)" % s3["Occupancy"])
ok.check(ssptest.psnr(img2, img3) < 40.0, "opacity edit changes the image (%.2f dB)"
         % ssptest.psnr(img2, img3))

# 4. Opacity zero below 150: fewer occupied cells, a rebuild.
pwf.Points = [0.0, 0.0, 0.5, 0.0, 150.0, 0.0, 0.5, 0.0, 255.0, 0.8, 0.5, 0.0]
img4, s4 = step("opacity edit, new occupancy",
                {"ColorUpdateCount": 0, "ClassifyCount": 1, "BuildCount": 1}, "tf_4.png")
ok.check(s4["Occupancy"] < occ, "occupancy dropped (%.4f -> %.4f)" % (occ, s4["Occupancy"]))

# 5. The image with skipping still equals the image without (lossless after the rebuild).
disp.Builder = "Naive"
naive = ssptest.read_png(ssptest.render_to(view, "tf_5_naive.png"))
p = ssptest.psnr(img4, naive)
ok.check(p >= 40.0, "after the rebuild Grid == Naive (PSNR %.2f dB)" % p)
ok.done()
