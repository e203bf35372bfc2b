#!/usr/bin/env bash
# Builds Core with CUDA on a GPU machine, runs the tests, compute-sanitizer (memcheck, racecheck)
# on the CUDA tests, and the benchmarks; writes everything into OUTDIR (see docs/gpu.md).
#
#   bench/device/run-core.sh OUTDIR [PHASE...]
#   PHASE: build test sanitize bench-small bench-large bench-nbody-builders bench-distance-grid bench-sweep regcap
#          resident bench-launch bench-menger profile2048 blocks ncu
#          (default: build test sanitize bench-small)
#          bench-sweep: KdTreeCPU vs KdTreeGPUFast with bins 0 (the same trees) at 256^3..2048^3
#   env:   BUILD_DIR (default ./build-gpu), TBB_DIR/LD_LIBRARY_PATH (set from ../.deps or ./.deps
#          when present), BENCH_FRAMES (8), SANITIZE_FILTER (gtest filter for the sanitizer runs),
#          SANITIZE_TOOLS ("memcheck racecheck"), SANITIZE_TIMEOUT (240 s per tool), SANITIZE_DEADLINE
#          (epoch seconds; shortens that timeout), BENCH_NBODY_KDGPU (the one KdTreeGPU deep variant
#          of bench-nbody-builders, "kdtree-gpu:deep:mls32:cold"; empty for none)
#
# OUTDIR receives at most 8 files (the device tool's limit): env.txt, build.log, ctest.log,
# sanitize.log, bench.log, bench.csv, bench.json, and logs.tgz (everything).
set -uo pipefail
out=${1:?usage: run-core.sh OUTDIR [PHASE...]}
shift
phases=${*:-build test sanitize bench-small}
src=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out"
out=$(cd "$out" && pwd)
work=$(mktemp -d)
build=${BUILD_DIR:-$src/build-gpu}
frames=${BENCH_FRAMES:-8}
status=0

. "$src/bench/device/tbb-env.sh"

log() { echo "[$(date -u +%H:%M:%S)] $*" | tee -a "$work/run.log"; }
has() { case " $phases " in *" $1 "*) return 0 ;; *) return 1 ;; esac; }

{
  echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  echo "host: $(hostname)  phases: $phases"
  nvidia-smi --query-gpu=name,memory.total,driver_version,clocks.max.sm,clocks.max.mem --format=csv 2>&1
  nvcc --version 2>&1 | tail -2
  echo "cmake: $(cmake --version | head -1)  cores: $(nproc)"
  echo "git: $(cd "$src" && git rev-parse HEAD 2>/dev/null || echo 'no git (copied tree)')"
} > "$work/env.txt"
cp "$work/env.txt" "$out/env.txt"

if has build; then
  log "configure + build in $build"
  cmake -S "$src" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSPACESKIP_ENABLE_CUDA=ON \
    -DSPACESKIP_ENABLE_PARAVIEW=OFF -DCMAKE_CUDA_ARCHITECTURES=90 > "$work/build.log" 2>&1 &&
    ninja -C "$build" >> "$work/build.log" 2>&1
  rc=$?
  log "build rc=$rc"
  [ $rc -eq 0 ] || status=1
  tail -c 60000 "$work/build.log" > "$out/build.log"
fi
tests=$build/Testing/spaceskip_core_tests
cli=$build/Core/spaceskip

if has test; then
  log "ctest"
  (cd "$build" && ctest --output-on-failure -j4 --timeout 600) > "$work/ctest.log" 2>&1
  rc=$?
  log "ctest rc=$rc"
  [ $rc -eq 0 ] || status=1
  # The CUDA tests alone, verbose (hardware-filter error lines, skip reasons).
  "$tests" --gtest_filter='*Cuda*' > "$work/cuda-tests.log" 2>&1
  log "cuda tests rc=$?"
  { tail -c 40000 "$work/ctest.log"; echo; echo "==== CUDA tests ===="; cat "$work/cuda-tests.log"; } > "$out/ctest.log"
fi

