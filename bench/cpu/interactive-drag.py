"""A camera drag as ParaView draws it: interactive renders (the view's InteractiveRender, the
render window's DesiredUpdateRate at 5) while the camera turns, then the still render where the
user lets go. Ours (CPU backend) with Coarser Sampling While Interacting on and off, and
ParaView's own Volume, on the same dense volume in one process, frame by frame alternated per
drag; the medians and their ratios, the sample distance each interactive frame of ours used, and
the still image after the drag against the still image before it (the same picture).

Usage (from the repository root, an X server on DISPLAY):
  PYTHONPATH=Testing/Plugin SPACESKIP_PLUGIN=build/lib/paraview-5.11/plugins/SpaceSkip/SpaceSkip.so \
  SPACESKIP_TEMP=/tmp/ss pvpython bench/cpu/interactive-drag.py [--size 256] [--frames 12] [--out FILE]
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
parser.add_argument("--size", type=int, default=256)
parser.add_argument("--view", type=int, nargs=2, default=[800, 600])
parser.add_argument("--frames", type=int, default=12, help="interactive frames per drag")
parser.add_argument("--drags", type=int, default=3, help="drags per configuration, alternated")
parser.add_argument("--no-stock", action="store_true", help="leave ParaView's own Volume out")
parser.add_argument("--shade", action="store_true", help="Shade on (ParaView's light kit)")
parser.add_argument("--out", default="")
args = parser.parse_args()
N = args.size

ssptest.load_plugin()
source, view, disp = ssptest.dense_wavelet_scene(N, args.view)
disp.SetRepresentationType("Space Skipping Volume")
disp.Backend = "CPU"
disp.Shade = 1 if args.shade else 0
view.ResetCamera()
Render(view)
print("volume: Wavelet %d^3 (dense)%s, view %dx%d, %d cores" % (N, ", shaded" if args.shade else "", args.view[0], args.view[1], os.cpu_count()))


def drag(frames):
    """Turns the camera by 2 degrees per interactive frame; returns each frame's seconds and,
    for ours, the sample distance it asked for; then the still render where the drag ends."""
    times, used = [], []
    cam = GetActiveCamera()
    for _ in range(frames):
        cam.Azimuth(2.0)
        t0 = time.perf_counter()
        view.SMProxy.InteractiveRender()
        times.append(time.perf_counter() - t0)
        if disp.Representation == "Space Skipping Volume":
            used.append(ssptest.stats(disp)["SampleDistanceUsed"])
    t0 = time.perf_counter()
    Render(view)
    return times, used, time.perf_counter() - t0


configs = [("ours, coarser sampling while interacting (default)", "Space Skipping Volume", 1),
           ("ours, coarser sampling off", "Space Skipping Volume", 0)]
if not args.no_stock:
    configs.append(("ParaView's Volume", "Volume", None))
results = {name: ([], [], []) for name, _, _ in configs}
for d in range(args.drags):
    for name, rep, coarse in configs:
        disp.SetRepresentationType(rep)
        if coarse is not None:
            disp.InteractiveSampling = coarse
        Render(view)  # the representation's first frame is not a drag's
        times, used, still = drag(args.frames)
        results[name][0].extend(times[1:])  # a drag's first frame follows a still one
        results[name][1].extend(used[1:])
        results[name][2].append(still)
        print("drag %d, %-52s interactive median %.3f s (%d frames), still %.3f s%s"
              % (d + 1, name, statistics.median(times[1:]), len(times) - 1, still,
                 ", sample distance %s" % sorted(set("%.3g" % u for u in used[1:])) if used else ""))

ref = configs[0][0]
lines = []
for name, _, _ in configs:
    times, used, stills = results[name]
    med = statistics.median(times)
    lines.append("| %s | %.3f | %.2f | %.3f | %s |" % (
        name, med, statistics.median(results[ref][0]) and med / statistics.median(results[ref][0]),
        statistics.median(stills), ", ".join(sorted(set("%.3g" % u for u in used))) or "-"))
header = ("| configuration | interactive frame, median (s) | / ours (default) | still frame after the drag, median (s) "
          "| sample distances of the interactive frames |\n|---|---|---|---|---|")
print(header)
print("\n".join(lines))

# The still picture after a drag is the exact one: ours, coarse on, against coarse off.
disp.SetRepresentationType("Space Skipping Volume")
disp.InteractiveSampling = 0
Render(view)
a_path = ssptest.temp_path("interactive_drag_off.png")
SaveScreenshot(a_path, view, ImageResolution=args.view)
disp.InteractiveSampling = 1
drag(3)
# The drag turned the camera by 6 degrees: turn it back and compare the still renders.
GetActiveCamera().Azimuth(-6.0)
b_path = ssptest.temp_path("interactive_drag_on.png")
SaveScreenshot(b_path, view, ImageResolution=args.view)
a = ssptest.read_png(a_path)
b = ssptest.read_png(b_path)
diff = abs(a.astype(int) - b.astype(int)).max()
print("still render after a drag (turned back) vs still render without coarser sampling: max |diff| %d/255" % diff)

if args.out:
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    with open(args.out, "w") as f:
        f.write("# Interactive renders during a camera drag, dense Wavelet %d^3%s, CPU backend (pvpython)\n\n"
                % (N, ", shaded" if args.shade else ""))
        f.write("Command: `pvpython bench/cpu/interactive-drag.py --size %d --frames %d --drags %d%s --out %s` "
                "(PYTHONPATH=Testing/Plugin, SPACESKIP_PLUGIN, SPACESKIP_TEMP set)\n\n"
                % (N, args.frames, args.drags, " --shade" if args.shade else "", args.out))
        f.write("Machine: %s, %d cores, no GPU (ParaView's Volume on Mesa llvmpipe); %s; commit %s; view %dx%d\n\n"
                % (platform.node() or "?", os.cpu_count(), time.strftime("%Y-%m-%d"), commit, *args.view))
        f.write(header + "\n" + "\n".join(lines) + "\n\n")
        f.write("Still render after a drag (the camera turned back) against one without coarser sampling: "
                "max |diff| %d/255.\n" % diff)
