"""Where ParaView's own parallel frame goes: the medians, per rank, of the scopes and IceT timers
that ParaView logs with PARAVIEW_LOG_RENDERING_VERBOSITY=INFO (pvbatch's stderr):

  frame        vtkPVRenderView::Render (the view's whole frame on that rank; serial pvbatch: rank 0)
  icet pass    vtkIceTCompositePass::Render (the scene drawn into IceT's buffer, read back,
               composited, collected on rank 0)
  ICET_*       IceT's own timers within that pass (RENDER: the draw and read-back; COMPRESS,
               BLEND, COLLECT, COMPOSITE: the compositing)

  PARAVIEW_LOG_RENDERING_VERBOSITY=INFO mpirun -n 2 pvbatch bench/pvbatch-orbit.py ... 2> log
  python3 bench/pv-frame-phases.py log [--skip 2]
"""
import argparse
import re
import statistics
from collections import defaultdict

parser = argparse.ArgumentParser()
parser.add_argument("log")
parser.add_argument("--skip", type=int, default=2, help="leave out each rank's first frames")
args = parser.parse_args()

ansi = re.compile(r"\x1b\[[0-9;]*m")
rank_re = re.compile(r"\[pvbatch(?:\.(\d+))?\s*\]")  # serial pvbatch: no rank
scope_re = re.compile(r"\} ([0-9.]+) s: (.*)$")
icet_re = re.compile(r"(ICET_[A-Z_]+_TIME): ([0-9.]+)")
values = defaultdict(lambda: defaultdict(list))
for raw in open(args.log, errors="replace"):
    line = ansi.sub("", raw.rstrip("\n"))
    r = rank_re.search(line)
    if not r:
        continue
    rank = int(r.group(1) or 0)
    m = scope_re.search(line)
    if m:
        name = m.group(2)
        if name.startswith("Render(interactive=false"):
            values[rank]["frame"].append(float(m.group(1)))
        elif "vtkIceTCompositePass" in name and name.endswith(": Render"):
            values[rank]["icet pass"].append(float(m.group(1)))
        continue
    m = icet_re.search(line)
    if m:
        values[rank][m.group(1)].append(float(m.group(2)))

if not values:
    raise SystemExit("pv-frame-phases: no ParaView rendering log in %s "
                     "(PARAVIEW_LOG_RENDERING_VERBOSITY=INFO)" % args.log)
for rank in sorted(values):
    parts = []
    med = {}
    for name, v in values[rank].items():
        v = v[args.skip:] or v
        med[name] = statistics.median(v)
        parts.append("%s %.3f" % (name.lower().replace("icet_", "").replace("_time", ""), 1e3 * med[name]))
    if "frame" in med:
        # What the view spends outside IceT's pass: the ranks' synchronisation, the composited
        # image pasted into the window, the passes around it.
        parts.append("outside icet %.3f" % (1e3 * (med["frame"] - med.get("icet pass", 0.0))))
    print("PV_FRAME_PHASES rank %d (median ms, %d frames): %s"
          % (rank, len(values[rank]["frame"]), ", ".join(parts)))