if has sanitize; then
  filter=${SANITIZE_FILTER:-'CudaBackend.*:Volumes/CudaImage.EqualsCpuForEveryBuilder/nbody_*'}
  for tool in ${SANITIZE_TOOLS:-memcheck racecheck}; do
    log "compute-sanitizer $tool ($filter)"
    limit=${SANITIZE_TIMEOUT:-240}
    # SANITIZE_DEADLINE (epoch seconds): stop in time for the device tool's per-command limit.
    if [ -n "${SANITIZE_DEADLINE:-}" ]; then
      left=$(( SANITIZE_DEADLINE - $(date +%s) ))
      [ $left -lt $limit ] && limit=$left
      [ $limit -lt 10 ] && limit=10
    fi
    timeout $limit compute-sanitizer --tool $tool --error-exitcode 99 --target-processes all \
      "$tests" --gtest_filter="$filter" > "$work/sanitize-$tool.log" 2>&1
    rc=$?
    log "compute-sanitizer $tool rc=$rc"
    [ $rc -eq 0 ] || status=1
  done
  for tool in ${SANITIZE_TOOLS:-memcheck racecheck}; do
    echo "==== $tool ===="
    grep -E "ERROR SUMMARY|RACECHECK SUMMARY|Invalid|Race|hazard|\[  (PASSED|FAILED|SKIPPED) |tests ran" "$work/sanitize-$tool.log" | head -60
    tail -5 "$work/sanitize-$tool.log"
  done > "$out/sanitize.log"
fi

bench() {  # NAME VOLUME BUILDERS [extra args]
  local name=$1 vol=$2 builders=$3
  shift 3
  log "bench $name: $vol"
  "$cli" bench "$vol" --backend cuda --builders "$builders" --size 1024x1024 --frames "$frames" \
    --json "$work/bench-$name.json" --csv "$work/bench-$name.csv" "$@" > "$work/bench-$name.log" 2>&1
  local rc=$?
  log "bench $name rc=$rc"
  cat "$work/bench-$name.log" >> "$work/bench.log"
  cp "$work/bench.log" "$out/bench.log"  # progressive: survives a run cut short
  if [ -f "$work/bench-$name.csv" ]; then
    [ -f "$out/bench.csv" ] || head -1 "$work/bench-$name.csv" > "$out/bench.csv"
    tail -n +2 "$work/bench-$name.csv" >> "$out/bench.csv"
  fi
  [ $rc -eq 0 ] || status=1
}

kd="kdtree-gpu:shallow,kdtree-gpu:deep:mls32,kdtree-gpu:deep:mls128,kdtree-gpu-fast:shallow,kdtree-gpu-fast:deep,kdtree-gpu-fast:deep:mls32,kdtree-gpu-fast:deep:mls128"
cpu="lbvh-cpu,kdtree-cpu:shallow,kdtree-cpu:deep:mls32,kdtree-cpu:deep:mls128,hybrid"
hw="naive:hw,grid:hw,grid:brick16:hw,lbvh:hw,kdtree-gpu-fast:deep:mls32:hw,kdtree-gpu-fast:deep:mls128:hw"
all="naive,grid,lbvh,$kd,$cpu,$hw"
if has bench-small; then
  for n in 256 512 1024; do bench "nbody$n" "gen:nbody:$n" "$all"; done
  bench menger1024 gen:menger:1024 "$all"
fi
if has bench-large; then
  # KdTreeGPU (the paper's host-driven recursion) is timed on its first build only at 2048^3.
  kdcold="kdtree-gpu:shallow:cold,kdtree-gpu:deep:mls32:cold,kdtree-gpu:deep:mls128:cold"
  kdfast="kdtree-gpu-fast:shallow,kdtree-gpu-fast:deep,kdtree-gpu-fast:deep:mls32,kdtree-gpu-fast:deep:mls128"
  # CPU-built trees (built on the GPU machine's 16 cores, uploaded) likewise.
  cpucold="lbvh-cpu:cold,kdtree-cpu:shallow:cold,kdtree-cpu:deep:mls32:cold,kdtree-cpu:deep:mls128:cold,hybrid:cold"
  bench nbody2048 gen:nbody:2048 "naive,grid,lbvh,$kdfast,$hw,$cpucold,${BENCH_2048_KDGPU:-$kdcold}"
fi
if has bench-nbody-builders; then
  # The resolution-independent N-body particle set: the GPU builders at 256^3..2048^3,
  # then naive at one-voxel steps (the paper does not state its step; ours defaults to half a voxel).
  kd1=${BENCH_NBODY_KDGPU-kdtree-gpu:deep:mls32:cold}
  r2="naive,naive:hw,grid,grid:hw,lbvh,lbvh:hw,kdtree-gpu-fast:shallow,kdtree-gpu-fast:deep:mls32,kdtree-gpu-fast:deep:mls32:hw,kdtree-gpu-fast:deep:mls128,kdtree-gpu-fast:deep:mls128:hw"
  for n in 256 512 1024; do bench r2-nbody$n gen:nbody:$n "$r2,kdtree-gpu:shallow,hybrid${kd1:+,$kd1}"; done
  bench r2-nbody2048 gen:nbody:2048 "$r2,kdtree-gpu:shallow:cold,hybrid:cold${kd1:+,$kd1}"
  bench r2-nbody2048-step1 gen:nbody:2048 "naive,naive:hw,grid:hw,lbvh:hw" --sample-distance 1
