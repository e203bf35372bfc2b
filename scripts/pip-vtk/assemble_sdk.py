#!/usr/bin/env python3
"""Assemble a Linux VTK SDK from PyPI's macOS `vtk-sdk` wheel and the Linux `vtk` wheel.

PyPI serves `vtk-sdk` (headers + CMake package) only for macOS; the Linux SDK wheels live on
Kitware's own index (docs/pip.md). The headers are the same sources for both platforms except
the generated configuration, and the CMake package names the same modules, so this copies the
macOS SDK's headers and CMake package and points them at Linux:

  * every imported library (VTK-targets-release.cmake, viskores/ViskoresTargets-release.cmake)
    at the Linux wheel's vtkmodules/lib*.so (the file must exist there, else this fails);
  * `-framework Cocoa` dropped from the link interfaces;
  * vtk-config.cmake: VTK_USE_X and VTK_OPENGL_HAS_EGL ON (the Linux wheel's
    libvtkRenderingOpenGL2 has the X, EGL and OSMesa windows), Python wrapping OFF (ON with
    WRAP_TOOLS_DIR, below);
  * vtkRenderingOpenGLConfigure.h: VTK_USE_X in place of VTK_USE_COCOA;
  * the wrapping executables (macOS binaries in the SDK; the Linux wheel ships only
    libvtkWrappingTools.so) replaced by stubs that fail with a message saying so; or, given
    WRAP_TOOLS_DIR (vtkWrapHierarchy, vtkWrapPython, vtkWrapPythonInit built for Linux from
    VTK's source of the same tag, see build.sh), by those, with Python wrapping left ON and
    the wrapped vtkmodules/*.cpython-*.so re-pointed at the Linux wheel's too.

The SMP configuration (vtkSMP.h: Sequential default, STDThread built, no TBB/OpenMP) is the
same in both wheels of 9.5.0; this script checks it against what the Linux libvtkCommonCore.so
links (no libtbb, no libgomp) rather than trusting it.

usage: assemble_sdk.py SDK_UNZIPPED VTKMODULES_DIR OUT_DIR [WRAP_TOOLS_DIR]
  SDK_UNZIPPED   the unzipped vtk_sdk-X.Y.Z-...-macosx_*.whl (holds vtk_sdk/content/)
  VTKMODULES_DIR the Linux wheel's installed vtkmodules/ folder (site-packages/vtkmodules)
  OUT_DIR        where the SDK goes; VTK_DIR is then OUT_DIR/vtk-X.Y.Z.data/headers/cmake
  WRAP_TOOLS_DIR optional: Linux builds of the three Python wrapping executables
"""
import glob
import os
import re
import shutil
import subprocess
import sys

WRAP_TOOLS = ["vtkWrapHierarchy", "vtkWrapPython", "vtkWrapPythonInit", "vtkParseJava",
              "vtkWrapJava", "vtkWrapSerDes", "vtkProbeOpenGLVersion"]


def fail(msg):
    sys.exit("assemble_sdk.py: " + msg)


def patch(path, fn):
    with open(path) as f:
        text = f.read()
    new = fn(text)
    with open(path, "w") as f:
        f.write(new)
    return text != new


