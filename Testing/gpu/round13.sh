#!/usr/bin/env bash
# Issue 13, round 13: toward the window's frame rate at N-body 2048^3 — the render kernel's
# launch shape and launch style, same binary, one process per setting, alternated (the default
# 16x8 between the others). Carried as cli-and-tests.sh: build-bench (both.tar.xz, lib/), .deps/tbb.
# Results: docs/results/round13-h100/NOTES.md. The column tool is not on the device: raw CSV.
#
#   Testing/gpu/round13.sh OUTDIR [phases]
#   phases (default: blocks): tests blocks bricks order segments resident
#   env: DEADLINE (epoch s: no phase starts after), BLOCKS ("16x8 8x4 ..."), DATASETS, ITEMS
set -uo pipefail
out=${1:?usage: round13.sh OUTDIR [phases]}
shift
phases=${*:-blocks}
source "$(dirname "$0")/ab-common.sh"
sets=${DATASETS:-nbody_2048,nbody_1024,menger_sponge}
items=${ITEMS:-distance-grid,distance-grid:hw,auto}
run() {  # name [env...]
  local name=$1
  shift
  env "$@" timeout 200 build-new/spaceskip bench --paper --datasets "$sets" --builders "$items" --frames 8 \
    --csv "$out/$name.csv" > "$out/$name.log" 2>&1
  log "$name rc=$? $*"
}
# SPACESKIP_CUDA_BLOCK=WxH (CudaExecutor: the block of pixels; a warp is its first 32 threads,
# row-major: 16x8 -> warps of 16x2 pixels, 8x4 -> one warp a block of 8x4 pixels).
if has blocks; then
  n=0
  for b in ${BLOCKS:-16x8 8x4 32x4 8x8 16x8 4x8 32x2 16x4 8x16 16x8 8x4 32x4}; do
    n=$((n + 1))
    late && break
    run "block$b-$n" SPACESKIP_CUDA_BLOCK=$b
  done
fi
# The brick size with the sub-brick masks (4^3 parts a brick: parts of 2, 3, 4, 8 voxels at
# bricks 8, 12, 16, 32), ITEMS in one process, REPS processes (default 2) with --edits EDITS.
if has bricks; then
  for n in $(seq "${REPS:-2}"); do
    late && break
    env timeout 250 build-new/spaceskip bench --paper --datasets "$sets" --builders "$items" --frames 8 \
      --edits "${EDITS:-8}" --csv "$out/bricks-$n.csv" > "$out/bricks-$n.log" 2>&1
    log "bricks-$n rc=$?"
  done
fi
# The persistent launch's tile order (SPACESKIP_TILE_ORDER=1: tiles nearest the image's centre
# first), ORDERS: "BLOCK:RESIDENT:ORDER ..." one process each (resident 0: the plain launch).
if has order; then
  n=0
  for spec in ${ORDERS:-16x8:0:0 16x8:8:1 8x4:32:1 16x8:0:0 16x8:8:0 8x4:32:0 16x8:8:1 8x4:32:1 16x8:0:0}; do
    n=$((n + 1))
    late && break
    IFS=: read -r b r o <<< "$spec"
    run "order-$b-$r-$o-$n" SPACESKIP_CUDA_BLOCK=$b SPACESKIP_CUDA_RESIDENT=$r SPACESKIP_TILE_ORDER=$o
  done
fi
# Rays cut into K segments marched by separate threads (SPACESKIP_RAY_SEGMENTS=K, 1: whole
# rays), SEGMENTS: one process per K, alternated.
if has segments; then
  n=0
  for k in ${SEGMENTS:-1 4 8 1 4 8}; do
    n=$((n + 1))
    late && break
    run "segments$k-$n" SPACESKIP_RAY_SEGMENTS=$k
  done
fi
# SPACESKIP_CUDA_RESIDENT=N: persistent blocks (N per SM) taking tiles from a counter.
if has resident; then
  n=0
  for r in ${RESIDENTS:-0 4 8 0 16 32 0}; do
    n=$((n + 1))
    late && break
    run "resident$r-$n" SPACESKIP_CUDA_RESIDENT=$r
  done
fi
summarize
