#!/usr/bin/env bash
# Builds ANARI-SDK (library + helium, no examples/viewer/tests), VisRTX's
# CUDA/OptiX device (libanari_library_visrtx: no GL device, no MDL, no NVTX)
# and anari_bench, installing all of it into $PREFIX. Offline: sources come
# from local trees, the OptiX headers from a local optix-dev tree.
#
#   ANARI_SRC   ANARI-SDK v0.14.1 tree   (default /work/peers/src/ANARI-SDK)
#   VISRTX_SRC  VisRTX v0.12.0 tree      (default /work/peers/src/VisRTX)
#   OPTIX_SRC   optix-dev v9.0.0 tree    (default /work/peers/src/optix-dev)
#   PREFIX      install prefix           (default <repo>/.peers/visrtx/install)
#   BUILD       build folder             (default <repo>/.peers/visrtx/build)
#   CUDA_ARCH   CMAKE_CUDA_ARCHITECTURES (default 90)
#   JOBS        parallel jobs            (default 2); runs under nice -n 15
#   HELIDE=1    also build ANARI's CPU 'helide' device (needs EMBREE_SRC, an
#               embree v4.3.3 tree) for a smoke test without a GPU
#   STAGES      any of "anari visrtx bench" (default all three)
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
REPO=$(cd "$HERE/../../.." && pwd)
SRC=${SRC:-/work/peers/src}
ANARI_SRC=${ANARI_SRC:-$SRC/ANARI-SDK}
VISRTX_SRC=${VISRTX_SRC:-$SRC/VisRTX}
OPTIX_SRC=${OPTIX_SRC:-$SRC/optix-dev}
EMBREE_SRC=${EMBREE_SRC:-$SRC/embree}
PREFIX=${PREFIX:-$REPO/.peers/visrtx/install}
BUILD=${BUILD:-$REPO/.peers/visrtx/build}
CUDA_ARCH=${CUDA_ARCH:-90}
JOBS=${JOBS:-2}
HELIDE=${HELIDE:-0}
STAGES=${STAGES:-anari visrtx bench}
NICE="nice -n 15"

mkdir -p "$BUILD" "$PREFIX"

# Patches: <tree>-NNNN-*.patch, applied once (skipped when already applied).
apply_patches() { # tree-prefix source-dir
  local p
  for p in "$HERE"/patches/"$1"-*.patch; do
    [ -e "$p" ] || continue
    if patch -d "$2" -p1 -R --dry-run -s -f < "$p" > /dev/null 2>&1; then
      echo "patch already applied: $(basename "$p")"
    else
      echo "applying $(basename "$p")"; patch -d "$2" -p1 -N -s < "$p"
    fi
  done
}

# NVML: VisRTX links CUDA::nvml and includes <nvml.h>; this toolkit has
# neither. nvml.h comes from PyPI's nvidia-nvml-dev (13.0.x); the link-time
# library is a stub with the three functions VisRTX calls, soname
# libnvidia-ml.so.1 (the driver's real one is used at run time).
NVML_DIR=${NVML_DIR:-$BUILD/nvml}
nvml() {
  [ -f "$NVML_DIR/lib/libnvidia-ml.so" ] && return
  mkdir -p "$NVML_DIR/include" "$NVML_DIR/lib" "$NVML_DIR/dl"
  if [ ! -f "$NVML_DIR/include/nvml.h" ]; then
    pip download -q --no-deps -d "$NVML_DIR/dl" "nvidia-nvml-dev==13.0.*"
    python3 -m zipfile -e "$NVML_DIR"/dl/nvidia_nvml_dev-*.whl "$NVML_DIR/dl/x"
    cp "$NVML_DIR"/dl/x/nvidia/cu13/include/nvml.h "$NVML_DIR/include/"
  fi
  cat > "$NVML_DIR/stub.c" <<'EOF'
int nvmlInit_v2(void) { return 999; }
int nvmlShutdown(void) { return 999; }
int nvmlSystemGetDriverVersion(char *v, unsigned n) { (void)v; (void)n; return 999; }
EOF
  cc -shared -fPIC -Wl,-soname,libnvidia-ml.so.1 -o "$NVML_DIR/lib/libnvidia-ml.so" "$NVML_DIR/stub.c"
}

build_anari() {
  local helide=OFF
  if [ "$HELIDE" = 1 ]; then
    helide=ON; apply_patches anari "$ANARI_SRC"
  fi
  $NICE cmake -S "$ANARI_SRC" -B "$BUILD/anari" -G Ninja \
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$PREFIX" \
    -DBUILD_TESTING=OFF -DBUILD_EXAMPLES=OFF -DBUILD_VIEWER=OFF \
    -DBUILD_CTS=OFF -DBUILD_CAT=OFF -DBUILD_HDANARI=OFF \
    -DINSTALL_VIEWER_LIBRARY=OFF -DINSTALL_PYTHON_BINDINGS=OFF \
    -DBUILD_DEBUG_DEVICE=OFF -DBUILD_SINK_DEVICE=ON -DBUILD_REMOTE_DEVICE=OFF \
    -DBUILD_HELIDE_DEVICE=$helide -DHELIDE_EMBREE_SRC="$EMBREE_SRC"
  $NICE cmake --build "$BUILD/anari" -j "$JOBS"
  cmake --install "$BUILD/anari"
}

build_visrtx() {
  apply_patches visrtx "$VISRTX_SRC"
  nvml
  $NICE cmake -S "$VISRTX_SRC" -B "$BUILD/visrtx" -G Ninja \
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$PREFIX" \
    -DCMAKE_PREFIX_PATH="$PREFIX" -DCMAKE_CUDA_ARCHITECTURES="$CUDA_ARCH" \
    -DVISRTX_BUILD_RTX_DEVICE=ON -DVISRTX_BUILD_GL_DEVICE=OFF \
    -DVISRTX_ENABLE_MDL_SUPPORT=OFF -DVISRTX_ENABLE_NVTX=OFF \
    -DVISRTX_BUILD_TSD=OFF -DVISRTX_BUILD_TESTS=OFF \
    -DVISRTX_PRECOMPILE_SHADERS=OFF \
    -DOPTIX_FETCH_VERSION=9.0 -DVISRTX_OPTIX_HEADERS_DIR="$OPTIX_SRC" \
    -DCUDA_nvml_LIBRARY="$NVML_DIR/lib/libnvidia-ml.so" \
    -DCMAKE_CXX_FLAGS="-isystem $NVML_DIR/include" \
    -DCMAKE_SHARED_LINKER_FLAGS="-Wl,--as-needed" \
    -DCMAKE_EXE_LINKER_FLAGS="-Wl,--as-needed -Wl,--allow-shlib-undefined"
  $NICE cmake --build "$BUILD/visrtx" -j "$JOBS"
  cmake --install "$BUILD/visrtx"
}

build_bench() {
  $NICE cmake -S "$HERE" -B "$BUILD/bench" -G Ninja \
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$PREFIX" \
    -DCMAKE_PREFIX_PATH="$PREFIX"
  $NICE cmake --build "$BUILD/bench" -j "$JOBS"
  cmake --install "$BUILD/bench"
}

for s in $STAGES; do
  echo "=== $s"; "build_$s"
done
echo "installed into $PREFIX"