def main():
    if len(sys.argv) not in (4, 5):
        fail("usage: assemble_sdk.py SDK_UNZIPPED VTKMODULES_DIR OUT_DIR [WRAP_TOOLS_DIR]")
    src, vtkmodules, out = (os.path.abspath(a) for a in sys.argv[1:4])
    tools = os.path.abspath(sys.argv[4]) if len(sys.argv) == 5 else None
    python_tools = ["vtkWrapHierarchy", "vtkWrapPython", "vtkWrapPythonInit"]
    if tools:
        for tool in python_tools:
            if not os.access(os.path.join(tools, tool), os.X_OK):
                fail(f"{tools} has no executable {tool}")
    content = os.path.join(src, "vtk_sdk", "content")
    data = glob.glob(os.path.join(content, "vtk-*.data"))
    if len(data) != 1:
        fail(f"expected one vtk-*.data folder in {content}, found {data}")
    data_name = os.path.basename(data[0])
    headers = os.path.join(data[0], "headers")
    if not os.path.isfile(os.path.join(vtkmodules, "libvtkCommonCore.so")):
        fail(f"{vtkmodules} has no libvtkCommonCore.so: not the Linux vtk wheel's vtkmodules")

    if os.path.exists(out):
        shutil.rmtree(out)
    out_headers = os.path.join(out, data_name, "headers")
    # hierarchy/ holds VTK's wrapping hierarchy files: only wrapping needs them.
    shutil.copytree(headers, out_headers,
                    ignore=None if tools else shutil.ignore_patterns("hierarchy"))
    cmake_dir = os.path.join(out_headers, "cmake")
    include_dir = glob.glob(os.path.join(out_headers, "vtk-*"))[0]

    # Imported libraries -> the Linux wheel.
    linux_libs = {os.path.basename(p) for p in glob.glob(os.path.join(vtkmodules, "lib*.so"))}
    missing = []

    def to_linux(m):
        name = m.group(1)
        so = name + ".so"
        if so not in linux_libs:
            # libvtkWrappingPythonCore3.10 (the SDK's Python) -> 3.X of the Linux wheel.
            stem = re.sub(r"\d+\.\d+$", "", name)
            alts = sorted(l for l in linux_libs if re.fullmatch(re.escape(stem) + r"\d+\.\d+\.so", l))
            if stem != name and len(alts) == 1:
                so = alts[0]
            else:
                missing.append(name)
        return '"' + os.path.join(vtkmodules, so) + '"'

    def python_module(m):
        found = glob.glob(os.path.join(vtkmodules, m.group(1) + ".cpython-*.so"))
        if len(found) != 1:
            missing.append(m.group(1) + " (Python module)")
            return m.group(0)
        return '"' + found[0] + '"'

    def fix_release(text):
        text = re.sub(r'"\$\{_IMPORT_PREFIX\}/build/[^"]*/\.dylibs/(lib[^"/]+)\.dylib"', to_linux, text)
        text = re.sub(r'"\$\{_IMPORT_PREFIX\}/\./vtkmodules/(vtk\w+)\.cpython-[^"/]*darwin\.so"',
                      python_module, text)
        return re.sub(r'"@rpath/(lib[^"/]+)\.dylib"', lambda m: '"' + m.group(1) + '.so"', text)

    # VTK's own targets and those of the packages it bundles (viskores/).
    releases = glob.glob(os.path.join(cmake_dir, "**", "*-release.cmake"), recursive=True)
    for release in releases:
        patch(release, fix_release)
    if missing:
        fail("the Linux wheel lacks " + ", ".join(missing))
    for release in releases:
        with open(release) as f:
            left = re.findall(r"\.dylib|macosx|darwin", f.read())
        if left:
            fail(f"{release} still names macOS files ({len(left)} places)")

    # The wrapping executables: stubs that say why they cannot run.
    bindir = os.path.join(out, "bin")
    os.makedirs(bindir)
    for tool in WRAP_TOOLS:
        stub = os.path.join(bindir, tool)
        if tools and tool in python_tools:
            shutil.copy2(os.path.join(tools, tool), stub)
            continue
        with open(stub, "w") as f:
            f.write("#!/bin/sh\necho \"%s: not available in this assembled SDK: PyPI's vtk-sdk "
                    "wheel ships macOS binaries and the Linux vtk wheel ships no wrapping "
                    "executables (build them from VTK's source of the same tag)\" >&2\nexit 1\n"
                    % tool)
        os.chmod(stub, 0o755)
    # VTK-targets-release.cmake finds them at ${_IMPORT_PREFIX}/bin, _IMPORT_PREFIX = OUT_DIR.

    n = patch(os.path.join(cmake_dir, "VTK-targets.cmake"),
              lambda t: t.replace(";-framework Cocoa", "").replace('"-framework Cocoa"', '""'))
    if not n:
        fail("VTK-targets.cmake had no -framework Cocoa to drop: not the expected macOS SDK")

    def fix_config(t):
        t = t.replace('set(VTK_OPENGL_HAS_EGL "OFF")', 'set(VTK_OPENGL_HAS_EGL "ON")')
        t = t.replace('set(VTK_USE_X "OFF")', 'set(VTK_USE_X "ON")')
        if tools:
            return t
        return t.replace('set("${CMAKE_FIND_PACKAGE_NAME}_WRAP_PYTHON" "ON")',
                         'set("${CMAKE_FIND_PACKAGE_NAME}_WRAP_PYTHON" "OFF")')
    config = os.path.join(cmake_dir, "vtk-config.cmake")
    patch(config, fix_config)
    with open(config) as f:
        t = f.read()
    wrap = '_WRAP_PYTHON" "ON")' if tools else '_WRAP_PYTHON" "OFF")'
    for want in ['set(VTK_OPENGL_HAS_EGL "ON")', 'set(VTK_USE_X "ON")', wrap]:
        if want not in t:
            fail(f"vtk-config.cmake: could not set {want}")

    glconf = os.path.join(include_dir, "vtkRenderingOpenGLConfigure.h")
    if not patch(glconf, lambda t: t.replace("#define VTK_USE_COCOA", "#define VTK_USE_X")):
        fail(f"{glconf} had no VTK_USE_COCOA to replace")

    # Same SMP backends as the headers say (vtkSMP.h): a TBB or OpenMP backend would make
    # libvtkCommonCore.so need libtbb or libgomp.
    with open(os.path.join(include_dir, "vtkSMP.h")) as f:
        smp = f.read()
    needed = subprocess.run(["readelf", "-d", os.path.join(vtkmodules, "libvtkCommonCore.so")],
                            capture_output=True, text=True, check=True).stdout
    for backend, lib in [("TBB", "libtbb"), ("OPENMP", "libgomp")]:
        in_headers = f"#define VTK_SMP_ENABLE_{backend} 1" in smp
        in_lib = f"[{lib}" in needed
        if in_headers != in_lib:
            fail(f"SMP backend {backend}: the SDK headers say {in_headers}, the Linux "
                 f"libvtkCommonCore.so {'needs' if in_lib else 'does not need'} {lib}")

    print(os.path.join(cmake_dir))


if __name__ == "__main__":
    main()
