#!/usr/bin/env bash
# Issue 13, round 11: the distance field's passes staging their lines in 16-byte pieces and the
# transfer table's upload without a host wait (an opacity edit's path), the binaries before
# (build-bench/old.tar.xz: round 10's final build) beside the new ones (build-bench/both.tar.xz)
# in one device call, one process per item list, alternated.
# Carried as cli-and-tests.sh: build-bench (both tar files, lib/libpng16), .deps/tbb.
# Results: docs/results/round11-h100/NOTES.md. The column tool is not on the device: raw CSV.
#
#   Testing/gpu/round11.sh OUTDIR [phases]
#   phases (default all): tests memcheck nbody cap ncu
#   env: DEADLINE (epoch s: no phase starts after)
set -uo pipefail
out=${1:?usage: round11.sh OUTDIR [phases]}
shift
phases=${*:-tests memcheck nbody cap ncu}
source "$(dirname "$0")/ab-common.sh"
if has memcheck && ! late; then
  cs=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
  timeout 240 "$cs" --tool memcheck --error-exitcode 3 ./build-new/spaceskip_core_tests \
    --gtest_filter="DistanceField.TheCuda*:CudaBackend.OpacityEdit*:DeviceImage.*" > "$out/memcheck.log" 2>&1
  log "memcheck rc=$?"
  timeout 150 "$cs" --tool racecheck --error-exitcode 3 ./build-new/spaceskip_core_tests \
    --gtest_filter="DistanceField.TheCuda*" > "$out/racecheck.log" 2>&1
  log "racecheck rc=$?"
  tail -2 "$out/memcheck.log" "$out/racecheck.log"
fi
# N-body 2048^3, the paper's protocol, one process per binary / setting.
items=distance-grid,distance-grid:hw,auto
bench() {  # name binary items [env...]
  local name=$1 bin=$2 its=$3
  shift 3
  env "$@" timeout 120 "$bin" bench --paper --datasets nbody_2048 --builders "$its" --frames 8 \
    --csv "$out/nb-$name.csv" > "$out/nb-$name.log" 2>&1
  log "nbody $name rc=$? $*"
}
if has nbody && ! late; then
  bench old build-old/spaceskip "$items"
  bench new build-new/spaceskip "$items"
  bench new2 build-new/spaceskip "$items"
  bench old2 build-old/spaceskip "$items"
  bench new3 build-new/spaceskip "$items"
fi
if has cap && ! late; then
  bench new-cap16 build-new/spaceskip "$items" SPACESKIP_DG_CAP=16
  bench old-cap16 build-old/spaceskip "$items" SPACESKIP_DG_CAP=16
fi
# Nsight Compute: the distance field's passes and the classification (durations).
if has ncu && ! late; then
  ncu=$(command -v ncu || ls /usr/local/cuda/bin/ncu 2>/dev/null)
  for v in old new; do
    timeout 120 "$ncu" -k regex:"stagedLineKernel|classifyKernel" --launch-count 4 \
      --metrics gpu__time_duration.sum,sm__warps_active.avg.pct_of_peak_sustained_active,dram__throughput.avg.pct_of_peak_sustained_elapsed \
      build-$v/spaceskip bench gen:nbody:2048 --backend cuda --builders distance-grid --frames 2 \
      > "$out/ncu-dg-$v.txt" 2>&1
    log "ncu $v rc=$?"
  done
fi
for f in "$out"/nb-*.csv; do
  [ -f "$f" ] && { echo "== $f"; cut -d, -f6,7,14,17,18 "$f"; }
done > "$out/summary.txt" 2>&1
grep -h "time_duration\|Kernel" "$out"/ncu-dg-*.txt >> "$out/summary.txt" 2>/dev/null
cat "$out/summary.txt"
