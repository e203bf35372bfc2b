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
  cs=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
  timeout 240 "$cs" --tool memcheck --error-exitcode 3 ./build-new/spaceskip_core_tests \
    --gtest_filter="${MEMCHECK_FILTER:-DeviceImage.*:CudaBackend.*}" > "$out/memcheck.log" 2>&1
  log "memcheck rc=$?"
  tail -3 "$out/memcheck.log"
  timeout 120 "$cs" --tool racecheck --error-exitcode 3 ./build-new/spaceskip_core_tests \
    --gtest_filter="${RACECHECK_FILTER:-CudaBackend.SegmentedRaysRenderTheSameImage}" > "$out/racecheck.log" 2>&1
  log "racecheck rc=$?"
  tail -3 "$out/racecheck.log"
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
    [ -x "$bin" ] || { log "$bin missing"; continue; }
    name="batch${spec/:/-seg}-$n"
    env SPACESKIP_SAMPLE_BATCH="$b" "${seg[@]}" timeout 200 "$bin" bench --paper --datasets "$sets" \
      --builders "$items" --frames "${FRAMES:-8}" --csv "$out/$name.csv" > "$out/$name.log" 2>&1
    log "$name rc=$? SPACESKIP_SAMPLE_BATCH=$b ${seg[*]}"
  done
fi
{
  for f in "$out"/*.csv; do
    [ -f "$f" ] && { echo "== $f"; cut -d, -f1,6,7,13,14,17,18,26,33,34 "$f"; }
  done
} > "$out/summary.txt" 2>&1
cat "$out/summary.txt"