fi
if has bench-distance-grid; then
  # DistanceGrid (the grid DDA leaping with a distance field) beside the best builders
  # of bench-nbody-builders, 256^3..2048^3 N-body and the 1024^3 Menger sponge; then one-voxel steps at 2048^3.
  r3="naive:hw,grid,grid:hw,distance-grid,distance-grid:hw,lbvh:hw,kdtree-gpu-fast:deep:mls32:hw"
  r3="$r3,grid:brick16:hw,distance-grid:brick16:hw,distance-grid:brick4:hw"
  for n in 256 512 1024 2048; do bench r3-nbody$n gen:nbody:$n "$r3"; done
  bench r3-menger1024 gen:menger:1024 "$r3"
  bench r3-nbody2048-step1 gen:nbody:2048 "naive:hw,grid:hw,distance-grid:hw,lbvh:hw" --sample-distance 1
fi
if has regcap; then
  # The texture kernels' register cap (SPACESKIP_CUDA_HW_MIN_BLOCKS, default 6 blocks of 256
  # threads = 40 registers) against no cap (1): a second build, the same items at 1024^3/2048^3.
  log "configure + build without the register cap in $build-cap1"
  cmake -S "$src" -B "$build-cap1" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSPACESKIP_ENABLE_CUDA=ON \
    -DSPACESKIP_ENABLE_PARAVIEW=OFF -DCMAKE_CUDA_ARCHITECTURES=90 -DSPACESKIP_CUDA_HW_MIN_BLOCKS=1 \
    -DSPACESKIP_ENABLE_TESTING=OFF > "$work/build-cap1.log" 2>&1 && ninja -C "$build-cap1" spaceskip >> "$work/build-cap1.log" 2>&1
  log "build rc=$?"
  rc_items="naive:hw,grid:hw,distance-grid:hw,lbvh:hw,kdtree-gpu-fast:deep:mls32:hw"
  for n in 1024 2048; do
    bench regcap6-nbody$n gen:nbody:$n "$rc_items"
    cli0=$cli; cli=$build-cap1/Core/spaceskip
    bench regcap1-nbody$n gen:nbody:$n "$rc_items"
    cli=$cli0
  done
fi
if has resident; then
  # Persistent launch (SPACESKIP_CUDA_RESIDENT=N blocks per SM, bench suffix :resN) against the
  # plain launch: bounds the warps in flight (the texture cache's working set) and balances tiles.
  rs="naive:hw,naive:hw:res4,naive:hw:res6,naive:hw:res8,naive:hw:res12,naive:hw:res16"
  rs="$rs,grid:hw,grid:hw:res8,grid:hw:res16,distance-grid:hw,distance-grid:hw:res8,distance-grid:hw:res16"
  rs="$rs,lbvh:hw,lbvh:hw:res8,lbvh:hw:res16"
  rs="$rs,distance-grid:brick4:hw,distance-grid:brick4:hw:res8,distance-grid:brick4:hw:res16"
  for n in 1024 2048; do bench res-nbody$n gen:nbody:$n "$rs"; done
fi
if has bench-launch; then
  # The launch table: the default launch (persistent, 6 blocks/SM, for hardware-filtered
  # textures over 2 GiB) beside the plain one (:res0), DistanceGrid at bricks 8 and 4, and the
  # best builders of bench-nbody-builders; then naive:hw at 2048^3 repeated (plain vs default vs 5/7 blocks/SM).
  f3="naive,naive:hw:res0,naive:hw,grid:hw,distance-grid,distance-grid:hw,distance-grid:brick4,distance-grid:brick4:hw"
  f3="$f3,lbvh:hw,kdtree-gpu-fast:deep:mls32:hw"
  for n in 256 512 1024 2048; do bench f3-nbody$n gen:nbody:$n "$f3"; done
  bench f3-menger1024 gen:menger:1024 "$f3"
  frames0=$frames
  frames=16
  bench f3-nbody2048-naive-repeats gen:nbody:2048 \
    "naive:hw:res0,naive:hw,naive:hw:res0,naive:hw,naive:hw:res5,naive:hw:res7,naive:hw:res0,naive:hw"
  frames=$frames0
fi
if has bench-menger; then
  # The Menger sponge (40.7% occupied): which structure is fastest when little space is empty.
  bench m3-menger1024 gen:menger:1024 \
    "naive:hw,kdtree-gpu-fast:shallow:hw,kdtree-cpu:shallow:hw,grid:hw,grid:brick16:hw,distance-grid:brick16:hw,kdtree-gpu-fast:deep:mls128:hw,kdtree-gpu-fast:deep:mls32:hw,hybrid:hw"
