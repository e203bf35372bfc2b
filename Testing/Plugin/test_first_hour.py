"""What a new user meets, side by side in one process against ParaView's own *Volume*, with the
stock defaults everywhere (default colour map and opacity ramp, Builder Auto, the backend this
machine has, the view ParaView's first Render gives):

- choosing "Space Skipping Volume" on a fresh display picks the colour array as *Volume* does
  (the view is never empty);
- a sparse volume whose background is exact zeros: occupancy < 0.2 under the default ramp and
  >= 3x the stock *Volume*'s frame rate;
- a dense volume (the Wavelet source): never slower than the stock *Volume* (ratio reported);
- images >= 40 dB against the stock *Volume* for both.

Frame times are medians of frames taken alternately (ours, stock, ours, ...) while the camera
turns 4 degrees a frame; the ratios are printed and, with --out FILE, written as a results table
(`pvpython Testing/Plugin/test_first_hour.py --out docs/results/cpu-vs-stock/latest.md`).
Usage: pvpython test_first_hour.py [--size N] [--frames K] [--out FILE]
"""
import argparse
import os
import platform
import statistics
import subprocess
import time

from paraview.simple import *
import ssptest

parser = argparse.ArgumentParser()
parser.add_argument("--size", type=int, default=192, help="edge of the generated volumes")
parser.add_argument("--frames", type=int, default=5, help="timed frames of each, alternately")
parser.add_argument("--view", type=int, default=400, help="view edge in pixels")
parser.add_argument("--out", default="", help="also write the results as a markdown table")
args = parser.parse_args()

ssptest.load_plugin()
ok = ssptest.Checker()
N = args.size


def shown(source, view, representation):
    """A fresh display of `source` switched to `representation` the way the GUI's menu does."""
    disp = Show(source, view)
    disp.SetRepresentationType(representation)
    return disp


def scene(source, name):
    """Ours and the stock Volume of `source`, each in its own view of the same size and camera.
    Returns the two views and our display."""
    views, disps = [], []
    for representation in ("Space Skipping Volume", "Volume"):
        view = ssptest.make_view((args.view, args.view), CreateView("RenderView"))
        disp = shown(source, view, representation)
        color = disp.ColorArrayName
        print("%s, %s: ColorArrayName %s" % (name, representation, list(color)))
        ok.check(color[1] != "", "%s, %s: a colour array is picked on the switch (%s)"
                 % (name, representation, color[1]))
        view.ResetCamera()
        views.append(view)
        disps.append(disp)
    copy_camera(views[0], views[1])  # the same camera for both
    return views, disps[0]


CAMERA = ("CameraPosition", "CameraFocalPoint", "CameraViewUp", "CameraViewAngle", "CameraParallelScale")


def copy_camera(src, dst):
    for name in CAMERA:
        dst.SetPropertyWithName(name, src.GetPropertyValue(name))


def turn(view, degrees):
    """The camera turned about the view-up axis through the focal point (vtkCamera::Azimuth)."""
    from vtkmodules.vtkRenderingCore import vtkCamera
    c = vtkCamera()
    c.SetPosition(view.CameraPosition)
    c.SetFocalPoint(view.CameraFocalPoint)
    c.SetViewUp(view.CameraViewUp)
    c.Azimuth(degrees)
    view.CameraPosition = c.GetPosition()
    view.CameraViewUp = c.GetViewUp()


def timed(view):
    t0 = time.perf_counter()
    Render(view)
    return time.perf_counter() - t0


def measure(views):
    """Median frame seconds of ours and stock, alternately, the camera turning 4 degrees a frame
    in both; the first frame of each (builds, uploads) is left out."""
    times = ([], [])
    for v in views:
        Render(v)
    for k in range(args.frames):
        for i in (k % 2, 1 - k % 2):  # each first in every other pair
            turn(views[i], 4.0)
            times[i].append(timed(views[i]))
    return statistics.median(times[0]), statistics.median(times[1])


