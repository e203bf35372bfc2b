#!/usr/bin/env bash
# Issue 13, round 14: samples fetched in batches (FrameView::sampleBatch, IntervalMarcher::
# takeBatch) — the same binary, one process per batch size, alternated, the paper's protocol
# (kernel fps from CUDA events). Carried like round13.sh: build-bench (both.tar.xz: stripped
# spaceskip + spaceskip_core_tests; lib/), .deps/tbb. Results: docs/results/round14-h100/NOTES.md.
#
#   Testing/gpu/round14.sh OUTDIR [phases]
#   phases (default: tests batch): tests (Core tests, then compute-sanitizer memcheck on
#          MEMCHECK_FILTER and racecheck on RACECHECK_FILTER), batch
#   env: DEADLINE (epoch s: no phase starts after), BATCHES ("old 4 1 old 4 1":
#        SPACESKIP_SAMPLE_BATCH per process; B:K also sets SPACESKIP_RAY_SEGMENTS=K; "old": the
#        binary build-old/spaceskip, e.g. the previous head's, carried in an earlier call to the
#        same machine), DATASETS, ITEMS, FRAMES (8)
set -uo pipefail
out=${1:?usage: round14.sh OUTDIR [phases]}
shift
phases=${*:-tests batch}
source "$(dirname "$0")/ab-common.sh"
if has tests && ! late; then
  sanitize memcheck "${MEMCHECK_FILTER:-DeviceImage.*:CudaBackend.*}"
  sanitize racecheck "${RACECHECK_FILTER:-CudaBackend.SegmentedRaysRenderTheSameImage}" 120
fi
sets=${DATASETS:-nbody_2048,nbody_1024,menger_sponge,richtmyer_meshkov,kingsnake}
items=${ITEMS:-naive,distance-grid,distance-grid:hw,auto}
if has batch; then
  n=0
  for spec in ${BATCHES:-old 4 1 old 4 1}; do
    n=$((n + 1))
    late && break
    b=${spec%%:*}
    seg=()
    [ "$spec" != "$b" ] && seg=(SPACESKIP_RAY_SEGMENTS="${spec#*:}")
    bin=build-new/spaceskip
    [ "$b" = old ] && bin=build-old/spaceskip
    [[ "$b" =~ ^[0-9]+$ ]] && seg+=(SPACESKIP_SAMPLE_BATCH="$b")
    [ -x "$bin" ] || { log "$bin missing"; continue; }
    name="batch${spec/:/-seg}-$n"
    env "${seg[@]}" timeout 200 "$bin" bench --paper --datasets "$sets" \
      --builders "$items" --frames "${FRAMES:-8}" --csv "$out/$name.csv" > "$out/$name.log" 2>&1
    log "$name rc=$? ${seg[*]}"
  done
fi
summarize
