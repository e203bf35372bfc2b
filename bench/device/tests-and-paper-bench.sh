#!/usr/bin/env bash
# One device call with carried binaries (see docs/gpu.md): the Core tests (CUDA twins included),
# compute-sanitizer memcheck on a filter, then the paper's protocol (paper-bench.sh) on data sets.
#
#   bench/device/tests-and-paper-bench.sh OUTDIR
#   expects: build-bench/both.tar.xz (stripped spaceskip + spaceskip_core_tests, one solid xz:
#            they share most of their code, so both fit the carry limit), build-bench/lib
#            (libpng16), .deps/tbb
#   env:     MEMCHECK_FILTER (gtest filter, default the CUDA distance field and Auto),
#            RUNS ("run2:DATASETS run1:DATASETS", space separated), BUILDERS, TIME_LIMIT, FRAMES
set -uo pipefail
out=${1:?usage: tests-and-paper-bench.sh OUTDIR}
mkdir -p "$out"
src=$(cd "$(dirname "$0")/../.." && pwd)
cd "$src"
mkdir -p build-x build-y/Core
tar xJf build-bench/both.tar.xz -C build-x || exit 1
cp build-x/spaceskip build-y/Core/
export LD_LIBRARY_PATH=$src/build-bench/lib:$src/.deps/tbb/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
{
  date -u +%Y-%m-%dT%H:%M:%SZ
  nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv
  git rev-parse HEAD 2>/dev/null || echo "tree of the carried working copy"
} > "$out/env.txt" 2>&1
timeout 240 ./build-x/spaceskip_core_tests --gtest_brief=1 > "$out/core.log" 2>&1
echo "core tests rc=$?" | tee -a "$out/env.txt"
tail -5 "$out/core.log"
cs=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
timeout 180 "$cs" --tool memcheck --error-exitcode 3 ./build-x/spaceskip_core_tests \
  --gtest_filter="${MEMCHECK_FILTER:-DistanceField.*Cuda*:AutoBuilder.*}" > "$out/memcheck.log" 2>&1
echo "memcheck rc=$?" | tee -a "$out/env.txt"
tail -3 "$out/memcheck.log"
for run in ${RUNS:-}; do
  name=${run%%:*}
  BUILD_DIR=$src/build-y DATASETS=${run#*:} BUILDERS=${BUILDERS:-naive,grid,distance_grid,kdtree_gpu_fast,kdtree_empty,auto} \
    TIME_LIMIT=${TIME_LIMIT:-200} FRAMES=${FRAMES:-8} bash bench/device/paper-bench.sh "$out/$name" > "$out/$name.out" 2>&1
  echo "$name rc=$?" | tee -a "$out/env.txt"
  grep -h "^Auto:" "$out/$name/bench.log" | head -20
done
