"""Time-series playback in ParaView (issue 38): ours ('Space Skipping Volume') against ParaView's
stock 'Volume' (vtkSmartVolumeMapper -> the GPU ray caster; Mesa llvmpipe on a machine without a
GPU), the same steps in the same view, one pvpython process.

The steps: N^3 uint8 .vti files of balls that drift apart and a ball that grows, step by step, in a
background of exact zeros (sparse, as a simulation's early steps), listed in a .pvd. The animation
scene steps AnimationTime over them. A step is timed as Play() takes it: AnimationTime set (the
animation scene's tick: ParaView loads the step, gathers its data information for the
representations' domains and renders the view) up to WaitForCompletion. In ParaView 5.11 the data
information computes the array's range through VTK's SMP tools: set
VTK_SMP_BACKEND_IN_USE=STDThread for threads. Then one more Render() of the loaded step with the
camera turned a little (a frame: what an interaction costs once the step is there). Rounds
alternate ours, stock and Outline (the floor of any representation); the medians and the ratios
stock / ours (> 1 means ours is faster) are printed.
--cache MB turns on ParaView's animation cache and plays each representation's steps a second time
from it (reported apart).

Usage (an X server is needed: `source scripts/xvfb.sh 97`):
  pvpython bench/time-series-vs-stock.py --plugin build/lib/paraview-5.11/plugins/SpaceSkip/SpaceSkip.so \
      [--dims 256] [--steps 10] [--view 1024] [--rounds 2] [--backend CPU] [--workdir /tmp/ts] [--raw]
      [--cache MB]
"""
import argparse
import os
import statistics
import time

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", required=True)
parser.add_argument("--dims", type=int, default=256)
parser.add_argument("--steps", type=int, default=10)
parser.add_argument("--view", type=int, default=1024)
parser.add_argument("--rounds", type=int, default=2)
parser.add_argument("--backend", default="CPU")
parser.add_argument("--workdir", default="/tmp/spaceskip-time-series")
parser.add_argument("--cache", type=int, default=0, metavar="MB",
                    help="turn on ParaView's animation cache (Cache Geometry For Animation, limit MB) and "
                         "play each representation's steps twice: the second pass plays from the cache")
parser.add_argument("--raw", action="store_true",
                    help="write the steps uncompressed (raw appended data) instead of zlib-compressed")
args = parser.parse_args()

import numpy  # noqa: E402
from paraview import simple  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLImageDataWriter  # noqa: E402
from vtkmodules.util.numpy_support import numpy_to_vtk  # noqa: E402

simple._DisableFirstRenderCameraReset()
if args.cache:
    from paraview.modules.vtkRemotingSettings import vtkPVGeneralSettings
    simple.GetSettingsProxy("GeneralSettings").CacheGeometryForAnimation = 1
    vtkPVGeneralSettings.GetInstance().SetAnimationGeometryCacheLimit(args.cache * 1024)  # KB
simple.LoadPlugin(args.plugin, remote=False, ns=vars(simple))
N, K = args.dims, args.steps
os.makedirs(args.workdir, exist_ok=True)


