#!/usr/bin/env bash
# Issue 13, round 12: the opacity edit's path at N-body 2048^3 without GL (`spaceskip bench
# --edits`: classification, of it the wait for the device, build, the edit's frame and the one
# after), the binaries before (build-bench/old.tar.xz, when carried) beside the new ones
# (build-bench/both.tar.xz) in one device call, one process per item list, alternated.
# Carried as cli-and-tests.sh: build-bench (the tar files, lib/), .deps/tbb.
# Results: docs/results/round12-h100/NOTES.md. The column tool is not on the device: raw CSV.
#
#   Testing/gpu/round12.sh OUTDIR [phases]
#   phases (default: tests memcheck edits ncu): tests memcheck edits all maxset ncurender ncu
#   env: DEADLINE (epoch s: no phase starts after), EDITS (16), ITEMS (distance-grid,distance-grid:hw,auto)
# Built on the device from the carried tree (quick-build.sh, into build-gpu) when
# build-bench/both.tar.xz is not carried.
set -uo pipefail
out=${1:?usage: round12.sh OUTDIR [phases]}
shift
phases=${*:-tests memcheck edits ncu}
if [ ! -f "$(dirname "$0")/../../build-bench/both.tar.xz" ]; then
  mkdir -p "$out" build-new
  BUILD_DIR=$PWD/build-gpu bash "$(dirname "$0")/quick-build.sh" "$out/build.log" || { tail -30 "$out/build.log"; exit 1; }
  cp build-gpu/Core/spaceskip build-gpu/Testing/spaceskip_core_tests build-new/
fi
source "$(dirname "$0")/ab-common.sh"
if has memcheck && ! late; then
  cs=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
  timeout 240 "$cs" --tool memcheck --error-exitcode 3 ./build-new/spaceskip_core_tests \
    --gtest_filter="SubMasks*:CudaBackend.*:DeviceImage.*" > "$out/memcheck.log" 2>&1
  log "memcheck rc=$?"
  tail -2 "$out/memcheck.log"
fi
items=${ITEMS:-distance-grid,distance-grid:hw,auto}
bench() {  # name binary [env...]
  local name=$1 bin=$2
  shift 2
  env "$@" timeout 150 "$bin" bench --paper --datasets nbody_2048 --builders "$items" --frames 8 \
    --edits "${EDITS:-16}" --csv "$out/nb-$name.csv" > "$out/nb-$name.log" 2>&1
  log "edits $name rc=$? $*"
}
# The part ranges on (default) and off (SPACESKIP_PART_RANGES=0: masks from the voxels on the
# frame after the edit's, as before), same binary, alternated; then the old binary when carried.
if has edits && ! late; then
  bench ranges0 build-new/spaceskip SPACESKIP_PART_RANGES=0
  bench ranges1 build-new/spaceskip
  bench ranges0b build-new/spaceskip SPACESKIP_PART_RANGES=0
  bench ranges1b build-new/spaceskip
  [ -x build-old/spaceskip ] && bench old build-old/spaceskip
fi
# Every stand-in of the paper (its dims), DistanceGrid and Auto, 4 edits each, part ranges off
# and on: the edits, the frames (unchanged path), and the device memory in use (the bounds).
if has all && ! late; then
  all=aneurism,xmas_tree,magnetic,stag_beetle,kingsnake,menger_sponge,richtmyer_meshkov,nbody_256,nbody_512,nbody_1024,nbody_2048
  for r in 0 1; do
    SPACESKIP_PART_RANGES=$r timeout 280 build-new/spaceskip bench --paper --datasets "$all" \
      --builders distance-grid,auto --frames 8 --edits 4 --csv "$out/all-ranges$r.csv" > "$out/all-ranges$r.log" 2>&1
    log "all ranges$r rc=$?"
  done
fi
# The most set parts a brick may have to be walked part by part (SPACESKIP_SUB_MASK_MAX, default
# 24 of 64), every stand-in, one process per setting, alternated: MAXSETS (e.g. "24 64 40 24 64 40").
if has maxset && ! late; then
  all=aneurism,xmas_tree,magnetic,stag_beetle,kingsnake,menger_sponge,richtmyer_meshkov,nbody_256,nbody_512,nbody_1024,nbody_2048
  n=0
  for m in ${MAXSETS:-24 64 40 24 64 40}; do
    n=$((n + 1))
    late && break
    SPACESKIP_SUB_MASK_MAX=$m timeout 200 build-new/spaceskip bench --paper --datasets "$all" \
      --builders distance-grid,distance-grid:hw,auto --frames 8 --csv "$out/maxset$m-$n.csv" > "$out/maxset$m-$n.log" 2>&1
    log "maxset $m ($n) rc=$?"
  done
fi
# Nsight Compute on one frame of the part walk at N-body 2048^3 (DistanceGrid, hardware filter):
# where the kernel's time goes now (the window's remaining goal is its frame rate).
if has ncurender && ! late; then
  ncu=$(command -v ncu || ls /usr/local/cuda/bin/ncu 2>/dev/null)
  timeout 200 "$ncu" -k regex:"render" --launch-skip 4 --launch-count 1 --section SpeedOfLight \
    --section Occupancy --section LaunchStats --section WarpStateStats --section MemoryWorkloadAnalysis \
    build-new/spaceskip bench gen:nbody:2048 --backend cuda --builders distance-grid:hw --frames 4 \
    > "$out/ncu-render.txt" 2>&1
  log "ncu render rc=$?"
fi
if has ncu && ! late; then
  ncu=$(command -v ncu || ls /usr/local/cuda/bin/ncu 2>/dev/null)
  timeout 150 "$ncu" -k regex:"classifyKernel|subMaskKernel|rangeMaskKernel|partRangeKernel|stagedLineKernel" --launch-count 12 \
    --metrics gpu__time_duration.sum,dram__throughput.avg.pct_of_peak_sustained_elapsed \
    build-new/spaceskip bench gen:nbody:2048 --backend cuda --builders distance-grid --frames 2 --edits 4 \
    > "$out/ncu-new.txt" 2>&1
  log "ncu rc=$?"
fi
{
  grep -h "edits:" "$out"/nb-*.log "$out"/all-*.log
  for f in "$out"/nb-*.csv "$out"/all-*.csv "$out"/maxset*.csv; do
    [ -f "$f" ] && { echo "== $f"; cut -d, -f6,7,14,17,18,33- "$f"; }
  done
  grep -h "time_duration\|Kernel\|  [a-zA-Z]*Kernel" "$out"/ncu-*.txt 2>/dev/null
} > "$out/summary.txt" 2>&1
cat "$out/summary.txt"
