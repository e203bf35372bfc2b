#!/usr/bin/env bash
# Builds only the CLI and the Core tests with CUDA (sm_90) on the GPU machine into ${BUILD_DIR:-build-gpu},
# for a before/after measurement in the same device call. usage: build-core.sh LOG
set -uo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
build=${BUILD_DIR:-$src/build-gpu}
for d in "$src/.deps/tbb" "$src/../.deps/tbb"; do
  [ -d "$d" ] && export TBB_DIR=$(cd "$d" && pwd)/usr/lib/x86_64-linux-gnu/cmake/TBB && break
done
cmake -S "$src" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSPACESKIP_ENABLE_CUDA=ON \
  -DSPACESKIP_ENABLE_PARAVIEW=OFF -DCMAKE_CUDA_ARCHITECTURES=90 > "${1:-/dev/stdout}" 2>&1 &&
  ninja -C "$build" spaceskip spaceskip_core_tests >> "${1:-/dev/stdout}" 2>&1
