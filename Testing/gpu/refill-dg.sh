#!/usr/bin/env bash
# Issue 13, round 10: the distance field's segmented passes (faster rebuilds after a TF edit
# that occupies bricks) and the part walk's lane refill (refillKernel), the binaries before
# (build-bench/old.tar.xz) beside the new ones (build-bench/both.tar.xz) in one device call.
# Carried as cli-and-tests.sh: build-bench (both tar files, lib/libpng16), .deps/tbb.
# The refill kernel lives on the branch refill-experiment (3x slower, not merged): on main's
# binaries SPACESKIP_CUDA_REFILL is ignored, so the refill phase and "new-refill0" are repeats.
# Results: docs/results/round10-h100/NOTES.md. The column tool is not on the device: raw CSV.
#
#   Testing/gpu/refill-dg.sh OUTDIR [phases]
#   phases (default all): tests memcheck nbody segs refill paper ncu
#   env: PAPER_DATASETS (the data sets of the paper A/B, default all but N-body 2048^3),
#        PAPER_BUILDERS (naive,grid,distance-grid,auto), DEADLINE (epoch s: no phase starts after)
set -uo pipefail
out=${1:?usage: refill-dg.sh OUTDIR [phases]}
shift
phases=${*:-tests memcheck nbody segs refill paper ncu}
source "$(dirname "$0")/ab-common.sh"
if has memcheck && ! late; then
  cs=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
  timeout 200 "$cs" --tool memcheck --error-exitcode 3 ./build-new/spaceskip_core_tests \
    --gtest_filter="DistanceField.TheCuda*:CudaBackend.LaneRefill*:CudaBackend.PartWalk*" > "$out/memcheck.log" 2>&1
  log "memcheck rc=$?"
  timeout 120 "$cs" --tool racecheck --error-exitcode 3 ./build-new/spaceskip_core_tests \
    --gtest_filter="DistanceField.TheCuda*:CudaBackend.LaneRefill*" > "$out/racecheck.log" 2>&1
  log "racecheck rc=$?"
  tail -2 "$out/memcheck.log" "$out/racecheck.log"
fi
# N-body 2048^3, the paper's protocol, one process per binary / setting.
items=distance-grid,distance-grid:hw,grid:hw,auto
bench() {  # name binary items [env...]
  local name=$1 bin=$2 its=$3
  shift 3
  env "$@" timeout 120 "$bin" bench --paper --datasets nbody_2048 --builders "$its" --frames 8 \
    --csv "$out/nb-$name.csv" > "$out/nb-$name.log" 2>&1
  log "nbody $name rc=$? $*"
}
if has nbody && ! late; then
  [ -x build-old/spaceskip ] && bench old build-old/spaceskip "$items"
  bench new-refill0 build-new/spaceskip "$items" SPACESKIP_CUDA_REFILL=0
  bench new build-new/spaceskip "$items"
  [ -x build-old/spaceskip ] && bench old2 build-old/spaceskip "$items"
  bench new2 build-new/spaceskip "$items"
fi
if has segs && ! late; then
  for s in 1 2 4; do bench "segs$s" build-new/spaceskip distance-grid SPACESKIP_DG_SEGMENTS=$s; done
fi
if has refill && ! late; then
  for r in 1 4 16 32; do bench "refill$r" build-new/spaceskip distance-grid:hw,grid:hw SPACESKIP_CUDA_REFILL=$r; done
fi
# The paper's other stand-ins: the new binaries change the march's code for every kernel (one
# step factored out) and run the refill where frames walk parts.
if has paper && ! late; then
  for v in old new; do
    [ -x build-$v/spaceskip ] || continue
    mkdir -p "$out/paper-$v"
    timeout 240 build-$v/spaceskip bench --paper --backend cuda --frames 8 --time-limit 200 \
      --datasets "${PAPER_DATASETS:-aneurism,xmas_tree,magnetic,stag_beetle,kingsnake,menger_sponge,richtmyer_meshkov,nbody_256,nbody_512,nbody_1024}" \
      --builders "${PAPER_BUILDERS:-naive,grid,distance-grid,auto}" \
      --csv "$out/paper-$v/paper.csv" > "$out/paper-$v/bench.log" 2>&1
    log "paper $v rc=$?"
  done
fi
# Nsight Compute: the distance field's passes (durations) and the refill kernel (lanes, occupancy).
if has ncu && ! late; then
  ncu=$(command -v ncu || ls /usr/local/cuda/bin/ncu 2>/dev/null)
  timeout 150 "$ncu" -k regex:"stagedLineKernel|markKernel|classifyKernel" --launch-count 8 \
    --metrics gpu__time_duration.sum,sm__warps_active.avg.pct_of_peak_sustained_active \
    build-new/spaceskip bench gen:nbody:2048 --backend cuda --builders distance-grid --frames 2 \
    > "$out/ncu-dg.txt" 2>&1
  log "ncu dg rc=$?"
  timeout 150 "$ncu" -k regex:"refillKernel|renderKernel" --launch-skip 2 --launch-count 1 \
    --section SpeedOfLight --section Occupancy --section LaunchStats --section WarpStateStats \
    --metrics smsp__thread_inst_executed_per_inst_executed.ratio,gpu__time_duration.sum \
    build-new/spaceskip bench gen:nbody:2048 --backend cuda --builders distance-grid:hw --frames 3 \
    > "$out/ncu-refill.txt" 2>&1
  log "ncu refill rc=$?"
fi
for f in "$out"/nb-*.csv; do
  [ -f "$f" ] || continue
  echo "== $(basename "$f")"
  cut -d, -f6,14,17,18,28,32 "$f"
done
