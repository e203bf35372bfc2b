#!/usr/bin/env bash
# Before/after benchmark of the main builders on the GPU machine: two CLI builds of SpaceSkip
# (e.g. the commit before a refactor and the one after) run the same cases alternately
# (A B A B ... so clock and thermal drift hit both alike) and the ratio after/before of the kernel
# fps and of the build time is printed per case.
#
#   bench/device/builders-ab.sh OUTDIR BEFORE_CLI AFTER_CLI
#   env: ROUNDS (3), FRAMES (16), VOLUMES ("gen:nbody:1024 gen:menger:1024"), BUILDERS (below),
#        EXTRA (more bench options, e.g. "--build-reps 20": the fastest of 20 rebuilds),
#        TBB_DIR/LD_LIBRARY_PATH as for run-core.sh (set from ./.deps when present)
# Writes OUTDIR/compare.csv (every run), OUTDIR/compare.txt (medians and ratios), OUTDIR/env.txt.
set -uo pipefail
out=${1:?usage: builders-ab.sh OUTDIR BEFORE_CLI AFTER_CLI}
before=${2:?} after=${3:?}
src=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out"
for d in "$src/.deps/tbb" "$src/../.deps/tbb"; do
  if [ -d "$d" ]; then
    export LD_LIBRARY_PATH=$(cd "$d" && pwd)/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
    break
  fi
done
rounds=${ROUNDS:-3}
frames=${FRAMES:-16}
volumes=${VOLUMES:-gen:nbody:1024 gen:menger:1024}
builders=${BUILDERS:-naive,grid,distance-grid,lbvh,kdtree-gpu-fast:deep:mls128,kdtree-gpu:deep:mls32,kdtree-cpu:deep:mls32,hybrid}
{
  echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader 2>&1
  echo "before: $before ($(sha256sum "$before" | cut -c1-12))"
  echo "after:  $after ($(sha256sum "$after" | cut -c1-12))"
  echo "rounds: $rounds frames: $frames volumes: $volumes"
  echo "builders: $builders"
  echo "extra: ${EXTRA:-}"
} > "$out/env.txt"
echo "which,round,dataset,variant,kernel_fps,build_s" > "$out/compare.csv"
for vol in $volumes; do
  for r in $(seq 1 "$rounds"); do
    for which in before after; do
      cli=$before
      [ $which = after ] && cli=$after
      tmp=$(mktemp)
      "$cli" bench "$vol" --backend cuda --builders "$builders" --size 1024x1024 --frames "$frames" --csv "$tmp" ${EXTRA:-} \
        > "$out/log-$which.txt" 2>&1 || echo "$which $vol round $r failed: $(tail -3 "$out/log-$which.txt")" >> "$out/env.txt"
      # columns: dataset(1) variant(3) build_s(10) kernel_fps(18)
      awk -F, -v w=$which -v r=$r 'NR > 1 { print w "," r "," $1 "," $3 "," $18 "," $10 }' "$tmp" >> "$out/compare.csv"
      rm -f "$tmp"
    done
  done
done
# Median over rounds per (dataset, variant, which); ratio after/before.
awk -F, 'NR > 1 { k = $3 " " $4; key[k] = 1; n[k "|" $1]++; f[k "|" $1 "|" n[k "|" $1]] = $5; b[k "|" $1 "|" n[k "|" $1]] = $6 }
function med(arr, pfx, cnt,   i, j, t, v) {
  for (i = 1; i <= cnt; i++) v[i] = arr[pfx "|" i]
  for (i = 1; i <= cnt; i++) for (j = i + 1; j <= cnt; j++) if (v[j] < v[i]) { t = v[i]; v[i] = v[j]; v[j] = t }
  return v[int((cnt + 1) / 2)]
}
END {
  printf "%-34s %-30s %12s %12s %8s %12s %12s %8s\n", "dataset", "variant", "kfps_before", "kfps_after", "ratio", "build_ms_bef", "build_ms_aft", "ratio"
  for (k in key) {
    split(k, p, " ")
    fb = med(f, k "|before", n[k "|before"]); fa = med(f, k "|after", n[k "|after"])
    bb = med(b, k "|before", n[k "|before"]); ba = med(b, k "|after", n[k "|after"])
    printf "%-34s %-30s %12.1f %12.1f %8.3f %12.3f %12.3f %8.3f\n", p[1], p[2], fb, fa, fa / fb, 1e3 * bb, 1e3 * ba, (bb > 0 ? ba / bb : 0)
  }
}' "$out/compare.csv" | sort > "$out/compare.txt"
cat "$out/env.txt" "$out/compare.txt"
