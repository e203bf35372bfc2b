#!/usr/bin/env bash
# The paper's whole benchmark on a GPU machine (issue 13): `spaceskip bench --paper` on the CUDA
# backend at the paper's dims (SCALE=1), every builder and parameter set of its table plus ours,
# with a time limit so the run ends inside the device tool's 10 minutes per command; then, when
# matplotlib is there, the figures (scripts/plot-paper-bench.py; else draw them afterwards).
#
#   bench/device/paper-bench.sh OUTDIR
#   env: BUILD_DIR (default ./build-gpu; built when it has no spaceskip), SCALE (1), FRAMES (8),
#        TIME_LIMIT (420 s: no new item starts after it), DATASETS / BUILDERS (subsets, comma
#        separated; default all), BACKEND (cuda), EXTRA (more bench options)
# OUTDIR receives: env.txt, paper.csv, paper.json, bench.log (+ the PNGs when plotted).
set -uo pipefail
out=${1:?usage: paper-bench.sh OUTDIR}
mkdir -p "$out"
out=$(cd "$out" && pwd)
src=$(cd "$(dirname "$0")/../.." && pwd)
build=${BUILD_DIR:-$src/build-gpu}
. "$src/bench/device/tbb-env.sh"
{
  echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)  host: $(hostname)  cores: $(nproc)"
  nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv 2>&1
  echo "git: $(cd "$src" && git rev-parse HEAD 2>/dev/null || echo 'no git (copied tree)')"
  free -g | head -2
} > "$out/env.txt"
if [ ! -x "$build/Core/spaceskip" ] && [ ! -x "$build/bin/spaceskip" ]; then
  cmake -S "$src" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSPACESKIP_ENABLE_CUDA=ON \
    -DSPACESKIP_ENABLE_PARAVIEW=OFF -DCMAKE_CUDA_ARCHITECTURES=90 > "$out/build.log" 2>&1 &&
    ninja -C "$build" spaceskip >> "$out/build.log" 2>&1 || { echo "build failed"; tail -30 "$out/build.log"; exit 1; }
fi
exe=$build/bin/spaceskip
[ -x "$exe" ] || exe=$build/Core/spaceskip
args=(bench --paper --backend "${BACKEND:-cuda}" --scale "${SCALE:-1}" --frames "${FRAMES:-8}"
      --time-limit "${TIME_LIMIT:-420}" --csv "$out/paper.csv" --json "$out/paper.json")
[ -n "${DATASETS:-}" ] && args+=(--datasets "$DATASETS")
[ -n "${BUILDERS:-}" ] && args+=(--builders "$BUILDERS")
echo "command: $exe ${args[*]} ${EXTRA:-}" | tee -a "$out/env.txt"
"$exe" "${args[@]}" ${EXTRA:-} > "$out/bench.log" 2>&1
rc=$?
echo "bench rc=$rc"
tail -40 "$out/bench.log"
if /usr/bin/python3 -c "import matplotlib" 2>/dev/null; then
  /usr/bin/python3 "$src/scripts/plot-paper-bench.py" "$out/paper.csv" --out "$out" --title "H100, CUDA, scale ${SCALE:-1}"
fi
exit $rc
