"""Label maps in ParaView (issue 37): a uint8 segmentation of touching blobs with far-apart ids,
coloured through a categorical colour map ("Interpret Values As Categories", annotations and
indexed colours), is drawn by the Space Skipping Volume's label-map mode (Label Map = Auto):
every pixel is the background or one label's colour, with either Label Sampling. The same data
through a continuous map of the same colours (categories off: Auto draws an ordinary volume)
shows colours of no label, so the check can fail. Label Map Off/On override Auto. Hidden Labels
hides one segment (its pixels go, the others stay, no voxel pass). A saved state reloads to the
same image with the label-map mode on and the hidden label still hidden."""
import numpy
from paraview.simple import *
import ssptest

ssptest.load_plugin()
ok = ssptest.Checker()

N, BLOBS, COLOURS, NAMES = ssptest.LABEL_N, ssptest.LABEL_BLOBS, ssptest.LABEL_COLOURS, ssptest.LABEL_NAMES
write_labels, unexplained = ssptest.write_label_blobs, ssptest.unexplained_colours


def shot(view, name):
    return ssptest.read_png(ssptest.render_to(view, name))


def label_map_used(disp):
    disp.UpdatePropertyInformation()
    return disp.GetPropertyValue("LabelMapUsed")


path = ssptest.temp_path("labelmap_blobs.vti")
write_labels(path)
reader = XMLImageDataReader(registrationName="LabelBlobs", FileName=[path])
view = ssptest.make_view()
disp = Show(reader, view)
disp.SetRepresentationType("Space Skipping Volume")
ColorBy(disp, ("POINTS", "labels"))
disp.Builder = "Grid"
disp.Backend = "CPU"
disp.Shade = 0
disp.ScalarOpacityUnitDistance = 1.0
c = (N - 1) / 2.0
view.CameraFocalPoint = [c, c, c]
view.CameraPosition = [c + 45.0, c + 30.0, c + 60.0]
view.CameraViewUp = [0.0, 1.0, 0.0]
view.CameraViewAngle = 30.0

lut = ssptest.categorical_label_map("labels")
ids = sorted(COLOURS)
colours = [COLOURS[i] for i in ids]

ok.check(disp.LabelMap == "Auto" and disp.LabelSampling == "Blended",
         "defaults: Label Map Auto, Label Sampling Blended (%s, %s)" % (disp.LabelMap, disp.LabelSampling))
images = {}
for sampling in ["Nearest", "Blended"]:
    disp.LabelSampling = sampling
    images[sampling] = img = shot(view, "labelmap_%s.png" % sampling.lower())
    lit, bad = ssptest.lit_fraction(img), unexplained(img, colours)
    print("categories, %s: lit %.3f, unexplained %d" % (sampling, lit, bad))
    ok.check(label_map_used(disp) == 1, "Auto + categorical map on uint8: label-map mode on")
    ok.check(lit > 0.05, "%s: the labels are drawn (%.1f%% of the pixels)" % (sampling, 100 * lit))
    ok.check(bad == 0, "%s: every pixel is the background or a label's colour (%d not)" % (sampling, bad))
    # every label shows up
    for i in ids:
        col = numpy.round(numpy.array(COLOURS[i]) * 255.0)
        n = int((numpy.abs(img - col) <= 2).all(axis=2).sum())
        ok.check(n > 50, "%s: label %d drawn (%d pixels)" % (sampling, i, n))
labelled = images["Blended"]
p = ssptest.psnr(images["Nearest"], labelled)
ok.check(p < 60.0, "Label Sampling changes the image (PSNR Nearest vs Blended %.2f dB)" % p)

# Label Map Off: an ordinary volume through the indexed map, whatever Auto would say.
disp.LabelMap = "Off"
off = shot(view, "labelmap_forced_off.png")
ok.check(label_map_used(disp) == 0, "Label Map Off: mode off")
disp.LabelMap = "Auto"

# Categories off: a continuous map of the same colours; Auto draws an ordinary volume, whose
# interpolation between ids invents colours (the check above can fail).
lut.InterpretValuesAsCategories = 0
cont = shot(view, "labelmap_continuous.png")
bad = unexplained(cont, colours)
print("continuous: unexplained %d" % bad)
ok.check(label_map_used(disp) == 0, "Auto + continuous map: label-map mode off")
ok.check(bad > 100, "a continuous map invents colours (%d pixels of no label's colour)" % bad)
# On forces the label map even with a continuous map (labels: every integer of the range).
disp.LabelMap = "On"
forced = shot(view, "labelmap_forced_on.png")
ok.check(label_map_used(disp) == 1, "Label Map On with a continuous map: mode on")
ok.check(ssptest.psnr(forced, cont) < 40.0, "Label Map On changes the continuous image")
disp.LabelMap = "Auto"
lut.InterpretValuesAsCategories = 1
again = shot(view, "labelmap_again.png")
p = ssptest.psnr(again, labelled)
ok.check(label_map_used(disp) == 1 and p == float("inf"),
         "categories back on: the label image again (PSNR %.2f dB)" % p)

# Hidden Labels: label 5 goes, the others stay; every pixel still explained.
def count(img, i):
    col = numpy.round(numpy.array(COLOURS[i]) * 255.0)
    return int((numpy.abs(img - col) <= 2).all(axis=2).sum())


ok.check(list(disp.HiddenLabels) == [], "Hidden Labels empty by default (%s)" % list(disp.HiddenLabels))
disp.HiddenLabels = [5]
hidden = shot(view, "labelmap_hidden5.png")
print("hidden 5: label pixels %s" % {i: count(hidden, i) for i in ids})
ok.check(count(hidden, 5) == 0, "Hidden Labels [5]: no pixel of label 5 (%d)" % count(hidden, 5))
ok.check(all(count(hidden, i) > 50 for i in ids if i != 5), "Hidden Labels [5]: the other labels drawn")
ok.check(unexplained(hidden, colours) == 0, "Hidden Labels [5]: every pixel explained")
disp.HiddenLabels = []
shown = shot(view, "labelmap_shown.png")
p = ssptest.psnr(shown, labelled)
ok.check(p == float("inf"), "Hidden Labels [] again: the label image again (PSNR %.2f dB)" % p)
disp.HiddenLabels = [5]
labelled = shot(view, "labelmap_hidden5_again.png")

# A saved state reloads to the same image, label-map mode on, label 5 hidden.
state = ssptest.temp_path("labelmap_state.pvsm")
SaveState(state)
ResetSession()
ssptest.load_plugin()
LoadState(state)
view = GetActiveViewOrCreate("RenderView")
disp = GetDisplayProperties(FindSource("LabelBlobs"), view)
after = shot(view, "labelmap_state_after.png")
diff = float(numpy.abs(after - labelled).max()) if after.shape == labelled.shape else 255.0
ok.check(disp.Representation == "Space Skipping Volume" and disp.LabelMap == "Auto",
         "state: Space Skipping Volume, Label Map Auto (%s, %s)" % (disp.Representation, disp.LabelMap))
ok.check(label_map_used(disp) == 1, "state: label-map mode on after LoadState")
ok.check(diff <= 1.0, "state: the same image (max difference %g/255)" % diff)
ok.check(unexplained(after, colours) == 0, "state: every pixel explained")
ok.check(list(disp.HiddenLabels) == [5], "state: Hidden Labels [5] (%s)" % list(disp.HiddenLabels))
ok.done()
