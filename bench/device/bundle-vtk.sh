#!/usr/bin/env bash
# Packs, on the development machine (Debian 12 + ParaView 5.11), what the VTK mapper tests and the
# window benchmark need on a GPU machine that has no VTK, X server or GL loader (docs/gpu.md):
#   .vtkbundle/vtk.tar.xz  bin/: vtkSpaceSkipCxxTests, spaceskip_window_bench, spaceskip (CLI),
#                          spaceskip_core_tests (Core's GoogleTest binary, when built);
#                          lib/: libvtkSpaceSkip.so (built with CUDA), libEGL (glvnd) + the closure of shared
#                          libraries they load (ldd), minus glibc and libstdc++/libgcc_s (the
#                          GPU machine's own are newer);
#   .vtkbundle/x.tar.xz    Xvfb + xkbcomp + xkb data, Mesa's swrast_dri.so (Xvfb's GLX needs a
#                          DRI driver to offer GLX visuals, even when the clients use NVIDIA's
#                          GL), libGLX_mesa (the fallback client), libglvnd, and their closure.
# Trimmed to fit one device run (64 MiB with the working tree): libz3 (LLVM's SMT solver, used by
# clang's analyzer only) and libicuuc/libicudata (libxml2's encoding conversion) are replaced by
# stubs that define the symbols their users link against and abort if ever called; Mesa never
# calls them (checked by running Xvfb and a Mesa client on the stubs, see run-vtk.sh).
#
#   bench/device/bundle-vtk.sh [BUILD_DIR]     (default ./build; configure it with CUDA on; BUNDLE_OUT:
#   the folder instead of .vtkbundle, e.g. .vtkbundle-pipvtk for build-pipvtk-cuda, VTK 9.5 from pip)
# Then on the GPU machine: bench/device/run-vtk.sh OUTDIR (the device tool: carry .vtkbundle).
# x.tar.xz is kept when it exists (it takes ~2 minutes to compress): delete it to repack.
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$src/build}" && pwd)
out=${BUNDLE_OUT:-$src/.vtkbundle}  # BUNDLE_OUT: e.g. .vtkbundle-pipvtk for a second build
mkdir -p "$out"
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
multiarch=/usr/lib/x86_64-linux-gnu

if ! grep -q "SPACESKIP_ENABLE_CUDA:BOOL=ON" "$build/CMakeCache.txt"; then
  echo "bundle-vtk: $build was configured without CUDA (SPACESKIP_ENABLE_CUDA)" >&2
  exit 1
fi
grep -E "CMAKE_CUDA_ARCHITECTURES" "$build/CMakeCache.txt" || echo "CMAKE_CUDA_ARCHITECTURES: project default (90)"

# Libraries left to the GPU machine: glibc's, the C++ runtime, and those replaced by stubs.
skip='^(linux-vdso|ld-linux|libc\.so|libm\.so|libpthread|libdl\.so|librt\.so|libresolv|libstdc\+\+|libgcc_s)'
stubbed='^(libz3\.so|libicuuc\.so|libicudata\.so|libicui18n\.so)'
closure() {  # FILE... -> resolved paths of every library they load, minus the above
  for f in "$@"; do ldd "$f"; done | awk '$3 ~ /^\// {print $1" "$3}' | sort -u |
    while read -r name path; do
      echo "$name" | grep -Eq "$skip|$stubbed" || echo "$path"
    done | sort -u
}
copy_libs() {  # DESTDIR FILE...
  local dest=$1
  shift
  mkdir -p "$dest"
  for p in $(closure "$@"); do cp -L "$p" "$dest/"; done
}