def images(views, name):
    for v in views[1:]:
        copy_camera(views[0], v)
    a = ssptest.read_png(ssptest.render_to(views[0], "first_hour_%s_ours.png" % name))
    b = ssptest.read_png(ssptest.render_to(views[1], "first_hour_%s_stock.png" % name))
    return ssptest.psnr(a, b), ssptest.lit_fraction(a)


rows = []
# -- sparse: exact-zero background -------------------------------------------------------------
path = ssptest.temp_path("first_hour_sparse_%d.vti" % N)
nonzero = ssptest.write_sparse_vti(path, N, balls=((0.3, 0.35, 0.4, 0.18), (0.7, 0.6, 0.55, 0.15), (0.5, 0.75, 0.3, 0.12)),
                                   tube_radius=0.05)
sparse = XMLImageDataReader(FileName=[path])
views, ours = scene(sparse, "sparse")
t_ours, t_stock = measure(views)
p, lit = images(views, "sparse")
s = ssptest.stats(ours)
print("sparse %d^3 (%.1f%% non-zero voxels): ours %.3f s, stock Volume %.3f s: %.2fx; %.2f dB; "
      "occupancy %.3f; %s" % (N, 100 * nonzero, t_ours, t_stock, t_stock / t_ours, p, s["Occupancy"],
                              s["BuilderChoice"]))
ok.check(lit > 0.01, "sparse: the view is not empty (%.1f%% lit)" % (100 * lit))
ok.check(s["Occupancy"] < 0.2, "sparse, default ramp: occupancy %.3f < 0.2" % s["Occupancy"])
ok.check(t_stock / t_ours >= 3.0, "sparse: %.2fx the stock Volume (>= 3x)" % (t_stock / t_ours))
ok.check(p >= 40.0, "sparse: %.2f dB against the stock Volume (>= 40)" % p)
rows.append(("sparse %d^3, exact-zero background (%.1f%% non-zero)" % (N, 100 * nonzero), t_ours, t_stock,
             p, s["Occupancy"], s["BuilderChoice"]))
for v in views:
    Delete(v)

# -- dense: the Wavelet source ----------------------------------------------------------------
half = N // 2
dense = Wavelet(WholeExtent=[-half, N - half - 1] * 3)
views, ours = scene(dense, "dense")
t_ours, t_stock = measure(views)
p, lit = images(views, "dense")
s = ssptest.stats(ours)
print("dense Wavelet %d^3: ours %.3f s, stock Volume %.3f s: %.2fx; %.2f dB; occupancy %.3f; %s"
      % (N, t_ours, t_stock, t_stock / t_ours, p, s["Occupancy"], s["BuilderChoice"]))
ok.check(lit > 0.01, "dense: the view is not empty (%.1f%% lit)" % (100 * lit))
ok.check(t_stock / t_ours >= 1.0, "dense: %.2fx the stock Volume (>= 1.0x)" % (t_stock / t_ours))
ok.check(p >= 40.0, "dense: %.2f dB against the stock Volume (>= 40)" % p)
rows.append(("dense Wavelet %d^3" % N, t_ours, t_stock, p, s["Occupancy"], s["BuilderChoice"]))

if args.out:
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                                cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
    except OSError:
        commit = "?"
    with open(args.out, "w") as f:
        f.write("# Space Skipping Volume vs ParaView's Volume, stock defaults (pvpython)\n\n")
        f.write("Command: `pvpython Testing/Plugin/test_first_hour.py --size %d --frames %d --view %d "
                "--out %s` (PYTHONPATH=Testing/Plugin, SPACESKIP_* set as ctest sets them)\n\n"
                % (N, args.frames, args.view, args.out))
        f.write("Machine: %s, %d cores; %s; commit %s\n\n" % (platform.node() or "?", os.cpu_count(),
                                                             time.strftime("%Y-%m-%d"), commit))
        f.write("| scene | ours (s/frame) | stock Volume (s/frame) | speed-up | PSNR vs stock | occupancy | Builder Choice |\n")
        f.write("|---|---|---|---|---|---|---|\n")
        for name, a, b, p, occ, choice in rows:
            f.write("| %s | %.3f | %.3f | %.2fx | %.1f dB | %.3f | %s |\n" % (name, a, b, b / a, p, occ, choice))
ok.done()
