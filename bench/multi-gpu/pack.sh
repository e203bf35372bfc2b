#!/usr/bin/env bash
# Packs, on the development machine, what bench/multi-gpu/run.sh needs on a GPU machine:
# .vtkbundle-mpi/mpi.tar.xz with bin/spaceskip_mpi_pieces (built with CUDA), lib/ (oneTBB,
# Highway, libpng: the GPU machine has none of them) and ompi.tar.xz (Debian's Open MPI 4.1.4
# runtime, used only where the machine's mpirun cannot load the binary's libmpi.so.40).
#   bench/multi-gpu/pack.sh [BUILD_DIR]    (default ./build)
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$src/build}" && pwd)
exe=$build/bench/multi-gpu/spaceskip_mpi_pieces
grep -q "SPACESKIP_ENABLE_CUDA:BOOL=ON" "$build/CMakeCache.txt" || { echo "pack: $build has no CUDA" >&2; exit 1; }
[ -x "$exe" ] || { echo "pack: build spaceskip_mpi_pieces first" >&2; exit 1; }
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/bin" "$stage/lib"
cp "$exe" "$stage/bin/"
for l in libtbb.so.12 libtbbmalloc.so.2 libhwy.so.1 libpng16.so.16; do
  p=$(ldconfig -p | awk -v l="$l" '$1 == l && !done {print $NF; done = 1}')  # no early exit: SIGPIPE under pipefail
  [ -n "$p" ] && cp -L "$p" "$stage/lib/"
done
for p in libopenmpi3 openmpi-bin openmpi-common libpmix2 libhwloc15 libevent-core-2.1-7 \
         libevent-pthreads-2.1-7 libevent-2.1-7; do
  dpkg -L "$p" 2>/dev/null
done | while read -r f; do [ -f "$f" ] && echo "${f#/}"; done | grep -v -E "/doc/|/man/|lintian" > "$stage/ompi.txt"
tar -cJf "$stage/ompi.tar.xz" -C / -T "$stage/ompi.txt"
mkdir -p "$src/.vtkbundle-mpi"
tar -cJf "$src/.vtkbundle-mpi/mpi.tar.xz" -C "$stage" bin lib ompi.tar.xz
ls -la "$src/.vtkbundle-mpi/mpi.tar.xz"