# --- VTK part ---------------------------------------------------------------------------------
v=$stage/vtk
mkdir -p "$v/bin" "$v/lib"
# The CLI (its CUDA kernels are ~5 MB of xz) only with BUNDLE_NO_CLI=0: run-vtk.sh's phases that
# time the CLI beside the window (bench-*, cli-ab) need it, the tests do not.
exes="bin/vtkSpaceSkipCxxTests bin/spaceskip_window_bench"
[ "${BUNDLE_NO_CLI:-1}" = 1 ] || exes="$exes Core/spaceskip"
for exe in $exes; do
  [ -x "$build/$exe" ] || { echo "bundle-vtk: $build/$exe missing (build first)" >&2; exit 1; }
  cp "$build/$exe" "$v/bin/"
done
# Core's GoogleTest binary (CUDA tests included): run and sanitized on the device without a build.
# Only with BUNDLE_NO_CORE_TESTS=0 (else carry it separately, e.g. xz'd under build-bench/).
[ "${BUNDLE_NO_CORE_TESTS:-1}" = 1 ] || { [ -x "$build/Testing/spaceskip_core_tests" ] && cp "$build/Testing/spaceskip_core_tests" "$v/bin/"; }
cp -L "$build/lib/libvtkSpaceSkip.so" "$v/lib/"
copy_libs "$v/lib" "$v/bin/"* "$build/lib/libvtkSpaceSkip.so"
# glvnd's libEGL, dlopen()ed by the window benchmark's --egl mode (NVIDIA's headless EGL).
cp -L "$multiarch/libEGL.so.1" "$v/lib/"
strip --strip-unneeded "$v/bin/"* "$v/lib/libvtkSpaceSkip.so"*
(cd "$src" && git rev-parse HEAD 2>/dev/null; git -C "$src" status --short | head -20) > "$v/COMMIT" || true
tar -C "$stage" -cf - vtk | xz -9 -T2 > "$out/vtk.tar.xz.tmp"
mv "$out/vtk.tar.xz.tmp" "$out/vtk.tar.xz"

# --- X server + GL part -----------------------------------------------------------------------
if [ ! -f "$out/x.tar.xz" ]; then
  x=$stage/x
  mkdir -p "$x/bin" "$x/lib/dri" "$x/share"
  cp /usr/bin/Xvfb /usr/bin/xkbcomp "$x/bin/"
  cp -r /usr/share/X11/xkb "$x/share/xkb"
  cp "$multiarch/dri/swrast_dri.so" "$x/lib/dri/"
  cp -L "$multiarch/libGLX_mesa.so.0" "$multiarch/libGL.so.1" "$multiarch/libGLX.so.0" \
    "$multiarch/libGLdispatch.so.0" "$multiarch/libOpenGL.so.0" "$x/lib/"
  copy_libs "$x/lib" /usr/bin/Xvfb /usr/bin/xkbcomp "$multiarch/dri/swrast_dri.so" \
    "$multiarch/libGLX_mesa.so.0"
  # Stubs: every symbol the real library's users import, each an abort().
  for pair in "libz3.so.4:$multiarch/libLLVM-15.so.1" "libicuuc.so.72:$multiarch/libxml2.so.2"; do
    lib=${pair%%:*}
    user=${pair#*:}
    real=$(ldd "$user" | awk -v l="$lib" '$1 == l {print $3}')
    {
      echo "// Stub of $lib for $(basename "$user"): aborts if any symbol is ever called."
      echo "#include <stdlib.h>"
      nm -D --undefined-only "$user" | awk '{print $2}' | sed 's/@.*//' | sort -u |
        grep -Fxf <(nm -D --defined-only "$real" | awk '{print $3}' | sed 's/@.*//') |
        sed 's/.*/void &(void) { abort(); }/'
    } > "$stage/stub.c"
    gcc -shared -fPIC -o "$x/lib/$lib" -Wl,-soname,"$lib" "$stage/stub.c"
  done
  strip --strip-unneeded "$x/lib/"*.so* 2>/dev/null || true
  tar -C "$stage" -cf - x | xz -9 -T2 > "$out/x.tar.xz.tmp"
  mv "$out/x.tar.xz.tmp" "$out/x.tar.xz"
fi
ls -la "$out"
du -cb "$out"/*.tar.xz | tail -1
