"""Ours ('Space Skipping Volume', the CPU backend unless --backend says otherwise) against ParaView's
stock 'Volume' (vtkSmartVolumeMapper -> the GPU ray caster: Mesa llvmpipe on a machine without a GPU,
NVIDIA's GL on the GPU machine, bench/device/run-pv.sh), side by side in one pvpython process, stock
defaults (default colour map and opacity ramp, the camera of ParaView's first Render).

Two representations of one source in two views of the same size; frames alternate (ours, stock,
ours, ...) with the camera turned by a few degrees each frame, and each Render() is timed up to the
render window's WaitForCompletion (glFinish: the frame drawn, not only queued). Prints
the median frame times, their ratio (stock / ours: > 1 means ours is faster) and the PSNR between
the two views' first images.

Usage (an X server is needed: `source scripts/xvfb.sh 97`):
  pvpython bench/cpu-vs-stock.py --plugin build/lib/paraview-5.11/plugins/SpaceSkip/SpaceSkip.so \
      [--source wavelet|sparse] [--dims 256] [--view 1024] [--frames 5] [--builder Auto] [--backend CPU]
"""
import argparse
import math
import statistics
import time

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", required=True)
parser.add_argument("--source", default="wavelet", choices=["wavelet", "sparse"])
parser.add_argument("--dims", type=int, default=256)
parser.add_argument("--view", type=int, default=1024)
parser.add_argument("--frames", type=int, default=5)
parser.add_argument("--builder", default="", help="'' keeps the default (Auto)")
parser.add_argument("--backend", default="CPU", help="ours: CPU, CUDA or Auto")
parser.add_argument("--turn", type=float, default=4.0, help="degrees the camera turns each frame")
args = parser.parse_args()

from paraview import simple  # noqa: E402

simple._DisableFirstRenderCameraReset()
simple.LoadPlugin(args.plugin, remote=False, ns=vars(simple))
N = args.dims


def make_source():
    if args.source == "wavelet":  # float32, dense and smooth: every voxel visible under the ramp
        h = N // 2
        return simple.Wavelet(WholeExtent=[-h, N - h - 1, -h, N - h - 1, -h, N - h - 1])
    # uint8 balls and a tube in exact zeros (about 5 % non-zero)
    import numpy
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.util.numpy_support import numpy_to_vtk
    z, y, x = numpy.mgrid[0:N, 0:N, 0:N].astype(numpy.float32) / N
    v = numpy.zeros((N, N, N), numpy.float32)
    for cx, cy, cz, r in ((0.3, 0.35, 0.4, 0.12), (0.7, 0.6, 0.55, 0.09), (0.5, 0.75, 0.3, 0.07)):
        d = numpy.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / r
        v = numpy.maximum(v, numpy.clip(1.0 - d, 0.0, 1.0))
    img = vtkImageData()
    img.SetDimensions(N, N, N)
    arr = numpy_to_vtk(numpy.round(v * 255.0).astype(numpy.uint8).ravel(), deep=1)
    arr.SetName("density")
    img.GetPointData().SetScalars(arr)
    src = simple.TrivialProducer()
    src.GetClientSideObject().SetOutput(img)
    return src


def make_view():
    view = simple.CreateView("RenderView")
    view.ViewSize = [args.view, args.view]
    view.OrientationAxesVisibility = 0
    return view


src = make_source()
views, reps = {}, {}
for name, rtype in (("ours", "Space Skipping Volume"), ("stock", "Volume")):
    view = make_view()
    rep = simple.Show(src, view)
    rep.SetRepresentationType(rtype)
    if name == "ours":
        if not rep.ColorArrayName[1]:  # older plugins did not pick the array themselves
            info = src.GetDataInformation().GetPointDataInformation()
            rep.ColorArrayName = ["POINTS", info.GetArrayInformation(0).GetName()]
        if hasattr(rep, "Backend"):
            rep.Backend = args.backend
        if args.builder:
            rep.Builder = args.builder
    view.ResetCamera()
    views[name], reps[name] = view, rep


def grab(view, name):
    import os
    import tempfile
    from vtkmodules.vtkIOImage import vtkPNGReader
    from vtkmodules.util.numpy_support import vtk_to_numpy
    path = os.path.join(tempfile.gettempdir(), "cpu-vs-stock-%s.png" % name)
    simple.SaveScreenshot(path, view, ImageResolution=[args.view, args.view])
    r = vtkPNGReader()
    r.SetFileName(path)
    r.Update()
    return vtk_to_numpy(r.GetOutput().GetPointData().GetScalars()).astype("float64")


times = {"ours": [], "stock": []}
first = {}
for name in ("ours", "stock"):  # first frames: uploads, builds, Auto's measuring
    t = time.perf_counter()
    simple.Render(views[name])
    views[name].GetRenderWindow().WaitForCompletion()
    print("%s first frame %.3f s" % (name, time.perf_counter() - t), flush=True)
    first[name] = grab(views[name], name)
for i in range(args.frames):
    for name in ("ours", "stock"):
        cam = views[name].GetActiveCamera()
        cam.Azimuth(args.turn)
        t = time.perf_counter()
        simple.Render(views[name])
        views[name].GetRenderWindow().WaitForCompletion()
        times[name].append(time.perf_counter() - t)
a, b = first["ours"], first["stock"]
mse = ((a - b) ** 2).mean()
psnr = float("inf") if mse == 0 else 10 * math.log10(255.0 ** 2 / mse)
med = {k: statistics.median(v) for k, v in times.items()}
print("source %s %d^3, view %dx%d, %d frames each" % (args.source, N, args.view, args.view, args.frames))
for k in ("ours", "stock"):
    print("%-5s median %.3f s/frame  (all: %s)" % (k, med[k], " ".join("%.3f" % x for x in times[k])))
builder = getattr(reps["ours"], "BuilderUsed", None) if hasattr(reps["ours"], "BuilderUsed") else None
print("ratio stock/ours %.2fx (>1: ours faster); PSNR ours vs stock %.1f dB%s" %
      (med["stock"] / med["ours"], psnr, "" if builder is None else "; builder %s" % builder))
