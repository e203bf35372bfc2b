#!/usr/bin/env bash
# Why a frame with half the rays is not half the kernel (issue 35: N-body 2048^3 on 2 GPUs at
# 1024^2): the CLI's kernel benchmark at a whole and a half pixel count, then Nsight Compute on
# one frame of each, every kernel of the frame timed and the render kernel's SM activity (how
# busy the SMs were on average and at most, the waves, the occupancy).
#   usage: ncu-ray-scaling.sh OUT BIN [VOLUME] [SIZES]
#   BIN: a spaceskip CLI built with CUDA; VOLUME default gen:nbody:2048; SIZES default
#   "1024x1024 724x724" (724^2 is half of 1024^2's pixels, the same view).
set -uo pipefail
out=$1 bin=$2 vol=${3:-gen:nbody:2048} sizes=${4:-1024x1024 724x724}
mkdir -p "$out"
{ nvidia-smi -L; date -u; } > "$out/env.txt" 2>&1
common=(bench "$vol" --backend cuda --builders distance-grid)
for s in $sizes; do
  "$bin" "${common[@]}" --size "$s" --frames 30 > "$out/bench-$s.txt" 2>&1
  # Every kernel's duration, one line each (the last frames' are the file's last lines).
  timeout 200 ncu --metrics gpu__time_duration.sum --csv --page raw \
    "$bin" "${common[@]}" --size "$s" --frames 12 > "$out/kernels-$s.csv" 2>&1
  # 60 frames: the orbit turns 6 degrees a frame, as in bench/multi-gpu (with 10 it turned 36, and
  # the launch order, the last frame's costs, no longer matched the frame).
  timeout 200 ncu -k regex:renderKernel --launch-skip 6 --launch-count 1 \
    --section LaunchStats --section Occupancy --section WarpStateStats \
    --metrics gpu__time_duration.sum,sm__cycles_active.avg,sm__cycles_active.max,sm__cycles_active.min,sm__cycles_elapsed.max,sm__warps_active.avg.pct_of_peak_sustained_active,sm__throughput.avg.pct_of_peak_sustained_elapsed,l1tex__t_sector_hit_rate.pct,lts__t_sector_hit_rate.pct \
    "$bin" "${common[@]}" --size "$s" --frames 60 > "$out/render-$s.txt" 2>&1
done
