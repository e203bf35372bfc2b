# Shared by the old-vs-new device scripts (paper-ab.sh): sourced after `out` and
# `phases` are set. Unpacks build-bench/both.tar.xz (new) and old.tar.xz (old, when carried)
# into build-new/ and build-old/, sets the library path (build-bench/lib, .deps/tbb), writes
# OUT/env.txt (GPU, driver, commit), defines has/late/log/sanitize/summarize, and runs the
# `tests` phase (Core's GoogleTest binary of the new build).
has() { [[ " $phases " == *" $1 "* ]]; }
late() { [ -n "${DEADLINE:-}" ] && [ "$(date +%s)" -ge "$DEADLINE" ]; }
mkdir -p "$out"
out=$(cd "$out" && pwd)
src=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$src"
mkdir -p build-new build-old
[ -x build-new/spaceskip ] || tar xJf build-bench/both.tar.xz -C build-new || exit 1
[ -x build-old/spaceskip ] || { [ -f build-bench/old.tar.xz ] && tar xJf build-bench/old.tar.xz -C build-old; }
export LD_LIBRARY_PATH=$src/build-bench/lib:$src/.deps/tbb/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
{
  date -u +%Y-%m-%dT%H:%M:%SZ
  nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv
  git rev-parse HEAD 2>/dev/null || echo "tree of the carried working copy"
} > "$out/env.txt" 2>&1
log() { echo "$(date -u +%H:%M:%S) $*" | tee -a "$out/env.txt"; }
# compute-sanitizer TOOL (memcheck, racecheck) on the new build's Core tests matching FILTER,
# into OUT/TOOL.log, with its exit status logged: sanitize TOOL FILTER [TIMEOUT_S]
sanitize() {
  local cs
  cs=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
  timeout "${3:-240}" "$cs" --tool "$1" --error-exitcode 3 ./build-new/spaceskip_core_tests \
    --gtest_filter="$2" > "$out/$1.log" 2>&1
  log "$1 rc=$?"
  tail -3 "$out/$1.log"
}
# The key columns of every bench CSV in OUT into OUT/summary.txt, printed.
summarize() {
  for f in "$out"/*.csv; do
    [ -f "$f" ] && { echo "== $f"; cut -d, -f1,6,7,13,14,17,18,26,33,34 "$f"; }
  done > "$out/summary.txt" 2>&1
  cat "$out/summary.txt"
}

if has tests && ! late; then
  timeout 300 ./build-new/spaceskip_core_tests --gtest_brief=1 > "$out/core.log" 2>&1
  log "core tests rc=$?"
  tail -4 "$out/core.log"
fi
