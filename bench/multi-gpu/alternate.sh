#!/usr/bin/env bash
# A/B of one run.sh setting in one hold: runs bench/multi-gpu/run.sh once per value of VAR, in
# turn, REPEATS times (v1, v2, ..., v1, v2, ...), so that a drift of the machine falls on every
# value alike, and prints one line per run: the value, the repeat, the ranks, fps, the frame, rank
# 0's kernel and its longest block over the orbit (run.sh's other settings come from the
# caller's environment: RANKS, SPLITS, CHECK, FRAMES, SIZE, ...).
#
#   VAR=RAY_SEGMENTS VALUES="4 8" REPEATS=2 RANKS="1 2" SPLITS=image CHECK=0 \
#     bash bench/multi-gpu/alternate.sh OUTDIR nbody:2048
set -u
out=${1:?usage: VAR=NAME VALUES="A B" [REPEATS=2] alternate.sh OUTDIR [SCENES...]}
shift
var=${VAR:?VAR names the run.sh setting}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
status=0
for rep in $(seq 1 "${REPEATS:-2}"); do
  for v in ${VALUES:?VALUES lists its values}; do
    dir="$out/$var-$v-$rep"
    env "$var=$v" bash "$here/run.sh" "$dir" "$@" > /dev/null 2>&1 || status=1
    for log in "$dir"/*.log; do
      [ -f "$log" ] || continue
      awk -v tag="$var=$v run $rep $(basename "$log" .log)" '
        /^frame_ms/ { fps = $4; frame = $2 }
        /^rank0 render_call_ms/ { kernel = $5; longest = $7 }
        /^check:/ { check = $0 }
        END { printf "%s: fps %s frame_ms %s kernel_ms %s longest_block_ms %s %s\n", tag, fps, frame, kernel, longest,
              check }' "$log" |
        tee -a "$out/summary.txt"
    done
  done
done
exit $status
