"""Every mapper property round-trips (proxy -> representation -> mapper and back) and changes
the rendering the way it should: builders change the hierarchy but not the image; the leaf
criterion and the max leaf size change the k-d tree; the macro-cell size re-classifies but keeps
the image; the sample distance changes the image but
not the hierarchy; the backend is the one asked for (or the documented CPU fallback); early ray
termination keeps the image and saves time on an opaque volume."""
from paraview.simple import *
import ssptest

ssptest.load_plugin()
ok = ssptest.Checker()
reader, view, disp = ssptest.make_scene(builder="Naive", backend="CPU")
rep = ssptest.mapper_of(disp)
ok.check(rep.GetClassName() == "vtkSpaceSkipVolumeRepresentation",
         "the active representation is vtkSpaceSkipVolumeRepresentation")


def shot(name):
    return ssptest.read_png(ssptest.render_to(view, name))


def roundtrip(name, value, expected):
    """Sets `name`, then reads it back from the proxy and from the mapper on the server (the
    information property <name>Info calls the mapper's getter)."""
    setattr(disp, name, value)
    got_proxy = disp.GetPropertyValue(name)
    disp.UpdatePropertyInformation()
    got_vtk = disp.GetPropertyValue(name + "Info")
    ok.check(got_proxy == value and got_vtk == expected,
             "%s = %r round-trips (proxy %r, mapper %r)" % (name, value, got_proxy, got_vtk))


def change(builder, first, name, value, expected, second):
    """With `builder`: a frame (saved as `first`), then `name` = `value` round-tripped and a
    frame (saved as `second`). Returns the statistics before, the second frame and the
    statistics after."""
    disp.Builder = builder
    shot(first)
    before = ssptest.stats(disp)
    roundtrip(name, value, expected)
    img = shot(second)
    return before, img, ssptest.stats(disp)


naive = shot("prop_naive.png")
s0 = ssptest.stats(disp)
ok.check(s0["BuilderUsed"] == "Naive", "Naive ran (%s)" % s0["BuilderUsed"])

# -- Builder: every builder, same image as Naive; each change rebuilds once -------------------
names = list(disp.GetProperty("Builder").Available)
for i, name in enumerate(names):
    before = ssptest.stats(disp)
    roundtrip("Builder", name, i)
    img = shot("prop_builder_%s.png" % name)
    s = ssptest.stats(disp)
    p = ssptest.psnr(naive, img)
    ok.check(p >= 40.0, "Builder %s (ran %s): image == Naive image (PSNR %.2f dB)"
             % (name, s["BuilderUsed"], p))
    if name == "Auto":
        # A measured frame per candidate (CPU: Naive, Grid, DistanceGrid, KdTreeCPU), a second one
        # to three more for the close ones, each the Naive image; then the cheapest is kept and says why.
        for k in range(24):
            img = shot("prop_builder_Auto_%d.png" % k)
            p = min(p, ssptest.psnr(naive, img))
            if not ssptest.stats(disp)["BuilderChoice"].startswith("Auto: measuring"):
                break
        img = shot("prop_builder_Auto_kept.png")  # builds the kept one when the last was another
        p = min(p, ssptest.psnr(naive, img))
        s = ssptest.stats(disp)
        ok.check(p >= 40.0, "Builder Auto: every measuring frame == Naive image (PSNR %.2f dB)" % p)
        ok.check(s["BuilderChoice"].startswith("Auto chose " + s["BuilderUsed"] + ":"),
                 "Builder Auto: kept %s and says why (%s)" % (s["BuilderUsed"], s["BuilderChoice"]))
        ok.check(s["BuildCount"] >= before["BuildCount"] + 4,
                 "Builder Auto: built each candidate (%d -> %d)" % (before["BuildCount"], s["BuildCount"]))
    elif name != "Naive":
        ok.check(s["BuildCount"] == before["BuildCount"] + 1,
                 "Builder %s: exactly one rebuild (%d -> %d)" % (name, before["BuildCount"],
                                                               s["BuildCount"]))
    # Naive, Grid and DistanceGrid march the macro-cell grid itself: no tree to report.
    if s["BuilderUsed"] == name and name not in ("Naive", "Grid", "DistanceGrid"):
        ok.check(s["NodeCount"] >= 1 and s["LeafCount"] >= 1,
                 "Builder %s: hierarchy reported (%d nodes, %d leaves, height %d)"
                 % (name, s["NodeCount"], s["LeafCount"], s["TreeHeight"]))
    if s["BuilderUsed"] != name and name != "Auto":
        print("note: Builder %s fell back to %s on this machine" % (name, s["BuilderUsed"]))
    ok.check(0.0 < s["Occupancy"] < 1.0, "Builder %s: occupancy %.3f in (0, 1)"
             % (name, s["Occupancy"]))

# -- MacroCellSize: 4^3 cells (DistanceGrid's best on sparse data) re-classify, image stays ----
before, cell4_img, after = change("DistanceGrid", "prop_dg_cell8.png", "MacroCellSize", 4, 4,
                                  "prop_dg_cell4.png")
