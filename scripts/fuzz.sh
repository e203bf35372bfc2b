#!/usr/bin/env bash
# Builds the libFuzzer harnesses (Testing/Fuzz, clang) and runs each one, bounded; a crash, a
# timeout or an out-of-memory fails the script and leaves the input in build-fuzz/artifacts/.
#   bash scripts/fuzz.sh                      # every harness for FUZZ_SECONDS (default 30) seconds
#   FUZZ_RUNS=1000000 bash scripts/fuzz.sh    # or a fixed number of executions each
#   bash scripts/fuzz.sh nrrd raw_name        # only these harnesses
# The committed seeds (Testing/Fuzz/corpus/<harness>) are read only; new inputs go to build-fuzz.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="${SPACESKIP_FUZZ_BUILD:-$root/build-fuzz}"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
# -O1 and line tables only, as scripts/test.sh builds its ASan + UBSan stage (there half the
# compile of -O2 -g); the stacks of a report keep file and line. No Highway (SPACESKIP_USE_HWY=OFF):
# the render harness drives the scalar integrator (Testing/Fuzz/CMakeLists.txt says why).
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" -DSPACESKIP_USE_HWY=OFF \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DSPACESKIP_FUZZ=ON \
  -DSPACESKIP_ENABLE_CUDA=OFF -DSPACESKIP_ENABLE_PARAVIEW=OFF "${launcher[@]}" >/dev/null
cmake --build "$build" -j "$(nproc)" --target spaceskip_fuzzers

harnesses=("$@")
[ ${#harnesses[@]} -gt 0 ] || harnesses=(raw_name nrrd transfer_function cli_options render)
if [ -n "${FUZZ_RUNS:-}" ]; then bound=(-runs="$FUZZ_RUNS"); else bound=(-max_total_time="${FUZZ_SECONDS:-30}"); fi
mkdir -p "$build/artifacts"
for h in "${harnesses[@]}"; do
  work="$build/corpus/$h"
  mkdir -p "$work"
  echo "== fuzz $h (${bound[*]})"
  # -rss_limit_mb: the harnesses cap volumes at 64 MiB, so more than 1 GiB is a bug.
  cmd=("$build/Testing/Fuzz/fuzz_$h" "${bound[@]}" -rss_limit_mb=1024 -timeout=10 -max_len=4096
       -print_final_stats=1 -dict="$root/Testing/Fuzz/dict/$h.dict"
       -artifact_prefix="$build/artifacts/$h-" "$work" "$root/Testing/Fuzz/corpus/$h")
  echo "${cmd[*]}"
  start=$(date +%s)
  if ! "${cmd[@]}" >"$build/fuzz_$h.log" 2>&1; then
    tail -n 60 "$build/fuzz_$h.log"
    echo "fuzz: $h FAILED (input in $build/artifacts/)" >&2
    exit 1
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$build/fuzz_$h.log" | grep -o '[0-9]*$' || echo "?")
  echo "fuzz: $h ok, $runs executions in $(( $(date +%s) - start )) s"
done
