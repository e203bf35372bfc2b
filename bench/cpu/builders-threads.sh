#!/usr/bin/env bash
# Build time vs oneTBB threads with interleaved repeats (robust against other load on a shared
# machine): REPS runs per thread count, alternating, each the fastest of 5 rebuilds.
# usage: bench/cpu/builders-threads.sh OUT_DIR [SPACESKIP_BINARY]   (THREADS="1 2", REPS=5)
set -euo pipefail
out=${1:?usage: $0 OUT_DIR [SPACESKIP_BINARY]}
bin=${2:-build/Core/spaceskip}
mkdir -p "$out"
for rep in $(seq 1 "${REPS:-5}"); do
  for th in ${THREADS:-1 2}; do
    echo "== rep $rep threads $th ($(uptime))" >> "$out/threads.txt"
    "$bin" bench gen:menger:256 --brick 1 --builders lbvh-cpu,kdtree-cpu:shallow,kdtree-cpu:deep:mls32 \
      --size 16x16 --frames 1 --build-reps 5 --threads "$th" --json "$out/threads-r$rep-t$th.json" >> "$out/threads.txt"
  done
done
python3 - "$out" <<'PY'
import glob, json, statistics, sys
out = sys.argv[1]
by = {}
for f in sorted(glob.glob(out + "/threads-r*-t*.json")):
    th = int(f.rsplit("-t", 1)[1].split(".")[0])
    for r in json.load(open(f)):
        by.setdefault((r["variant"], th), []).append(r["build_s"] * 1e3)
ths = sorted({t for _, t in by})
print("| menger:256, brick 1 | " + " | ".join(f"{t} thread(s): median (min–max) ms" for t in ths) + " | median 1T / 2T |")
print("|---|" + "---:|" * (len(ths) + 1))
for v in dict.fromkeys(k[0] for k in by):
    cells = [f"{statistics.median(by[(v, t)]):.1f} ({min(by[(v, t)]):.1f}–{max(by[(v, t)]):.1f})" for t in ths]
    ratio = statistics.median(by[(v, ths[0])]) / statistics.median(by[(v, ths[-1])])
    print(f"| {v} | " + " | ".join(cells) + f" | {ratio:.2f} |")
PY
