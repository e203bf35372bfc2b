#!/usr/bin/env bash
# Packs what build.sh installed into .peers/visrtx/visrtx.tar.xz for the GPU machine:
# bin/anari_bench, lib/libanari.so*, lib/libanari_library_visrtx.so (and helide when built),
# libtbb and libpng,
# stripped, plus VERSIONS. CUDA runtime is static; libcuda, libnvidia-ml and libnvoptix come
# from the driver there.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
REPO=$(cd "$HERE/../../.." && pwd)
PREFIX=${PREFIX:-$REPO/.peers/visrtx/install}
OUT=${OUT:-$REPO/.peers/visrtx/visrtx.tar.xz}
SRC=${SRC:-/work/peers/src}
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
chmod 755 "$stage"
mkdir -p "$stage/bin" "$stage/lib"
cp "$PREFIX/bin/anari_bench" "$stage/bin/"
cp -P "$PREFIX"/lib/libanari.so* "$PREFIX/lib/libanari_library_visrtx.so" "$stage/lib/"
[ -f "$PREFIX/lib/libanari_library_helide.so" ] && cp "$PREFIX/lib/libanari_library_helide.so" "$stage/lib/"
# SpaceSkip's readers and PNG writer compiled into anari_bench need oneTBB and libpng there.
for lib in libtbb.so.12 libpng16.so.16; do
  cp -L "$(ldconfig -p | awk -v l="$lib" '$1 == l {print $NF; exit}')" "$stage/lib/"
done
find "$stage" -type f -name '*.so*' -exec strip --strip-unneeded {} +
strip "$stage/bin/anari_bench"
{
  for t in ANARI-SDK VisRTX optix-dev embree; do
    [ -f "$SRC/$t/.commit" ] && echo "$t $(cat "$SRC/$t/.commit")"
  done
  nvcc --version | tail -1
  echo "built $(date -u +%Y-%m-%dT%H:%M:%SZ) for CUDA arch ${CUDA_ARCH:-90}"
} > "$stage/VERSIONS"
mkdir -p "$(dirname "$OUT")"
(cd "$stage" && XZ_OPT="-9 -T2" nice -n 15 tar -cJf "$OUT" .)
tar -tvJf "$OUT"
du -h "$OUT"