def write_step(path, k):
    d = 0.3 * k / K
    balls = ((0.3 - d, 0.35, 0.4, 0.12), (0.7 + d / 2, 0.6, 0.55, 0.09), (0.5, 0.75 - d, 0.3, 0.07),
             (0.5, 0.4, 0.7, 0.03 + 0.06 * k / K))
    data = numpy.zeros((N, N, N), numpy.uint8)
    for cx, cy, cz, r in balls:  # each ball over its own bounding box only
        lo = [max(0, int((c - r) * N)) for c in (cz, cy, cx)]
        hi = [min(N, int((c + r) * N) + 2) for c in (cz, cy, cx)]
        z, y, x = numpy.ogrid[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
        dist = numpy.sqrt((x / N - cx) ** 2 + (y / N - cy) ** 2 + (z / N - cz) ** 2) / r
        v = numpy.round(numpy.clip(1.0 - dist, 0.0, 1.0) * 255.0).astype(numpy.uint8)
        box = data[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
        numpy.maximum(box, v, out=box)
    img = vtkImageData()
    img.SetDimensions(N, N, N)
    arr = numpy_to_vtk(data.ravel(), deep=1)
    arr.SetName("density")
    img.GetPointData().SetScalars(arr)
    w = vtkXMLImageDataWriter()
    w.SetFileName(path)
    w.SetInputData(img)
    if args.raw:
        w.SetCompressorTypeToNone()
        w.SetDataModeToAppended()
        w.EncodeAppendedDataOff()
    w.Write()
    return float((data > 0).mean())


tag = "%d%s" % (N, "_raw" if args.raw else "")
pvd = os.path.join(args.workdir, "steps_%s.pvd" % tag)
with open(pvd, "w") as f:
    f.write('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n<Collection>\n')
    for k in range(K):
        name = "step_%s_%d.vti" % (tag, k)
        path = os.path.join(args.workdir, name)
        if not os.path.exists(path):
            t0 = time.perf_counter()
            write_step(path, k)
            print("  wrote %s in %.2f s" % (name, time.perf_counter() - t0), flush=True)
        f.write('<DataSet timestep="%d" file="%s"/>\n' % (k, name))
    f.write('</Collection>\n</VTKFile>\n')

reader = simple.PVDReader(FileName=pvd)
view = simple.CreateView("RenderView")
view.ViewSize = [args.view, args.view]
view.OrientationAxesVisibility = 0
view.EnableRenderOnInteraction = 0
disp = simple.Show(reader, view)
simple.ColorBy(disp, ("POINTS", "density"))
lut = simple.GetColorTransferFunction("density")
lut.AutomaticRescaleRangeMode = "Never"
lut.RescaleTransferFunction(0.0, 255.0)
pwf = simple.GetOpacityTransferFunction("density")
pwf.Points = [0.0, 0.0, 0.5, 0.0, 20.0, 0.0, 0.5, 0.0, 255.0, 0.5, 0.5, 0.0]
view.ResetCamera()
scene = simple.GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
times = list(reader.TimestepValues)


def set_rep(name):
    disp.SetRepresentationType(name)
    if name == "Space Skipping Volume":
        disp.Backend = args.backend
    scene.AnimationTime = times[-1]
    simple.Render(view)  # the representation's first frame, not timed


def play():
    """Each step: (the step, a frame) in ms. The step is what Play() does per step: AnimationTime
    set, in which ParaView loads the step, gathers its data information for every representation
    alike and renders the views (the animation scene's tick), up to WaitForCompletion. A frame is
    one more Render() of the loaded step with the camera turned a little (what an interaction
    costs once the step is there: the representation's drawing alone)."""
    ms = []
    window = view.GetRenderWindow()
    for t in times:
        t0 = time.perf_counter()
        scene.AnimationTime = t
        window.WaitForCompletion()  # the tick's frame drawn, not only queued
        t1 = time.perf_counter()
        view.GetActiveCamera().Azimuth(1.0)
        simple.Render(view)
        window.WaitForCompletion()
        ms.append((1e3 * (t1 - t0), 1e3 * (time.perf_counter() - t1)))
    return ms


# "Outline": the floor of any representation here (the reader's load of the step, the pipeline's
# update and a frame of a few lines).
results = {"Space Skipping Volume": [], "Volume": [], "Outline": []}
cached = {name: [] for name in results}  # --cache: the second pass, played from the cache
for r in range(args.rounds):
    for name in results:
        t0 = time.perf_counter()
        set_rep(name)
        t1 = time.perf_counter()
        results[name] += play()
        print("  round %d, %s: first frame %.2f s, %d steps %.2f s" %
              (r, name, t1 - t0, K, time.perf_counter() - t1), flush=True)
        if args.cache:
            cached[name] += play()


def medians(runs):
    return statistics.median(m[0] for m in runs), statistics.median(m[1] for m in runs)


def report(what, runs):
    ours, stock, floor = medians(runs["Space Skipping Volume"]), medians(runs["Volume"]), medians(runs["Outline"])
    print(what)
    for label, m in (("ours", ours), ("stock Volume", stock), ("Outline (the floor)", floor)):
        print("  %-20s a step %.1f ms (%.2f steps/s); a frame of the loaded step %.1f ms (medians)" %
              (label, m[0], 1e3 / m[0], m[1]))
    print("  stock / ours: a step %.2fx, a frame %.2fx; ours' step above the floor's %.1f ms, its frame %.1f ms" %
          (stock[0] / ours[0], stock[1] / ours[1], ours[0] - floor[0], ours[1] - floor[1]))


report("time series %d^3 uint8, %d steps (.pvd of %s .vti), %dx%d view, %d rounds, VTK_SMP_BACKEND_IN_USE=%s%s:" %
       (N, K, "raw" if args.raw else "zlib-compressed", args.view, args.view, args.rounds,
        os.environ.get("VTK_SMP_BACKEND_IN_USE", "(unset)"),
        ", animation cache on (%d MB), first passes" % args.cache if args.cache else ""), results)
if args.cache:
    report("played again from ParaView's animation cache:", cached)
disp.SetRepresentationType("Space Skipping Volume")
disp.UpdatePropertyInformation()
print("  ours: backend %s, builder %s; %s" % (disp.GetPropertyValue("BackendUsed"), disp.GetPropertyValue("BuilderUsed"),
                                              disp.GetPropertyValue("BuilderChoice")))
