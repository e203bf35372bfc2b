#!/usr/bin/env bash
# Configures and builds SpaceSkip into ${BUILD_DIR:-build}. CUDA and ParaView are detected
# (SPACESKIP_ENABLE_CUDA / SPACESKIP_ENABLE_PARAVIEW default ON when found); extra CMake
# arguments are passed through.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$root/build}
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build "$build" -j "$(nproc)"
