#!/usr/bin/env bash
# On the GPU machine (issue 38): the carried Core tests (`tests`: .vtkbundle-core/core.tar.xz) run
# the time-series tests, compute-sanitizer memcheck on the CUDA ones and the whole Core suite; the
# carried CLI (`bench`: .vtkbundle-cli/cli.tar.xz) the playback benchmark at 512^3 and 1024^3,
# uint8 and float32, 1024x1024 (bench/device/pack-core.sh packs both; TS_SPECS picks others).
# `scatter`: the CLI's volumetric-scattering benchmark instead (issue 34).
#   bash bench/device/time-series.sh OUT tests|bench|scatter
set -uo pipefail
out=${1:?usage: time-series.sh OUT tests|bench}
what=${2:?tests or bench}
src=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out" /tmp/c
if [ "$what" = tests ]; then tar -C /tmp/c -xJf "$src/.vtkbundle-core/core.tar.xz"
else tar -C /tmp/c -xJf "$src/.vtkbundle-cli/cli.tar.xz"; fi
export LD_LIBRARY_PATH=/tmp/c/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
# The Core tests read files of the source tree by the path they were built with.
[ -e /work/main ] || { mkdir -p /work && ln -s "$src" /work/main; }
{
  date -u +%Y-%m-%dT%H:%M:%SZ
  nvidia-smi --query-gpu=name,driver_version,pcie.link.gen.max,pcie.link.width.max --format=csv,noheader
  echo "cores: $(nproc)"
} > "$out/env.txt" 2>&1
B=/tmp/c/bin
# Volumetric scattering (issue 34) in the CLI: shading alone, then scattering (SCATTER, default
# 1,0.5,0) with its shadow rays queued for a second kernel and (SCATTER_DEFER="1 0") marched in
# place, N-body 2048^3 and the dense stand-in rm 1024^3 (SCATTER_SPECS), kernel fps per builder.
if [ "$what" = scatter ]; then
  for spec in ${SCATTER_SPECS:-nbody:2048 rm:1024}; do
    set -- ${spec/:/ }
    for mode in shade ${SCATTER_DEFER:-1 0}; do  # shading alone, then scattering per queue setting
      args="--shade on" env=""
      [ "$mode" = shade ] || { args="--scatter ${SCATTER:-1,0.5,0}"; env="SPACESKIP_DEFER_SHADOWS=$mode"; }
      cmd="bench gen:$1:$2 --backend cuda --builders ${SCATTER_BUILDERS:-auto,grid,distance-grid} --size 1024x1024 --frames 8 $args"
      echo "== $env spaceskip $cmd" >> "$out/scatter.log"
      env $env timeout 200 $B/spaceskip $cmd >> "$out/scatter.log" 2>&1
      echo "rc=$?" >> "$out/scatter.log"
    done
  done
  exit 0
fi
if [ "$what" != bench ]; then
  $B/spaceskip_core_tests --gtest_filter='TimeSeries.*' > "$out/time-series-tests.log" 2>&1
  echo "time-series tests rc=$?" >> "$out/env.txt"
  timeout 200 compute-sanitizer --tool memcheck --error-exitcode 9 $B/spaceskip_core_tests \
    --gtest_filter='TimeSeries.Cuda*' > "$out/memcheck.log" 2>&1
  echo "memcheck rc=$?" >> "$out/env.txt"
  timeout 330 $B/spaceskip_core_tests > "$out/core-tests.log" 2>&1
  echo "core tests rc=$?" >> "$out/env.txt"
  tail -3 "$out/core-tests.log" >> "$out/env.txt"
fi
# TS_SPECS: "SHAPE N TYPE HELD" items (default the N-body at 512^3 and 1024^3; rm: the mixing
# layer, widening over its first 25 steps); TS_MEMORY: the steps' host memory per run (pageable,
# pinned: the engine's page-locked step memory).
if [ "$what" != tests ]; then
  specs=${TS_SPECS:-"nbody 512 uint8 10,nbody 512 float32 10,nbody 1024 uint8 8,nbody 1024 float32 4"}
  IFS=, read -ra items <<< "$specs"
  for spec in "${items[@]}"; do
    set -- $spec
    for mem in ${TS_MEMORY:-pageable}; do  # TS_MEMORY="pageable pinned": the steps' host memory
      cmd="bench gen:$1:$2 --time-series 100 --steps-held $4 --step-type $3 --step-memory $mem --backend cuda --size 1024x1024 --check"
      echo "== spaceskip $cmd" >> "$out/bench.log"
      timeout ${TS_TIMEOUT:-140} $B/spaceskip $cmd >> "$out/bench.log" 2>&1
      echo "rc=$?" >> "$out/bench.log"
    done
  done
fi
