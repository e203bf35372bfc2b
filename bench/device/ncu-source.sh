#!/usr/bin/env bash
# On the GPU machine: where one render kernel's warps stall, line by line. Nsight Compute's
# source counters (warp stall sampling) and warp state statistics on the render kernel of frame
# 40 of the CLI's 60-frame orbit, then the lines with the most samples (ncu-source.py).
# BIN: a CLI built with -DCMAKE_CUDA_FLAGS=-lineinfo (the product's code; line info only).
#   usage: ncu-source.sh OUT BIN [VOLUME] [SIZE]    (default gen:nbody:2048 724x724)
set -uo pipefail
out=$1 bin=$2 vol=${3:-gen:nbody:2048} size=${4:-724x724}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
{ nvidia-smi -L; date -u; } > "$out/env.txt" 2>&1
timeout 420 ncu -k regex:renderKernel --launch-skip 40 --launch-count 1 --section SourceCounters \
  --section WarpStateStats --import-source yes -o "$out/prof" \
  "$bin" bench "$vol" --backend cuda --builders distance-grid --size "$size" --frames 60 > "$out/ncu-run.txt" 2>&1
ncu -i "$out/prof.ncu-rep" --page details --section WarpStateStats --print-details all > "$out/warpstate.txt" 2>&1
ncu -i "$out/prof.ncu-rep" --page source --csv --print-source cuda,sass > "$out/source.csv" 2>&1
python3 "$here/ncu-source.py" "$out/source.csv" | tee "$out/summary.txt"
