# Sourced by build.sh and wheel.sh: a Linux VTK SDK for `vtk==$ver` from pip, assembled from what
# PyPI serves (see build.sh's header). Needs: root, ver, cache, py and a `step` function. Sets:
#   venv        a venv holding `vtk==$ver` (--no-deps)
#   vtkmodules  its vtkmodules/ folder (the Linux libvtk*.so)
#   vtk_dir     VTK_DIR of the assembled SDK
#   wrap        ON when VTK's Python wrapping executables were built (SPACESKIP_PIP_VTK_SOURCE), else OFF
mkdir -p "$cache"
step "VTK $ver from PyPI (cache $cache)"
if ! ls "$cache"/wheels/vtk-"$ver"-*manylinux*.whl >/dev/null 2>&1; then
  if ! "$py" -m pip download --no-deps --only-binary=:all: -d "$cache/wheels" "vtk==$ver" >"$cache/pip-vtk.log" 2>&1; then
    tail -5 "$cache/pip-vtk.log"
    echo "pip-vtk: cannot download vtk==$ver from PyPI (see $cache/pip-vtk.log); nothing built" >&2
    exit 1
  fi
fi
venv=$cache/venv
if [ ! -f "$venv/.vtk-installed" ]; then
  rm -rf "$venv"
  "$py" -m venv "$venv"
  "$venv/bin/python" -m pip install -q --no-deps "$cache"/wheels/vtk-"$ver"-*manylinux*.whl
  touch "$venv/.vtk-installed"
fi
vtkmodules=$("$venv/bin/python" -c 'import os, sysconfig; print(os.path.join(sysconfig.get_paths()["platlib"], "vtkmodules"))')
echo "Linux libraries: $vtkmodules ($(ls "$vtkmodules"/libvtk*.so | wc -l) libvtk*.so)"

step "vtk-sdk $ver (PyPI: macOS wheels only) -> a Linux SDK"
if ! ls "$cache"/sdk-wheel/vtk_sdk-"$ver"-*.whl >/dev/null 2>&1; then
  if ! "$py" -m pip download --no-deps --only-binary=:all: --platform macosx_10_9_x86_64 \
      --python-version 3.10 -d "$cache/sdk-wheel" "vtk-sdk==$ver" >"$cache/pip-sdk.log" 2>&1; then
    tail -5 "$cache/pip-sdk.log"
    echo "pip-vtk: PyPI has no vtk-sdk==$ver macOS x86_64 wheel to take headers from; nothing built" >&2
    exit 1
  fi
fi
if [ ! -f "$cache/sdk-unzipped/.done" ]; then
  rm -rf "$cache/sdk-unzipped"
  "$py" -m zipfile -e "$cache"/sdk-wheel/vtk_sdk-"$ver"-*.whl "$cache/sdk-unzipped"
  touch "$cache/sdk-unzipped/.done"
fi
tools=()
wrap=OFF
if [ -n "${SPACESKIP_PIP_VTK_SOURCE:-}" ]; then
  step "VTK's Python wrapping tools from $SPACESKIP_PIP_VTK_SOURCE, tag v$ver"
  if ! git -C "$SPACESKIP_PIP_VTK_SOURCE" rev-parse -q --verify "v$ver^{commit}" >/dev/null; then
    echo "pip-vtk: $SPACESKIP_PIP_VTK_SOURCE is not a VTK git repository with the tag v$ver" >&2
    exit 1
  fi
  wt=$cache/wrap-tools
  if [ ! -f "$wt/.done" ]; then
    rm -rf "$wt" && mkdir -p "$wt/src"
    git -C "$SPACESKIP_PIP_VTK_SOURCE" archive --prefix=Wrapping/Tools/ "v$ver:Wrapping/Tools" | tar -x -C "$wt/src"
    ws=$wt/src/Wrapping/Tools
    # The SDK's headers (vtkParse.h, vtkWrappingToolsModule.h, ...) and the wheel's library.
    inc=(-I"$ws" -I"$(ls -d "$cache"/sdk-unzipped/vtk_sdk/content/vtk-*.data/headers/vtk-*)")
    lnk=(-L"$vtkmodules" -lvtkWrappingTools -Wl,-rpath,"$vtkmodules")
    cc -O2 "${inc[@]}" -o "$wt/vtkWrapHierarchy" "$ws/vtkWrapHierarchy.c" "${lnk[@]}"
    cc -O2 "${inc[@]}" -o "$wt/vtkWrapPythonInit" "$ws/vtkWrapPythonInit.c" "${lnk[@]}"
    # vtkWrapPython's sources as Wrapping/Tools/CMakeLists.txt lists them.
    py_src=()
    for f in "" Class Constant Enum Method MethodDef Namespace NumberProtocol Overload Property \
        Template Type; do
      py_src+=("$ws/vtkWrapPython$f.c")
    done
    cc -O2 "${inc[@]}" -o "$wt/vtkWrapPython" "${py_src[@]}" "${lnk[@]}"
    touch "$wt/.done"
  fi
  "$wt/vtkWrapPython" --version
  tools=("$wt")
  wrap=ON
  # The Python test reads images through numpy.
  "$venv/bin/python" -c 'import numpy' 2>/dev/null || "$venv/bin/python" -m pip install -q numpy
fi
vtk_dir=$("$py" "$root/scripts/pip-vtk/assemble_sdk.py" "$cache/sdk-unzipped" "$vtkmodules" "$cache/sdk" "${tools[@]}")
echo "VTK_DIR=$vtk_dir"
if [ "$wrap" = OFF ]; then
  echo "NOTE: Python wrapping is NOT built here: it needs VTK's wrapping executables (vtkWrapHierarchy,"
  echo "      vtkWrapPython, vtkWrapPythonInit) for Linux, which neither PyPI wheel ships (the vtk wheel"
  echo "      has libvtkWrappingTools.so only, vtk-sdk's are macOS binaries). Set"
  echo "      SPACESKIP_PIP_VTK_SOURCE to a VTK git repository with tag v$ver to build them, or use"
  echo "      Kitware's Linux vtk-sdk (docs/pip.md)."
fi

