"""The longest single interaction a ParaView user waits for, on the CPU backend: a sparse N^3
volume (exact-zero background) loaded, shown as "Space Skipping Volume" with stock defaults, then
a camera drag, an opacity edit and a colour edit, each timed as the one still render ParaView does
for it; ParaView's progress events during each step are recorded (time, fraction, text), as the
GUI's progress bar receives them.

Usage (from the repository root, an X server on DISPLAY):
  PYTHONPATH=Testing/Plugin SPACESKIP_PLUGIN=build/lib/paraview-5.11/plugins/SpaceSkip/SpaceSkip.so \
  SPACESKIP_TEMP=/tmp/ss SPACESKIP_DATA=Data pvpython bench/cpu/interactions.py [--size 512] [--out FILE]
"""
import argparse
import os
import platform
import subprocess
import time

from paraview.simple import *
from paraview import servermanager
import ssptest

parser = argparse.ArgumentParser()
parser.add_argument("--size", type=int, default=512)
parser.add_argument("--view", type=int, nargs=2, default=[800, 600])
parser.add_argument("--out", default="")
parser.add_argument("--limit", type=float, default=2.0, help="seconds an interaction may take")
parser.add_argument("--dense", action="store_true", help="ParaView's Wavelet source (dense) instead of the sparse file")
args = parser.parse_args()
N = args.size


events = []  # (seconds since the step began, fraction, text)
step_start = [0.0]


def on_progress(handler, _event):
    events.append((time.perf_counter() - step_start[0], handler.GetLastProgress() / 100.0,
                   handler.GetLastProgressText() or ""))


handler = servermanager.ActiveConnection.Session.GetProgressHandler()
handler.AddObserver("ProgressEvent", on_progress)

results = []


def step(name, action):
    del events[:]
    step_start[0] = time.perf_counter()
    action()
    seconds = time.perf_counter() - step_start[0]
    ours = [e for e in events if e[2].startswith("Space Skipping")]
    fractions = [e[1] for e in ours]
    # The longest wait between progress updates (from the step's start to its end).
    marks = [0.0] + [e[0] for e in ours] + [seconds]
    gap = max(b - a for a, b in zip(marks, marks[1:]))
    print("%-28s %.3f s; %d progress events of ours (%s), longest gap %.3f s"
          % (name, seconds, len(ours), ", ".join("%.2f" % f for f in fractions[:12]), gap))
    results.append((name, seconds, len(ours), gap))
    return seconds


ssptest.load_plugin()
if args.dense:
    reader = Wavelet(WholeExtent=[-(N // 2), N - N // 2 - 1] * 3)
    ARRAY = "RTData"
    print("volume: Wavelet %d^3 (dense)" % N)
else:
    path = ssptest.temp_path("interactions_%d.vti" % N)
    t0 = time.perf_counter()
    nonzero = ssptest.write_sparse_vti(path, N) if not os.path.exists(path) else -1
    print("volume %d^3 written in %.1f s (%s non-zero)" % (N, time.perf_counter() - t0,
                                                           "%.1f%%" % (100 * nonzero) if nonzero >= 0 else "cached"))
    reader = XMLImageDataReader(FileName=[path])
    ARRAY = "density"
view = CreateView("RenderView")
view.ViewSize = args.view
view.EnableRenderOnInteraction = 0
disp = Show(reader, view)
step("read the file (ParaView)", lambda: reader.UpdatePipeline())
Render(view)  # the outline, as after Apply


def choose():
    disp.SetRepresentationType("Space Skipping Volume")
    view.ResetCamera()
    Render(view)


step("choose the representation", choose)
s = ssptest.stats(disp)
print("  ", s["BuilderChoice"], "| occupancy %.3f" % s["Occupancy"])


def drag():
    view.CameraPosition = [p + d for p, d in zip(view.CameraPosition, (0.15 * N, 0.05 * N, 0))]
    Render(view)


step("drag the camera", drag)
pwf = GetOpacityTransferFunction(ARRAY)


def opacity_edit():
    pts = list(pwf.Points)
    mid = 0.5 * (pts[0] + pts[-4])
    pwf.Points = pts[:4] + [mid, 0.2, 0.5, 0.0] + pts[4:]
    Render(view)


step("opacity edit", opacity_edit)
lut = GetColorTransferFunction(ARRAY)


def colour_edit():
    lut.ApplyPreset("Viridis (matplotlib)", True)
    Render(view)


step("colour edit", colour_edit)
s = ssptest.stats(disp)
print("  ", s["BuilderChoice"], "| occupancy %.3f" % s["Occupancy"])

ours = [r for r in results if not r[0].startswith("read")]
longest = max(ours, key=lambda r: r[1])
slow_without_progress = [r for r in ours if r[1] > 0.5 and r[3] > 0.5]
print("longest interaction: %s %.3f s (limit %.1f s); steps over 0.5 s with a gap in progress over 0.5 s: %s"
      % (longest[0], longest[1], args.limit, [r[0] for r in slow_without_progress] or "none"))
if args.out:
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    with open(args.out, "w") as f:
        f.write("# Interactions on a %s %d^3 volume, CPU backend (pvpython)\n\n" % ("dense" if args.dense else "sparse", N))
        f.write("Command: `pvpython bench/cpu/interactions.py --size %d%s --out %s` (PYTHONPATH=Testing/Plugin, "
                "SPACESKIP_PLUGIN, SPACESKIP_TEMP set)\n\n" % (N, " --dense" if args.dense else "", args.out))
        f.write("Machine: %s, %d cores, no GPU; %s; commit %s; view %dx%d\n\n"
                % (platform.node() or "?", os.cpu_count(), time.strftime("%Y-%m-%d"), commit, *args.view))
        f.write("| step | seconds | progress events (ours) | longest wait between progress updates (s) |\n")
        f.write("|---|---|---|---|\n")
        for name, sec, n, gap in results:
            f.write("| %s | %.3f | %d | %.3f |\n" % (name, sec, n, gap))
        f.write("\nBuilder Choice after the edits: %s\n" % s["BuilderChoice"])
