#!/usr/bin/env bash
# On the GPU machine: a block trace of one frame of the CLI's kernel benchmark (each render
# block's SM, start, end and cycles, the launch order's keys, the last frame's cycles; in
# TRACE.counts each pixel's samples and march iterations in each ray segment), at N-body
# 2048^3 in a 1024^2 window and at 724^2 (half the pixels: one rank's share on 2 GPUs), frame 40
# of a 60-frame orbit (6 degrees a frame, as bench/multi-gpu), then block-trace.py on both.
# BIN is a CLI built with bench/device/block-trace.patch (a measurement build, never main):
#   git apply bench/device/block-trace.patch && ninja -C build spaceskip &&
#   bash bench/device/pack-core.sh build && git apply -R bench/device/block-trace.patch
#   usage: block-trace.sh OUT BIN [VOLUME] [SIZES]   (FIRST=N: block-trace.py --first N)
set -uo pipefail
out=$1 bin=$2 vol=${3:-gen:nbody:2048} sizes=${4:-1024x1024 724x724}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
{ nvidia-smi -L; date -u; } > "$out/env.txt" 2>&1
for s in $sizes; do
  SPACESKIP_TRACE_FRAME=40 SPACESKIP_TRACE_OUT="$out/trace-$s.bin" \
    "$bin" bench "$vol" --backend cuda --builders distance-grid --size "$s" --frames 60 > "$out/bench-$s.txt" 2>&1
done
python3 "$here/block-trace.py" ${FIRST:+--first "$FIRST"} "$out"/trace-*.bin | tee "$out/summary.txt"
