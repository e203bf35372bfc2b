#!/usr/bin/env bash
# Kernel fps of two source trees side by side on the GPU machine, from source: OLD is a
# `git archive` tarball carried in .gpu-src/old.tar (e.g. the previous release's Core), NEW is
# .gpu-src/new.tar when carried (a commit, whatever the working tree holds), else this tree. Both are built here (Core and the CLI only, CUDA for sm_90, oneTBB from
# .deps/tbb: ../shared/device/prepare-deps.sh), then `spaceskip bench --paper` runs alternately
# (one process per run, RUNS order) and the medians per data set and item are compared.
#
#   On the CPU machine:  mkdir -p .gpu-src && git archive -o .gpu-src/old.tar <old-commit> CMakeLists.txt Core
#                        [git archive -o .gpu-src/new.tar <new-commit> CMakeLists.txt Core Testing Data]
#   On the GPU machine:  bench/device/kernel-ab.sh OUTDIR [build] [tests] [runs]   (carry .deps, .gpu-src)
#
# env: DATASETS (nbody_2048,menger_sponge,richtmyer_meshkov), ITEMS (naive,distance-grid:hw,auto),
#      FRAMES (8), RUNS ("old new new old"), JOBS (16), BUILD_ROOT (/tmp/ss-ab: outside the work
#      tree, kept while the machine is held)
set -uo pipefail
out=${1:?usage: kernel-ab.sh OUTDIR [build] [tests] [runs]}
shift
phases=" ${*:-build tests runs} "
has() { [[ "$phases" == *" $1 "* ]]; }
src=$(cd "$(dirname "$0")/../.." && pwd)
root=${BUILD_ROOT:-/tmp/ss-ab}
mkdir -p "$out" "$root"
out=$(cd "$out" && pwd)
log() { echo "$(date -u +%H:%M:%S) $*" | tee -a "$out/env.txt"; }
export TBB_DIR=$src/.deps/tbb/usr/lib/x86_64-linux-gnu/cmake/TBB
export LD_LIBRARY_PATH=$src/.deps/tbb/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
{
  date -u +%Y-%m-%dT%H:%M:%SZ
  nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv
  nvcc --version | tail -2
} >> "$out/env.txt" 2>&1

build() {  # build TREE SOURCE_DIR TESTING(ON|OFF) TARGETS...
  local tree=$1 dir=$2 testing=$3
  shift 3
  cmake -S "$dir" -B "$root/build-$tree" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSPACESKIP_ENABLE_PARAVIEW=OFF \
    -DSPACESKIP_ENABLE_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES=90 -DSPACESKIP_ENABLE_TESTING="$testing" \
    > "$out/configure-$tree.log" 2>&1 &&
    cmake --build "$root/build-$tree" -j "${JOBS:-16}" --target "$@" > "$out/build-$tree.log" 2>&1
  log "build $tree rc=$?"
  tail -3 "$out/build-$tree.log"
}

if has build; then
  rm -rf "$root/old-src" && mkdir -p "$root/old-src"
  tar xf "$src/.gpu-src/old.tar" -C "$root/old-src" || { log "no .gpu-src/old.tar"; exit 1; }
  newsrc=$src
  if [ -f "$src/.gpu-src/new.tar" ]; then
    rm -rf "$root/new-src" && mkdir -p "$root/new-src" && tar xf "$src/.gpu-src/new.tar" -C "$root/new-src"
    newsrc=$root/new-src
  fi
  build old "$root/old-src" OFF spaceskip &
  build new "$newsrc" ON spaceskip spaceskip_core_tests &
  wait
fi
if has tests; then
  timeout 300 "$root/build-new/Testing/spaceskip_core_tests" --gtest_brief=1 > "$out/core-tests.log" 2>&1
  log "new Core tests rc=$?"
  tail -4 "$out/core-tests.log"
fi
if has runs; then
  n=0
  for tree in ${RUNS:-old new new old}; do
    n=$((n + 1))
    bin=$root/build-$tree/Core/spaceskip
    [ -x "$bin" ] || { log "$bin missing"; continue; }
    timeout 280 "$bin" bench --paper --datasets "${DATASETS:-nbody_2048,menger_sponge,richtmyer_meshkov}" \
      --builders "${ITEMS:-naive,distance-grid:hw,auto}" --frames "${FRAMES:-8}" \
      --csv "$out/$tree-$n.csv" > "$out/$tree-$n.log" 2>&1
    log "run $n ($tree) rc=$?"
  done
  # Medians of kernel fps per data set and item, new/old.
  python3 - "$out" <<'EOF' | tee "$out/summary.txt"
import csv, glob, os, statistics, sys
out = sys.argv[1]
fps = {}
for path in sorted(glob.glob(os.path.join(out, "*-*.csv"))):
    tree = os.path.basename(path).split("-")[0]
    with open(path) as f:
        for row in csv.DictReader(f):
            try:
                v = float(row["kernel_fps"])
            except (KeyError, ValueError):
                continue
            item = row["item"].split("->")[0]
            fps.setdefault((row["dataset"], item), {}).setdefault(tree, []).append(v)
print("%-20s %-18s %12s %12s %8s" % ("dataset", "item", "old fps", "new fps", "new/old"))
for (ds, item), t in sorted(fps.items()):
    o = statistics.median(t["old"]) if t.get("old") else float("nan")
    n = statistics.median(t["new"]) if t.get("new") else float("nan")
    print("%-20s %-18s %12.1f %12.1f %8.3f" % (ds, item, o, n, n / o if o == o and o > 0 else float("nan")))
EOF
fi
