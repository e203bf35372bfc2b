#!/usr/bin/env bash
# Where the N-body 2048^3 frame goes (issue 13: 700 fps in the window needs a kernel well under
# the 1.4 ms it takes): the paper's protocol with DistanceGrid variants side by side in one
# process (brick size, persistent launch, block shape), then an Nsight Compute profile of the
# DistanceGrid kernel. Carried binaries as cli-and-tests.sh (build-bench/both.tar.xz, .deps/tbb).
#
#   Testing/gpu/profile-nbody.sh OUTDIR
#   env: DATASET (nbody_2048), ITEMS (the bench items), MASKS (SPACESKIP_SUB_MASKS values: 1),
#        BLOCKS (block shapes to sweep),
#        NCU_ITEM (distance-grid:hw; empty: no profile), NCU_VOLUME (gen:nbody:2048)
set -uo pipefail
out=${1:?usage: profile-nbody.sh OUTDIR}
mkdir -p "$out"
src=$(cd "$(dirname "$0")/../.." && pwd)
cd "$src"
mkdir -p build-x
[ -x build-x/spaceskip ] || tar xJf build-bench/both.tar.xz -C build-x || exit 1
export LD_LIBRARY_PATH=$src/build-bench/lib:$src/.deps/tbb/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
bin=$src/build-x/spaceskip
{
  date -u +%Y-%m-%dT%H:%M:%SZ
  nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv
  git rev-parse HEAD 2>/dev/null || echo "tree of the carried working copy"
} > "$out/env.txt" 2>&1
ds=${DATASET:-nbody_2048}
items=${ITEMS:-distance-grid:hw,distance-grid:hw:res0,distance-grid:hw:res12,distance-grid:brick4:hw,distance-grid:brick16:hw,distance-grid:brick32:hw,grid:hw,grid:brick16:hw,kdtree-gpu-fast:empty:bins0:hw}
# MASKS: the values of SPACESKIP_SUB_MASKS to run the items with (0: whole bricks, 1: sub-brick masks)
for m in ${MASKS:-1}; do
  echo "== items, default block, SPACESKIP_SUB_MASKS=$m" >> "$out/bench.log"
  SPACESKIP_SUB_MASKS=$m timeout 200 "$bin" bench --paper --datasets "$ds" --builders "$items" --frames 8 \
    --csv "$out/items-masks$m.csv" >> "$out/bench.log" 2>/dev/null
  echo "items masks $m rc=$?" | tee -a "$out/env.txt"
done
for b in ${BLOCKS:-8x8 32x4 16x16}; do
  echo "== block $b" >> "$out/bench.log"
  timeout 100 "$bin" bench --paper --datasets "$ds" --builders distance-grid:hw,distance-grid:hw:res0 --frames 8 \
    --cuda-block "$b" --csv "$out/block-$b.csv" >> "$out/bench.log" 2>/dev/null
  echo "block $b rc=$?" | tee -a "$out/env.txt"
done
if [ -n "${NCU_ITEM-distance-grid:hw}" ]; then
  ncu=$(command -v ncu || ls /usr/local/cuda/bin/ncu 2>/dev/null)
  timeout 200 "$ncu" -k regex:renderKernel --launch-skip 2 --launch-count 1 \
    --section SpeedOfLight --section Occupancy --section LaunchStats --section WarpStateStats \
    --section SchedulerStats --section MemoryWorkloadAnalysis --section InstructionStats \
    --metrics smsp__thread_inst_executed_per_inst_executed.ratio,l1tex__t_sector_hit_rate.pct,lts__t_sector_hit_rate.pct \
    "$bin" bench "${NCU_VOLUME:-gen:nbody:2048}" --backend cuda --builders "${NCU_ITEM:-distance-grid:hw}" --frames 3 \
    > "$out/ncu.txt" 2>&1
  echo "ncu rc=$?" | tee -a "$out/env.txt"
fi
cat "$out/bench.log" | grep -v "^\s*$" | tail -40