ok.check(after["BuilderUsed"] == "DistanceGrid",
         "DistanceGrid ran with MacroCellSize 4 (ran %s)" % after["BuilderUsed"])
ok.check(after["ClassifyCount"] == before["ClassifyCount"] + 1
         and after["BuildCount"] == before["BuildCount"] + 1,
         "MacroCellSize change re-classifies and rebuilds once (classify %d -> %d, build %d -> %d)"
         % (before["ClassifyCount"], after["ClassifyCount"], before["BuildCount"],
            after["BuildCount"]))
# Each 8^3 cell is the union of eight 4^3 cells: the finer grid leaves less of the shell occupied.
ok.check(0.0 < after["Occupancy"] < before["Occupancy"],
         "4^3 cells: smaller occupied fraction (%.4f < %.4f)" % (after["Occupancy"],
                                                              before["Occupancy"]))
diff = abs(naive - cell4_img).max()
ok.check(diff <= 1, "DistanceGrid, MacroCellSize 4 renders the Naive image (max %d/255, PSNR %.2f dB)"
         % (diff, ssptest.psnr(naive, cell4_img)))
roundtrip("MacroCellSize", 0, 1)  # the mapper clamps to [1, 64]
roundtrip("MacroCellSize", 100, 64)
roundtrip("MacroCellSize", 8, 8)
cell8_img = shot("prop_dg_cell8_again.png")
ok.check(ssptest.stats(disp)["ClassifyCount"] == after["ClassifyCount"] + 1,
         "back to MacroCellSize 8 re-classifies once")
ok.check(abs(naive - cell8_img).max() <= 1, "MacroCellSize 8 again renders the Naive image")

# -- LeafCriterion and MaxLeafSize: the k-d tree's shape ---------------------------------------
disp.Builder = "KdTreeCPU"
roundtrip("LeafCriterion", "Shallow", 0)
shallow_img = shot("prop_shallow.png")
shallow = ssptest.stats(disp)
roundtrip("LeafCriterion", "Deep", 1)
deep_img = shot("prop_deep.png")
deep = ssptest.stats(disp)
ok.check(deep["BuildCount"] == shallow["BuildCount"] + 1, "LeafCriterion change rebuilds once")
ok.check(ssptest.psnr(naive, shallow_img) >= 40.0 and ssptest.psnr(naive, deep_img) >= 40.0,
         "Shallow and Deep trees render the Naive image")
kd_available = shallow["BuilderUsed"] == "KdTreeCPU"
if kd_available:
    ok.check(deep["NodeCount"] > shallow["NodeCount"],
             "Deep tree has more nodes than Shallow (%d > %d)" % (deep["NodeCount"],
                                                                shallow["NodeCount"]))
else:
    print("note: KdTreeCPU not available (ran %s): tree-shape checks not run"
          % shallow["BuilderUsed"])

disp.LeafCriterion = "Shallow"
roundtrip("MaxLeafSize", 16, 16)
mls_img = shot("prop_mls16.png")
mls = ssptest.stats(disp)
ok.check(mls["BuildCount"] >= shallow["BuildCount"] + 1, "MaxLeafSize change rebuilds")
ok.check(ssptest.psnr(naive, mls_img) >= 40.0, "MaxLeafSize 16 renders the Naive image")
if kd_available:
    ok.check(mls["LeafCount"] > shallow["LeafCount"],
             "MLS 16 splits the Shallow tree's leaves (%d > %d leaves)"
             % (mls["LeafCount"], shallow["LeafCount"]))
roundtrip("MaxLeafSize", 0, 0)

# -- BinCount: parameter of the GPU k-d trees; a change rebuilds, the image stays ------------
before, bins_img, after = change("KdTreeGPUFast", "prop_gpufast.png", "BinCount", 8, 8,
                                 "prop_bins8.png")
ok.check(after["BuildCount"] == before["BuildCount"] + 1, "BinCount change rebuilds once")
ok.check(ssptest.psnr(naive, bins_img) >= 40.0, "BinCount 8 renders the Naive image")
# 0: the sweep (KdTreeCPU's candidates); 1 has no candidate plane and clamps to 2 in the mapper.
roundtrip("BinCount", 0, 0)
sweep_img = shot("prop_bins0.png")
ok.check(ssptest.stats(disp)["BuildCount"] == after["BuildCount"] + 1, "BinCount 0 rebuilds once")
ok.check(ssptest.psnr(naive, sweep_img) >= 40.0, "BinCount 0 (sweep) renders the Naive image")
roundtrip("BinCount", 1, 2)
roundtrip("BinCount", 4, 4)

# -- SampleDistance: changes the sampling (image and work), not the hierarchy ----------------


def frame_seconds(n=3):
    """Best of n frames (the machine is shared: the minimum is the stable statistic)."""
    times = []
    for k in range(n):
        view.CameraPosition = view.CameraPosition  # invalidate the cached image
        Render(view)
        times.append(ssptest.stats(disp)["LastRenderSeconds"])
    return min(times)


