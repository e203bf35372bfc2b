#!/usr/bin/env bash
# All tests: set up, build everything that this machine can build (CUDA compiles when nvcc is
# present; GPU tests skip without a device), run ctest under Xvfb, then Core's tests again under
# AddressSanitizer + UndefinedBehaviorSanitizer, then a short bounded run of each libFuzzer
# harness (scripts/fuzz.sh; SPACESKIP_FUZZ_SECONDS per harness, default 30, 0 skips).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/setup-debian.sh"
bash "$root/scripts/build.sh"

# One Xvfb for all rendering tests (VTK/ParaView here need an X server).
source "$root/scripts/xvfb.sh" 91
(cd "$root/build" && ctest --output-on-failure -j "$(nproc)" --timeout 600)

echo "== Core tests under ASan + UBSan"
asan="$root/build-asan"
cmake -S "$root" -B "$asan" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSPACESKIP_SANITIZE=ON \
  -DSPACESKIP_ENABLE_CUDA=OFF -DSPACESKIP_ENABLE_PARAVIEW=OFF
cmake --build "$asan" -j "$(nproc)"
(cd "$asan" && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j "$(nproc)" -L core)
fuzz_seconds=${SPACESKIP_FUZZ_SECONDS:-30}
if [ "$fuzz_seconds" -gt 0 ]; then
  echo "== fuzz: each parser for $fuzz_seconds s (clang, libFuzzer + ASan + UBSan)"
  FUZZ_SECONDS="$fuzz_seconds" bash "$root/scripts/fuzz.sh"
fi
echo "all tests passed"
