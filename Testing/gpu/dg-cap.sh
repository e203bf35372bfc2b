#!/usr/bin/env bash
# Issue 13, round 10: DistanceGrid's distance cap (SPACESKIP_DG_CAP, a measurement switch in
# CudaBackend::build) against its build time and frame rate, the paper's protocol, one process per
# setting, alternated. Carried as cli-and-tests.sh: build-bench (both.tar.xz: the CLI), .deps.
#   Testing/gpu/dg-cap.sh OUTDIR   env: DATASETS (default nbody_2048,richtmyer_meshkov,nbody_1024),
#   BUILDERS (distance-grid,distance-grid:hw), CAPS (64 32 16), REPS (1 2)
set -uo pipefail
out=${1:?usage: dg-cap.sh OUTDIR}
mkdir -p "$out" && out=$(cd "$out" && pwd)
src=$(cd "$(dirname "$0")/../.." && pwd)
cd "$src"
mkdir -p build-new
[ -x build-new/spaceskip ] || tar xJf build-bench/both.tar.xz -C build-new || exit 1
export LD_LIBRARY_PATH=$src/build-bench/lib:$src/.deps/tbb/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
{ date -u +%Y-%m-%dT%H:%M:%SZ; nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv; } > "$out/env.txt" 2>&1
for rep in ${REPS:-1 2}; do
  for cap in ${CAPS:-64 32 16}; do
    SPACESKIP_DG_CAP=$cap timeout 150 build-new/spaceskip bench --paper --backend cuda --frames 8 \
      --datasets "${DATASETS:-nbody_2048,richtmyer_meshkov,nbody_1024}" --builders "${BUILDERS:-distance-grid,distance-grid:hw}" \
      --csv "$out/cap$cap-$rep.csv" > "$out/cap$cap-$rep.log" 2>&1
    echo "$(date -u +%T) cap $cap rep $rep rc=$?" | tee -a "$out/env.txt"
  done
done
