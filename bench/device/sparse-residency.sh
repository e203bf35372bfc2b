#!/usr/bin/env bash
# Sparse residency on the GPU machine (issue "Larger than GPU memory"), from a CLI and core-test
# build carried over (SS_CLI, SS_TESTS; LD_LIBRARY_PATH for oneTBB and libpng as for run-core.sh).
#
#   bench/device/sparse-residency.sh OUTDIR [tests] [memcheck] [compare] [beyond]
#   tests:    the core tests BrickPool.* (CUDA sparse == in core for every builder and mode)
#             and the CUDA suites that touch the backend (CudaTrees, Cuda*, Slice, CropClip)
#   memcheck: compute-sanitizer memcheck on BrickPool.Cuda* and a small sparse CLI run
#   compare:  `spaceskip sparse` on $COMPARE_VOLUME (gen:nbody:2048, 8 GiB) with a budget of
#             $COMPARE_BUDGET (1G): in core vs sparse per builder, kernel fps, max diff of every
#             frame, the TF edit that shows new bricks timed to its first frame
#   beyond:   `spaceskip sparse --no-in-core` on $BEYOND_VOLUME (gen:kingsnake:4480, 83.7 GiB of
#             uint8 voxels: more than the device's memory), budget $BEYOND_BUDGET (default: the
#             device's free memory less the rest)
# Each phase writes OUTDIR/<phase>.log; OUTDIR/env.txt has the GPU, date and binaries.
set -uo pipefail
out=${1:?usage: sparse-residency.sh OUTDIR [tests] [memcheck] [compare] [beyond]}
shift
mkdir -p "$out"
cli=${SS_CLI:-build/Core/spaceskip}
tests=${SS_TESTS:-build/Testing/spaceskip_core_tests}
{
  echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  nvidia-smi --query-gpu=name,memory.total,memory.free,driver_version --format=csv,noheader 2>&1
  echo "cli: $cli ($(sha256sum "$cli" 2>/dev/null | cut -c1-12)); tests: $tests"
  echo "host memory: $(free -g | awk '/Mem:/ {print $2 " GiB"}'), cores: $(nproc)"
} > "$out/env.txt"
for phase in "$@"; do
  case $phase in
    tests)
      "$tests" --gtest_filter='BrickPool.*:CudaTrees*:Cuda*:Slice.Cuda*:CropClip.Cuda*:ComponentsCuda*:Pieces.Cuda*' \
        > "$out/tests.log" 2>&1; echo "exit $?" >> "$out/tests.log" ;;
    memcheck)
      { compute-sanitizer --tool memcheck --error-exitcode 9 "$tests" --gtest_filter='BrickPool.Cuda*'; echo "exit $?"
        compute-sanitizer --tool memcheck --error-exitcode 9 "$cli" sparse gen:nbody:256 --memory-budget 2M \
          --builders grid,kdtree-gpu-fast --frames 2 --size 256x256; echo "exit $?"; } > "$out/memcheck.log" 2>&1 ;;
    compare)
      "$cli" sparse "${COMPARE_VOLUME:-gen:nbody:2048}" --memory-budget "${COMPARE_BUDGET:-1G}" --backend cuda \
        --builders "${COMPARE_BUILDERS:-naive,grid,distance-grid,lbvh,kdtree-gpu-fast,hybrid,auto}" \
        --frames "${FRAMES:-8}" --size 1024x1024 --tf "${COMPARE_TF:-band}" --edit-tf ramp \
        > "$out/compare.log" 2>&1; echo "exit $?" >> "$out/compare.log" ;;
    beyond)
      budget=()
      [ -n "${BEYOND_BUDGET:-}" ] && budget=(--memory-budget "$BEYOND_BUDGET")
      [ ${#budget[@]} -eq 0 ] && budget=(--memory-budget 70G)
      /usr/bin/time -v "$cli" sparse "${BEYOND_VOLUME:-gen:kingsnake:4480}" --no-in-core "${budget[@]}" --backend cuda \
        --max-volume-bytes 100G --builders "${BEYOND_BUILDERS:-grid,kdtree-gpu-fast}" --frames "${FRAMES:-8}" \
        --size 1024x1024 --tf "${BEYOND_TF:-band}" --edit-tf ramp > "$out/beyond.log" 2>&1
      echo "exit $?" >> "$out/beyond.log"
      nvidia-smi --query-gpu=memory.used,memory.total --format=csv >> "$out/beyond.log" 2>&1 ;;
    *) echo "unknown phase $phase" >&2 ;;
  esac
done
