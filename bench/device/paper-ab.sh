#!/usr/bin/env bash
# Kernel fps of two builds side by side: the carried old binary (build-bench/old.tar.xz ->
# build-old/spaceskip, e.g. the previous head's) and the new one (build-bench/both.tar.xz ->
# build-new/: stripped spaceskip + spaceskip_core_tests; build-bench/lib, .deps/tbb), one process
# per run, alternated, on the paper's protocol (kernel fps from CUDA events); first the new
# build's Core tests with compute-sanitizer memcheck/racecheck. Uses ab-common.sh.
#
#   bench/device/paper-ab.sh OUTDIR [phases]
#   phases (default: tests runs): tests (Core tests, then compute-sanitizer memcheck on
#          MEMCHECK_FILTER and racecheck on RACECHECK_FILTER), runs
#   env: DEADLINE (epoch s: no phase starts after), RUNS ("old new old new new old": which build
#        each process runs; SPEC:VAR=VALUE runs it with one environment variable set, e.g.
#        new:SPACESKIP_RAY_SEGMENTS=1), DATASETS, ITEMS, FRAMES (8)
set -uo pipefail
out=${1:?usage: paper-ab.sh OUTDIR [phases]}
shift
phases=${*:-tests runs}
source "$(dirname "$0")/ab-common.sh"
if has tests && ! late; then
  sanitize memcheck "${MEMCHECK_FILTER:-DeviceImage.*:CudaBackend.*}"
  sanitize racecheck "${RACECHECK_FILTER:-CudaBackend.SegmentedRaysRenderTheSameImage}" 120
fi
sets=${DATASETS:-nbody_2048,nbody_1024,menger_sponge,richtmyer_meshkov,kingsnake}
items=${ITEMS:-naive,distance-grid,distance-grid:hw,auto}
if has runs; then
  n=0
  for spec in ${RUNS:-old new old new new old}; do
    n=$((n + 1))
    late && break
    b=${spec%%:*}
    envs=()
    [ "$spec" != "$b" ] && envs=("${spec#*:}")
    bin=build-$b/spaceskip
    [ -x "$bin" ] || { log "$bin missing"; continue; }
    name="$b${envs:+-${envs[0]//=/-}}-$n"
    env "${envs[@]}" timeout 200 "$bin" bench --paper --datasets "$sets" \
      --builders "$items" --frames "${FRAMES:-8}" --csv "$out/$name.csv" > "$out/$name.log" 2>&1
    log "$name rc=$? ${envs[*]}"
  done
fi
summarize
