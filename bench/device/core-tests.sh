#!/usr/bin/env bash
# On the GPU machine: the carried Core tests (.vtkbundle-core/core.tar.xz, made by
# bench/device/pack-core.sh): FILTER's tests, compute-sanitizer memcheck on MEMCHECK's, then the
# whole suite but the wall-clock ratio test (it belongs to the benchmarks).
#   bash bench/device/core-tests.sh OUT FILTER MEMCHECK
set -uo pipefail
out=${1:?usage: core-tests.sh OUT FILTER MEMCHECK}
filter=${2:?gtest filter}
memfilter=${3:?gtest filter for memcheck}
src=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out" /tmp/c
tar -C /tmp/c -xJf "$src/.vtkbundle-core/core.tar.xz"
export LD_LIBRARY_PATH=/tmp/c/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
# The Core tests read files of the source tree by the path they were built with.
[ -e /work/main ] || { mkdir -p /work && ln -s "$src" /work/main; }
{
  date -u +%Y-%m-%dT%H:%M:%SZ
  nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
  echo "tree: $(cd "$src" && git rev-parse HEAD 2>/dev/null || echo copied)"
} > "$out/env.txt" 2>&1
B=/tmp/c/bin
$B/spaceskip_core_tests --gtest_filter="$filter" > "$out/tests.log" 2>&1
echo "tests ($filter) rc=$?" >> "$out/env.txt"
tail -3 "$out/tests.log" >> "$out/env.txt"
timeout 240 compute-sanitizer --tool memcheck --error-exitcode 9 $B/spaceskip_core_tests \
  --gtest_filter="$memfilter" > "$out/memcheck.log" 2>&1
echo "memcheck ($memfilter) rc=$?" >> "$out/env.txt"
tail -2 "$out/memcheck.log" >> "$out/env.txt"
timeout 300 $B/spaceskip_core_tests --gtest_filter=-AutoBuilder.NeverSlowerThanNaiveOnEveryShapeAt256 > "$out/core-tests.log" 2>&1
echo "core tests rc=$?" >> "$out/env.txt"
tail -3 "$out/core-tests.log" >> "$out/env.txt"
