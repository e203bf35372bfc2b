#!/usr/bin/env bash
# Packs, on the development machine (Debian 12 + ParaView 5.11), ParaView's own engine for a GPU
# machine that has no ParaView, X server or GL loader: pvbatch and pvpython, the SpaceSkip plugin
# built with CUDA, the spaceskip CLI (to generate volumes there: GEN_CLI), the closure of shared libraries they load (ldd, minus glibc and the C++ runtime,
# whose GPU-machine copies are newer), Python 3.11's standard library and the Python packages the
# plugin's tests and benchmarks import (paraview, vtkmodules, numpy).
#
# The closure is ~650 MB (414 libraries), more than one device run carries (64 MiB with the
# working tree), so the compressed stream is cut into parts of PART_MB (default 56) MB, one folder
# each: .vtkbundle-pv1/, .vtkbundle-pv2/, ... Carry one folder a call and park its part on the held
# machine (files outside the work tree stay between calls of one hold):
#   call k:  carry .vtkbundle-pvk   command: mkdir -p /tmp/bun && cp .vtkbundle-pvk/* /tmp/bun/
# then bench/device/run-pv.sh OUTDIR with BUNDLE=/tmp/bun (it also needs the X part, x.tar.xz of
# bench/device/bundle-vtk.sh, in that folder).
#
# Open MPI's libraries go into their own folder (pv/lib-mpi): run-pv.sh uses the machine's
# Open MPI 4.x when it has one (same libmpi.so.40 ABI; its mpirun then finds its own components)
# and the carried ones otherwise.
#
#   bench/device/bundle-pv.sh [BUILD_DIR]     (default ./build, configured with CUDA on)
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$src/build}" && pwd)
part_mb=${PART_MB:-56}
plugin=$build/lib/paraview-5.11/plugins/SpaceSkip
grep -q "SPACESKIP_ENABLE_CUDA:BOOL=ON" "$build/CMakeCache.txt" ||
  { echo "bundle-pv: $build was configured without CUDA (SPACESKIP_ENABLE_CUDA)" >&2; exit 1; }
[ -f "$plugin/SpaceSkip.so" ] || { echo "bundle-pv: $plugin/SpaceSkip.so missing (build first)" >&2; exit 1; }
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
py=/usr/lib/python3.11
dist=/usr/lib/python3/dist-packages
pv=$stage/pv
mkdir -p "$pv/bin" "$pv/lib" "$pv/lib-mpi" "$pv/plugin" "$pv/python/lib" "$pv/python/dist-packages"

# Executables and the plugin (its libraries next to it, as ParaView's plugin loader expects).
cp -L /usr/bin/pvbatch3.11 "$pv/bin/pvbatch"
cp -L /usr/bin/pvpython3.11 "$pv/bin/pvpython"
cp -L "$plugin"/*.so "$pv/plugin/"
cp -L "$build/lib/libvtkSpaceSkip.so" "$pv/lib/"
# The CLI: run-pv.sh's bench-pvbatch generates its volumes with it (spaceskip generate, on the
# CPU). GEN_CLI, default a CPU-only build's (build-cpu: 4 MB against the CUDA build's 42 MB of xz).
cli=${GEN_CLI:-$src/build-cpu/Core/spaceskip}
[ -x "$cli" ] || cli=$build/Core/spaceskip
[ -x "$cli" ] && cp "$cli" "$pv/bin/spaceskip"

# Python: the standard library without its tests and GUI toolkits, and the packages used.
tar -C /usr/lib -cf - --exclude=__pycache__ --exclude=python3.11/test --exclude=python3.11/idlelib \
  --exclude=python3.11/tkinter --exclude=python3.11/turtledemo --exclude=python3.11/ensurepip \
  --exclude=python3.11/lib2to3 --exclude=python3.11/dist-packages python3.11 | tar -C "$pv/python/lib" -xf -
for p in paraview vtkmodules vtk.py numpy; do
  [ -e "$dist/$p" ] && tar -C "$dist" -cf - --exclude=__pycache__ --exclude=tests "$p" |
    tar -C "$pv/python/dist-packages" -xf -
done

# The closure of everything that loads a shared library. Libraries that only readers, writers and
# filters a volume rendering run never calls need (GDAL, FFmpeg, ICU, VTK-m's filters: ~300 MB
# with what they load) are replaced by stubs that abort if ever called (bench/device/closure.py).
cut='^(libgdal|libavcodec|libavformat|libavutil|libswscale|libswresample|libicuuc|libicudata|libicui18n|libvtkm_filter_[a-z_]+-pv5\.11)\.so'
mpi='^(libmpi\.so|libmpi_cxx|libopen-pal|libopen-rte|libhwloc|libevent|libpmix|libfabric|libpsm|libucp|libucs|libuct|libucm|libibverbs|librdmacm|libnl-)'
users=$(find "$pv/bin" "$pv/plugin" "$pv/lib" "$pv/python" -type f \( -name "*.so*" -o -path "*/bin/*" \))
mkdir -p "$stage/stubs"
# shellcheck disable=SC2086
python3 "$src/bench/device/closure.py" --cut "$cut" --stubs "$stage/stubs" $users > "$stage/closure.txt"
while read -r path; do
  dest=$pv/lib
  basename "$path" | grep -Eq "$mpi" && dest=$pv/lib-mpi
  cp -Ln "$path" "$dest/"
done < "$stage/closure.txt"
for c in "$stage/stubs"/*.c; do
  lib=$(basename "$c" .c)
  gcc -shared -fPIC -o "$pv/lib/$lib" -Wl,-soname,"$lib" "$c"
done
echo "closure: $(ls "$pv/lib" | wc -l) libraries ($(ls "$stage/stubs" | wc -l) stubs), $(ls "$pv/lib-mpi" | wc -l) of Open MPI"
strip --strip-unneeded "$pv/bin/"* "$pv/lib/"* "$pv/lib-mpi/"* "$pv/plugin/"* 2>/dev/null || true
(cd "$src" && git rev-parse HEAD; git status --short | head -20) > "$pv/COMMIT" 2>/dev/null || true
du -sh "$pv"

# Compress and cut into parts, one folder each.
rm -rf "$src"/.vtkbundle-pv[0-9]*
tar -C "$stage" -cf - pv | xz -9e -T2 > "$stage/pv.tar.xz"
(cd "$stage" && split -b "${part_mb}M" -d -a 1 pv.tar.xz pv.tar.xz.)
n=0
for part in "$stage"/pv.tar.xz.[0-9]; do
  n=$((n + 1))
  mkdir -p "$src/.vtkbundle-pv$n"
  mv "$part" "$src/.vtkbundle-pv$n/"
done
(cd "$stage" && sha256sum pv.tar.xz) > "$src/.vtkbundle-pv1/pv.tar.xz.sha256"
ls -la "$src"/.vtkbundle-pv*/
echo "bundle-pv: $n parts; carry each .vtkbundle-pvK in its own call (see the header)"
