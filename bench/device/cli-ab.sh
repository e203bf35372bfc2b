#!/usr/bin/env bash
# Kernel fps of two CLI builds side by side on one GPU. A and B are cli.tar.xz bundles
# (bench/device/pack-core.sh) left in /tmp/bundles/A.tar.xz and B.tar.xz by two calls of one
# hold (carry the one bundle, copy it there, carry the other). Per volume and size the runs
# alternate (ORDER), one process each; every run's line and each side's mean are printed.
# A side is a bundle's name, or a bundle and the CLI variables it runs with, after commas
# ("B,SPACESKIP_TRAVERSAL_STEPS=2": bundle B with that variable set); the summary gives each
# side's mean and its ratio to the first side of ORDER.
#
#   bash bench/device/cli-ab.sh OUT "gen:nbody:2048 gen:rm:1024" "1024x1024 724x724"
#   ORDER="A B,SPACESKIP_TRAVERSAL_STEPS=2 B" bash bench/device/cli-ab.sh OUT gen:nbody:2048 1024x1024
#
# env: BACKEND (cuda), BUILDER (distance-grid), FRAMES (60), ORDER ("A B B A")
set -uo pipefail
out=${1:?usage: cli-ab.sh OUT VOLUMES SIZES}
vols=${2:?volumes}
sizes=${3:?sizes}
mkdir -p "$out"
order=${ORDER:-A B B A}
for side in $order; do
  x=${side%%,*}
  [ -x /tmp/ab-$x/bin/spaceskip ] || { mkdir -p /tmp/ab-$x && tar -C /tmp/ab-$x -xJf /tmp/bundles/$x.tar.xz; } || exit 1
done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$out/env.txt"
for v in $vols; do
  for s in $sizes; do
    for side in $order; do
      x=${side%%,*}
      vars=()
      [ "$side" = "$x" ] || IFS=, read -ra vars <<< "${side#*,}"
      csv=$out/$x-${v//[:\/]/_}-$s.csv
      env "${vars[@]}" LD_LIBRARY_PATH=/tmp/ab-$x/lib /tmp/ab-$x/bin/spaceskip bench "$v" --backend "${BACKEND:-cuda}" --builders "${BUILDER:-distance-grid}" \
        --size "$s" --frames "${FRAMES:-60}" --csv "$csv.tmp" > /dev/null 2> "$out/$x.err" || tail -3 "$out/$x.err"
      # the kernel_fps column of the item's row
      awk -F, -v x="$side" -v v="$v" -v s="$s" 'NR == 1 {for (i = 1; i <= NF; ++i) if ($i == "kernel_fps") c = i}
        NR > 1 {print x, v, s, $c}' "$csv.tmp"
      rm -f "$csv.tmp"
    done
  done
done | tee "$out/runs.txt"
awk -v first="${order%% *}" '{k = $2 " " $3; n[k, $1]++; f[k, $1] += $4; keys[k]; sides[$1]} END {
  for (k in keys) {
    line = k
    for (x in sides) if (n[k, x]) line = line sprintf("  %s %.1f (%.3f)", x, f[k, x] / n[k, x], (f[k, x] / n[k, x]) / (f[k, first] / n[k, first]))
    print line
  }
}' "$out/runs.txt" | sort | tee "$out/summary.txt"
