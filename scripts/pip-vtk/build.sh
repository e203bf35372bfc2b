#!/usr/bin/env bash
# Build the VTK module (Core inside) and its C++ tests against VTK from pip, then run the VTK
# mapper tests under Xvfb: the check that one source tree builds against ParaView 5.11's VTK 9.2
# (build/) and against VTK >= 9.4 (glad in place of GLEW; VTKModule/vtkSpaceSkipOpenGL.h).
#
# What it uses, all from PyPI (pip) and Debian:
#   * `vtk==$VER` (the Linux manylinux wheel): the libvtk*.so in vtkmodules/, installed into a
#     venv with --no-deps (its Python dependencies are not needed for C++);
#   * `vtk-sdk==$VER`: headers and CMake package. PyPI has it only as macOS wheels, so the macOS
#     one is downloaded and re-pointed at the Linux wheel's libraries (assemble_sdk.py says how);
#     Kitware's Linux SDK wheels are the real-world route (docs/pip.md).
# Everything is compiled with -D_GLIBCXX_USE_CXX11_ABI=0, the ABI of the manylinux2014 wheel
# (else the module fails to load: undefined symbol ...GetObjectDescriptionB5cxx11).
# Python wrapping needs VTK's wrapping executables, which neither wheel has for Linux: given
# SPACESKIP_PIP_VTK_SOURCE (a git repository of VTK with the tag v$VER, kept outside this
# repository), the script compiles vtkWrapHierarchy, vtkWrapPython and vtkWrapPythonInit from
# its Wrapping/Tools against the wheel's libvtkWrappingTools.so, wraps the mapper (package
# spaceskip), installs numpy into the venv and runs the Python test too; without it, it says so
# and builds C++ only. CUDA is off unless SPACESKIP_PIP_VTK_CUDA_ARCH is set (e.g. 90: the CUDA
# backend for sm_90, its host code with the same ABI; bench/device/bundle-pipvtk.sh carries it to a
# GPU machine). Without it CUDA is not built: a CPU build.
# The SDK part (downloads, wrapping tools, assemble_sdk.py) is sdk.sh, shared with wheel.sh (the
# `spaceskip` wheel + PyVista test).
#
# usage: scripts/pip-vtk/build.sh [ctest arguments; default -R SpaceSkipping: the VTK mapper tests]
# environment (all optional):
#   SPACESKIP_PIP_VTK_VERSION  VTK version from pip (default 9.5.0, PyPI's only vtk-sdk version)
#   SPACESKIP_PIP_VTK_CACHE    downloads, venv and assembled SDK (default ~/.cache/spaceskip-pip-vtk)
#   SPACESKIP_PIP_VTK_BUILD    build folder (default build-pipvtk in the repository, git-ignored)
#   SPACESKIP_PIP_VTK_JOBS     build jobs (default: nproc)
#   SPACESKIP_PIP_VTK_SOURCE   VTK git repository with tag v$VER: Python wrapping (see above)
#   SPACESKIP_PIP_VTK_CUDA_ARCH  CUDA architecture: build the CUDA backend for it (default: none, CUDA off)
#   SPACESKIP_PIP_VTK_NO_TESTS   set: build only, run no test (e.g. a CUDA build for the GPU machine)
#   SPACESKIP_XVFB_DISPLAY     Xvfb display number when DISPLAY is unset (default 92)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
ver=${SPACESKIP_PIP_VTK_VERSION:-9.5.0}
cache=${SPACESKIP_PIP_VTK_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/spaceskip-pip-vtk}/$ver
build=${SPACESKIP_PIP_VTK_BUILD:-$root/build-pipvtk}
jobs=${SPACESKIP_PIP_VTK_JOBS:-$(nproc)}
ctest_args=("$@")
[ ${#ctest_args[@]} -gt 0 ] || ctest_args=(-R SpaceSkipping)
py=${PYTHON:-python3}
t0=$SECONDS
step() { echo "== pip-vtk [$((SECONDS - t0)) s]: $*"; }
mkdir -p "$cache"

source "$root/scripts/pip-vtk/sdk.sh"

cuda=(-DSPACESKIP_ENABLE_CUDA=OFF)
if [ -n "${SPACESKIP_PIP_VTK_CUDA_ARCH:-}" ]; then
  # nvcc's host compiler needs the same C++ ABI as the C++ files: Core's API passes std::string.
  cuda=(-DSPACESKIP_ENABLE_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES="$SPACESKIP_PIP_VTK_CUDA_ARCH"
    -DCMAKE_CUDA_FLAGS="-D_GLIBCXX_USE_CXX11_ABI=0")
fi
step "configure $build (ParaView off, ${cuda[0]#-D}, Python wrapping $wrap, -D_GLIBCXX_USE_CXX11_ABI=0)"
# CMAKE_DISABLE_FIND_PACKAGE_ParaView: the system ParaView's VTK must not be loaded beside this one.
mkdir -p "$build"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_DISABLE_FIND_PACKAGE_ParaView=TRUE -DSPACESKIP_ENABLE_PARAVIEW=OFF \
  -DSPACESKIP_ENABLE_VTK=ON "${cuda[@]}" -DSPACESKIP_WRAP_PYTHON=$wrap \
  -DPython3_EXECUTABLE="$venv/bin/python" \
  -DVTK_DIR="$vtk_dir" -DCMAKE_CXX_FLAGS="-D_GLIBCXX_USE_CXX11_ABI=0" >"$build/pip-vtk-configure.log" 2>&1 ||
  { tail -30 "$build/pip-vtk-configure.log"; exit 1; }
grep -E "SpaceSkip: " "$build/pip-vtk-configure.log"

step "build the module, its C++ tests, the window benchmark, the test baselines and, with wrapping, its Python module (-j$jobs)"
targets=(vtkSpaceSkipCxxTests spaceskip_window_bench SpaceSkip-data)
[ "$wrap" = OFF ] || targets+=(vtkSpaceSkipPython)
nice -n 10 cmake --build "$build" -j "$jobs" --target "${targets[@]}"

if [ -n "${SPACESKIP_PIP_VTK_NO_TESTS:-}" ]; then
  step "built; no tests run (SPACESKIP_PIP_VTK_NO_TESTS)"
  exit 0
fi
step "VTK C++ tests (ctest ${ctest_args[*]}) under X"
source "$root/scripts/xvfb.sh" 92
echo "DISPLAY=$DISPLAY"
# The window the tests draw in, as the pip vtk opens it here.
"$venv/bin/python" - <<'PY' || echo "pip-vtk: could not open a VTK render window to report its GL" >&2
from vtkmodules.vtkRenderingCore import vtkRenderWindow
import vtkmodules.vtkRenderingOpenGL2
w = vtkRenderWindow()
w.Render()
caps = [l.strip() for l in w.ReportCapabilities().splitlines()
        if l.startswith("OpenGL") and "extensions" not in l]
print(w.GetClassName() + ": " + "; ".join(caps))
PY
set +e
(cd "$build" && ctest "${ctest_args[@]}" --output-on-failure -j1 --timeout 300) 2>&1 | tee "$build/pip-vtk-ctest.log"
rc=${PIPESTATUS[0]}
set -e
step "done: ctest exit $rc; VTK $ver from pip; log $build/pip-vtk-ctest.log"
exit "$rc"
