#!/usr/bin/env bash
# On the development machine: packs the CUDA-built CLI and Core tests of BUILD (default ./build,
# sm_90) with the shared libraries the GPU machine lacks (oneTBB, Highway, libpng): the tests and
# the libraries in .vtkbundle-core/core.tar.xz, the CLI and the libraries in .vtkbundle-cli/cli.tar.xz
# (git-ignored; each binary is ~45 MB of CUDA kernels, so they travel in two calls of one warm
# hold: carry one, then the other). The device scripts unpack them to /tmp/c.
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$src/build}
stage=$(mktemp -d)
mkdir -p "$stage/bin" "$stage/lib" "$src/.vtkbundle-core" "$src/.vtkbundle-cli"
for exe in spaceskip Testing/spaceskip_core_tests; do
  cp "$build/$exe" "$stage/bin/" 2>/dev/null || cp "$build/Core/$exe" "$stage/bin/"
done
strip "$stage/bin/"*
for lib in libtbb.so.12 libhwy.so.1 libpng16.so.16; do
  cp -L "$(ldconfig -p | awk -v l="$lib" '$1 == l {print $NF; exit}')" "$stage/lib/"
done
tar -C "$stage" -cJf "$src/.vtkbundle-core/core.tar.xz" bin/spaceskip_core_tests lib &
tar -C "$stage" -cJf "$src/.vtkbundle-cli/cli.tar.xz" bin/spaceskip lib
wait
rm -rf "$stage"
ls -la "$src/.vtkbundle-core/core.tar.xz" "$src/.vtkbundle-cli/cli.tar.xz"
