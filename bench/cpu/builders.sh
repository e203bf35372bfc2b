#!/usr/bin/env bash
# Reruns the CPU-builder measurements quoted in docs/results/cpu-builders/NOTES.md.
# usage: bench/cpu/builders.sh OUT_DIR [SPACESKIP_BINARY]
#   THREADS="1 2" (default) oneTBB thread counts for the build-time sweep; BRICKS="8 4 2 1".
set -euo pipefail
out=${1:?usage: $0 OUT_DIR [SPACESKIP_BINARY]}
bin=${2:-build/Core/spaceskip}
threads=${THREADS:-1 2}
bricks=${BRICKS:-8 4 2 1}
mkdir -p "$out"
all=naive,grid,lbvh-cpu,kdtree-cpu:shallow,kdtree-cpu:deep,kdtree-cpu:deep:mls32,kdtree-cpu:deep:mls128,hybrid
trees=lbvh-cpu,kdtree-cpu:shallow,kdtree-cpu:deep,kdtree-cpu:deep:mls32,kdtree-cpu:deep:mls128,hybrid
{ echo "host: $(uname -n) $(nproc) cores, $(date -u +%FT%TZ)"; uptime; } | tee "$out/env.txt"

# 1. The table: every builder, 256^3 stand-ins, 512x512 orthographic orbit, 4 frames, no ERT.
"$bin" bench gen:menger:256 gen:nbody:256 --builders "$all" --size 512x512 --frames 4 --build-reps 3 \
  --json "$out/bench-256.json" --csv "$out/bench-256.csv" | tee "$out/bench-256.txt"

# 2. Build time vs oneTBB threads and brick size (tiny viewport: only build numbers matter here).
for br in $bricks; do
  for th in $threads; do
    echo "== brick $br threads $th ($(uptime))" | tee -a "$out/build-sweep.txt"
    "$bin" bench gen:menger:256 gen:nbody:256 --builders "$trees" --brick "$br" --size 16x16 --frames 1 \
      --build-reps 5 --threads "$th" --json "$out/build-b${br}-t${th}.json" | tee -a "$out/build-sweep.txt"
  done
done

# 3. Menger sponge at the paper's 1024^3 (node counts and heights vs paper_statistics.csv).
for th in $threads; do
  echo "== menger 1024 brick 8 threads $th ($(uptime))" | tee -a "$out/menger-1024.txt"
  "$bin" bench gen:menger:1024 --builders "$trees" --size 16x16 --frames 1 --build-reps 3 --threads "$th" \
    --json "$out/menger-1024-t${th}.json" | tee -a "$out/menger-1024.txt"
done