disp.Builder = "Grid"
ref = shot("prop_grid.png")
t_auto = frame_seconds()
before = ssptest.stats(disp)
roundtrip("SampleDistance", 2.0, 2.0)
coarse = shot("prop_sd2.png")
t_coarse = frame_seconds()
after = ssptest.stats(disp)
p_coarse = ssptest.psnr(ref, coarse)
# The shell is smooth and the opacity is corrected for the step, so 4x coarser sampling changes
# the image only slightly (about 51 dB here), but measurably, and it is faster.
ok.check(p_coarse < 60.0, "SampleDistance 2.0 changes the image (PSNR %.2f dB vs auto 0.5)"
         % p_coarse)
ok.check(p_coarse > 30.0, "... but it still shows the same volume (PSNR %.2f > 30 dB)" % p_coarse)
# Timing is printed, not asserted: four engineers share two cores here.
print("frame time: %.3f s at distance 2.0 vs %.3f s at auto (0.5)" % (t_coarse, t_auto))
ok.check(after["BuildCount"] == before["BuildCount"], "SampleDistance does not rebuild")
roundtrip("SampleDistance", 0.25, 0.25)
fine = shot("prop_sd025.png")
p_fine = ssptest.psnr(ref, fine)
ok.check(p_fine > p_coarse, "a finer distance (0.25) stays closer to auto (0.5) than 2.0 does "
         "(%.2f > %.2f dB)" % (p_fine, p_coarse))
# A typo far below the voxel size (1e-4 ran for minutes and froze the GUI) is clamped to 1/16
# of the smallest spacing (1 here: auto is 0.5), said once, and shown as Sample Distance Used.
roundtrip("SampleDistance", 1e-6, 1e-6)
tiny = shot("prop_sd_tiny.png")
used = ssptest.stats(disp)["SampleDistanceUsed"]
ok.check(used >= 1.0 / 16 * 0.999 and used <= 1.0 / 16 * 1.001,
         "SampleDistance 1e-6 is clamped to 1/16 of the spacing (used %g)" % used)
ok.check(ssptest.psnr(ref, tiny) > 30.0, "... and draws the volume")
roundtrip("SampleDistance", 0.0, 0.0)
again = shot("prop_sd_auto.png")
ok.check(ssptest.psnr(ref, again) >= 60.0, "SampleDistance 0 (auto) renders the first image again")

# -- Backend ----------------------------------------------------------------------------------
for value, index in (("CPU", 1), ("CUDA", 2), ("Auto", 0)):
    roundtrip("Backend", value, index)
    img = shot("prop_backend_%s.png" % value)
    used = ssptest.stats(disp)["BackendUsed"]
    ok.check(used in ("cpu", "cuda"), "Backend %s: drew with %s" % (value, used))
    if value == "CPU":
        ok.check(used == "cpu", "Backend CPU forces the CPU backend")
    ok.check(ssptest.psnr(ref, img) >= 40.0, "Backend %s (%s) renders the same image (%.2f dB)"
             % (value, used, ssptest.psnr(ref, img)))
disp.Backend = "CPU"

# -- FilterMode: the CPU backend has no texture unit and samples exactly: Hardware draws the
# Exact image there, without a rebuild ---------------------------------------------------------
exact = shot("prop_filter_exact.png")
before = ssptest.stats(disp)
roundtrip("FilterMode", "Hardware", 1)
hw = shot("prop_filter_hw.png")
after = ssptest.stats(disp)
ok.check(abs(exact - hw).max() == 0, "FilterMode Hardware on the CPU backend: the Exact image (max %d/255)"
         % abs(exact - hw).max())
ok.check(after["BuildCount"] == before["BuildCount"] and after["ClassifyCount"] == before["ClassifyCount"],
         "FilterMode neither re-classifies nor rebuilds")
roundtrip("FilterMode", "Exact", 0)

# -- EarlyRayTermination: same image, less work on an opaque volume ---------------------------
lut, pwf = ssptest.set_transfer_functions(
    opacity_points=[0.0, 0.0, 0.5, 0.0, 40.0, 0.0, 0.5, 0.0, 60.0, 1.0, 0.5, 0.0,
                    255.0, 1.0, 0.5, 0.0])
disp.Builder = "Naive"  # every ray marches the whole box: what ERT saves is plain to see



roundtrip("EarlyRayTermination", 1, 1)
ert_on = shot("prop_ert_on.png")
t_on = frame_seconds()
roundtrip("EarlyRayTermination", 0, 0)
ert_off = shot("prop_ert_off.png")
t_off = frame_seconds()
p = ssptest.psnr(ert_on, ert_off)
diff = abs(ert_on - ert_off).max()
# Rays stop at opacity 1 - 1/255 (vtkGPUVolumeRayCastMapper's threshold): what lies behind
# changes a pixel by less than one 8-bit step, but it does change some pixels (measured
# 2026-11-29: max 1, 92.21 dB); identical images would mean ERT is ignored.
ok.check(0 < diff <= 1, "ERT on/off: images differ by at most 1/255 (max %d, PSNR %.2f dB)"
         % (diff, p))
print("frame time (Naive, opaque): %.3f s with ERT vs %.3f s without" % (t_on, t_off))
ok.done()
