#!/usr/bin/env bash
# Nsight Compute profile of the render kernel per builder on one volume (issue 13: why skipping
# loses to naive on dense data). usage: ncu-render-kernel.sh OUT BIN [VOLUME] [BUILDERS]
#   BIN: a spaceskip CLI built with CUDA; VOLUME default gen:menger:1024;
#   BUILDERS default naive,grid,kdtree-gpu-fast:deep:mls128,lbvh; env EXTRA: more bench options.
set -uo pipefail
out=$1 bin=$2 vol=${3:-gen:menger:1024} builders=${4:-naive,grid,kdtree-gpu-fast:deep:mls128,lbvh}
mkdir -p "$out"
nvidia-smi -L > "$out/env.txt" 2>&1; date -u >> "$out/env.txt"
"$bin" bench "$vol" --backend cuda --builders "$builders" --frames 8 ${EXTRA:-} --csv "$out/bench.csv" > "$out/bench.txt" 2>&1
IFS=, read -ra items <<< "$builders"
for b in "${items[@]}"; do
  tag=${b//:/_}
  timeout 150 ncu -k regex:renderKernel --launch-skip 1 --launch-count 1 \
    --section SpeedOfLight --section Occupancy --section LaunchStats --section WarpStateStats \
    --section SchedulerStats --section MemoryWorkloadAnalysis --section SourceCounters \
    --metrics smsp__thread_inst_executed_per_inst_executed.ratio,smsp__thread_inst_executed_per_inst_executed.pct \
    "$bin" bench "$vol" --backend cuda --builders "$b" --frames 2 ${EXTRA:-} > "$out/ncu-$tag.txt" 2>&1
done
