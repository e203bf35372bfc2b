#!/usr/bin/env bash
# CLI builds side by side on one GPU: kernel fps (and any other column of the bench's CSV) of two
# or more bundles, alternated one process per run so that clock and thermal drift hit every side
# alike. The bundles are cli.tar.xz files (bench/device/pack-core.sh) left in
# /tmp/bundles/NAME.tar.xz by the calls of one hold (carry one bundle, copy it there, carry the
# next). Per volume and size the runs follow ORDER; every run's line and, per data set, item, size
# and column, each side's mean and its ratio to the first side of ORDER are printed.
# A side is a bundle's name, or a bundle and the CLI variables it runs with, after commas
# ("B,SPACESKIP_TRAVERSAL_STEPS=2": bundle B with that variable set).
# A volume is one the CLI reads (gen:nbody:2048, a file) or paper:NAME[,NAME...]: stand-ins of the
# paper's data sets on its protocol (bench --paper --datasets NAME..., always 1024x1024).
# OUT gets env.txt, runs.txt, summary.txt and last.err (the last run's stderr): four files, so
# that two OUTs come back within the device tool's eight.
#
#   bash bench/device/cli-ab.sh OUT "gen:nbody:2048 gen:rm:1024" "1024x1024 724x724"
#   ORDER="A B,SPACESKIP_TRAVERSAL_STEPS=2 B" bash bench/device/cli-ab.sh OUT gen:nbody:2048 1024x1024
#   BUILDER=naive,grid,lbvh COLUMNS="kernel_fps build_s" ORDER="A B A B A B" \
#     bash bench/device/cli-ab.sh OUT "gen:nbody:1024 paper:menger_sponge" 1024x1024
#
# env: BACKEND (cuda), BUILDER (distance-grid; a comma list: a line per item), COLUMNS
#      (kernel_fps), FRAMES (60), ORDER ("A B B A"), EXTRA (more bench options), CLI_TIMEOUT (600 s)
set -uo pipefail
out=${1:?usage: cli-ab.sh OUT VOLUMES SIZES}
vols=${2:?volumes}
sizes=${3:?sizes}
mkdir -p "$out"
order=${ORDER:-A B B A}
columns=${COLUMNS:-kernel_fps}
for side in $order; do
  x=${side%%,*}
  [ -x /tmp/ab-$x/bin/spaceskip ] || { mkdir -p /tmp/ab-$x && tar -C /tmp/ab-$x -xJf /tmp/bundles/$x.tar.xz; } || exit 1
done
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>&1; echo "order: $order"; echo "builder: ${BUILDER:-distance-grid} frames: ${FRAMES:-60} extra: ${EXTRA:-}"; } | tee "$out/env.txt"
for v in $vols; do
  vsizes=$sizes
  [ "${v#paper:}" = "$v" ] || vsizes=1024x1024
  for s in $vsizes; do
    for side in $order; do
      x=${side%%,*}
      vars=()
      [ "$side" = "$x" ] || IFS=, read -ra vars <<< "${side#*,}"
      if [ "${v#paper:}" != "$v" ]; then
        args=(--paper --datasets "${v#paper:}")
      else
        args=("$v" --size "$s")
      fi
      csv=$out/$x-${v//[:\/,]/_}-$s.csv
      env "${vars[@]}" LD_LIBRARY_PATH=/tmp/ab-$x/lib timeout "${CLI_TIMEOUT:-600}" /tmp/ab-$x/bin/spaceskip bench "${args[@]}" \
        --backend "${BACKEND:-cuda}" --builders "${BUILDER:-distance-grid}" --frames "${FRAMES:-60}" ${EXTRA:-} \
        --csv "$csv.tmp" > /dev/null 2> "$out/last.err" || { echo "$side $v $s failed:" >&2; tail -3 "$out/last.err" >&2; }
      # per row of the CSV: side, data set, item, size, then each asked column's name and value
      [ -s "$csv.tmp" ] && awk -F, -v x="$side" -v s="$s" -v cols="$columns" 'NR == 1 {
          for (i = 1; i <= NF; ++i) at[$i] = i
          n = split(cols, want, " ")
          for (j = 1; j <= n; ++j) if (!(want[j] in at)) { print "no column " want[j] > "/dev/stderr"; exit 1 }
        }
        NR > 1 {for (j = 1; j <= n; ++j) print x, $at["dataset"], $at["variant"], s, want[j], $at[want[j]]}' "$csv.tmp"
      rm -f "$csv.tmp"
    done
  done
done | tee "$out/runs.txt"
awk -v order="$order" 'BEGIN {m = split(order, o, " "); first = o[1]}
  {k = $2 " " $3 " " $4 " " $5; n[k, $1]++; f[k, $1] += $6; keys[k]} END {
  for (k in keys) {
    line = k
    for (i = 1; i <= m; ++i) {
      x = o[i]
      if (done[k, x]++ || !n[k, x] || !n[k, first] || f[k, first] == 0) continue
      line = line sprintf("  %s %.6g (%.3f)", x, f[k, x] / n[k, x], (f[k, x] / n[k, x]) / (f[k, first] / n[k, first]))
    }
    print line
  }
}' "$out/runs.txt" | sort | tee "$out/summary.txt"