fi
if has profile2048; then
  # Why naive:hw does half the samples/s at 2048^3 that it does at 1024^3: a launch shape sweep
  # on one generated file, then Nsight Compute sections.
  vol=$work/nbody_2048x2048x2048_uint8.raw
  [ -f "$vol" ] || "$cli" generate nbody --dims 2048 2048 2048 -o "$vol" > "$work/generate.log" 2>&1
  for bs in ${PROFILE_BLOCKS:-16x8 8x8 32x4 8x4 32x2 16x16}; do
    SPACESKIP_CUDA_BLOCK=$bs bench "p2048-block$bs" "$vol" "naive:hw,distance-grid:hw"
  done
  sections="--section SpeedOfLight --section MemoryWorkloadAnalysis --section MemoryWorkloadAnalysis_Chart --section Occupancy --section WarpStateStats --section SchedulerStats --section LaunchStats"
  for spec in "naive:$vol" "distance-grid:$vol" "naive:gen:nbody:1024"; do
    b=${spec%%:*}
    v=${spec#*:}
    log "ncu $b $v"
    timeout 240 ncu --kernel-name regex:renderKernel --launch-count 1 $sections \
      "$cli" render "$v" --backend cuda --builder "$b" --filter hardware --size 1024x1024 --camera 30,20 \
      -o "$work/ncu.png" > "$work/ncu-$b-$(basename "$v" | tr ':' '_').log" 2>&1
    log "ncu rc=$?"
    cat "$work/ncu-$b-$(basename "$v" | tr ':' '_').log" >> "$work/ncu.log"
  done
  cp "$work/ncu.log" "$out/ncu.log" 2>/dev/null
  rm -f "$vol"
fi
if has bench-sweep; then
  # "Same parameters, fps within 5%": bins 0 makes KdTreeGPUFast sweep every brick boundary like
  # KdTreeCPU, so each kdtree-cpu item and its kdtree-gpu-fast:...:bins0 twin render the same tree
  # (same nodes/height/leaves in the CSV); their fps must agree. Results go to the usual
  # bench.log/bench.csv/bench.json (no new files in OUTDIR).
  sw="kdtree-cpu:shallow,kdtree-cpu:deep:mls32,kdtree-cpu:deep:mls128"
  sw="$sw,kdtree-gpu-fast:shallow:bins0,kdtree-gpu-fast:deep:mls32:bins0,kdtree-gpu-fast:deep:mls128:bins0"
  sw="$sw,kdtree-cpu:deep:mls32:hw,kdtree-gpu-fast:deep:mls32:bins0:hw"
  for n in 256 512 1024 2048; do bench sweep-nbody$n gen:nbody:$n "$sw"; done
  bench sweep-menger1024 gen:menger:1024 "$sw"
fi
if has blocks; then
  # Launch-shape sweep on one data set (SPACESKIP_CUDA_BLOCK: an override of LaunchParams, which
  # the CLI also takes as --cuda-block WxH), recorded for the notes.
  for bs in 8x8 32x4 16x16 16x8; do
    SPACESKIP_CUDA_BLOCK=$bs bench "block$bs" gen:nbody:1024 "naive,grid,lbvh,kdtree-gpu-fast:deep:mls32,naive:hw,kdtree-gpu-fast:deep:mls32:hw"
  done
fi
if has ncu; then
  log "ncu: DRAM traffic of the render kernel"
  for b in naive kdtree-gpu-fast; do
    timeout 300 ncu --kernel-name regex:renderKernel --launch-count 1 --launch-skip 1 \
      --metrics gpu__time_duration.sum,dram__bytes_read.sum,dram__throughput.avg.pct_of_peak_sustained_elapsed,lts__t_bytes.sum,l1tex__t_bytes.sum \
      "$cli" render gen:nbody:1024 --backend cuda --builder $b --size 1024x1024 -o /tmp/ncu.png > "$work/ncu-$b.log" 2>&1
    log "ncu $b rc=$?"
    cat "$work/ncu-$b.log" >> "$work/bench.log"
  done
fi

if ls "$work"/bench-*.json > /dev/null 2>&1; then
  { echo "["; sep=""; for f in "$work"/bench-*.json; do
      body=$(sed '1d;$d' "$f"); [ -n "$body" ] && { printf '%s%s' "$sep" "$body"; sep=$',\n'; }
    done; echo; echo "]"; } > "$out/bench.json"
fi
cp "$work/run.log" "$out/run.log" 2>/dev/null
tar -C "$work" -czf "$out/logs.tgz" . 2>/dev/null
# Keep the device tool's limit of 8 files: run.log folds into logs.tgz when needed.
[ "$(ls "$out" | wc -l)" -le 8 ] || rm -f "$out/run.log"
log "done, status=$status"
exit $status
