#!/usr/bin/env bash
# Installs the Debian 12 packages SpaceSkip builds against (run as root). Idempotent.
# ParaView 5.11 + its VTK come from Debian (paraview-dev); the extra -dev packages are the ones
# find_package(ParaView) needs but paraview-dev does not pull in (see docs in shared PARAVIEW.md).
# Do not install libvtk9-dev: it conflicts with python3-paraview.
# python3-dev: the headers the Python wrapping of the VTK module needs (SPACESKIP_WRAP_PYTHON).
# clang + libclang-rt-14-dev: the libFuzzer harnesses (scripts/fuzz.sh; -fsanitize=fuzzer needs the
# runtime, which clang-14 only recommends).
# libhwy-dev: Highway, the CPU backend's SIMD ray packets (Core/src/CpuMarch.cpp; optional: without
# it the CPU backend marches one ray at a time).
set -euo pipefail
pkgs=(build-essential cmake ninja-build pkg-config libtbb-dev libpng-dev libgtest-dev googletest
      paraview paraview-dev python3-paraview python3-numpy python3-dev xvfb xauth
      libopenmpi-dev openmpi-bin libdouble-conversion-dev liblz4-dev libglew-dev libutfcpp-dev libtiff-dev
      clang libclang-rt-14-dev libhwy-dev)
# SPACESKIP_PLOTS=1: also matplotlib for scripts/plot-paper-bench.py (not needed by the tests or CI).
if [ "${SPACESKIP_PLOTS:-0}" = 1 ]; then pkgs+=(python3-matplotlib); fi
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
echo "setup: Debian packages ready"
