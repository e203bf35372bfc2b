#!/usr/bin/env bash
# On the GPU machine: VisRTX through ANARI against SpaceSkip on the same volumes (issue 39).
#   bash bench/peers/visrtx/run-device.sh OUT VOLUME...
# VOLUME: NAME_XxYxZ_TYPE.raw, or gen:SHAPE:N (written to DATA, default /tmp/visrtx-data, by the carried spaceskip).
# Unpacks .peers/visrtx/visrtx.tar.xz (TARBALL) to /tmp/visrtx and, when carried, the CLI
# (.vtkbundle-cli/cli.tar.xz, or SPACESKIP=path) to /tmp/c. Per volume: anari_bench with the
# default and the fast settings, then spaceskip bench and render on the same raw file with the
# same TF, camera, size and sample distance (and SS_OPTS); the first view of each, VisRTX's and
# ours, compared (PSNR) with a reference: SpaceSkip's Naive at a quarter of the sample distance. Writes OUT/visrtx.csv, OUT/summary.md,
# OUT/*.png, OUT/*.log.
# env: LIBRARY (visrtx; helide: ANARI's CPU device, a smoke test without a GPU), TF (ramp), SIZE (1024x1024), FRAMES (8), EDITS (20), SD (sample distance; default
# half a voxel, both sides), ACCUM (0: extra frames at the first view before saving),
# SS_OPTS (extra spaceskip options, default "--ert 0.99"; e.g. add "--filter hardware")
set -uo pipefail
out=${1:?usage: run-device.sh OUT VOLUME...}
shift
src=$(cd "$(dirname "$0")/../../.." && pwd)
tf=${TF:-ramp} size=${SIZE:-1024x1024} frames=${FRAMES:-8} edits=${EDITS:-20} accum=${ACCUM:-0}
data=${DATA:-/tmp/visrtx-data}
mkdir -p "$out" "$data" /tmp/visrtx
out=$(cd "$out" && pwd)
[ -x /tmp/visrtx/bin/anari_bench ] || tar -C /tmp/visrtx -xJf "${TARBALL:-$src/.peers/visrtx/visrtx.tar.xz}"
export LD_LIBRARY_PATH=/tmp/visrtx/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
ss=${SPACESKIP:-}
if [ -z "$ss" ] && [ -f "$src/.vtkbundle-cli/cli.tar.xz" ]; then
  mkdir -p /tmp/c
  [ -x /tmp/c/bin/spaceskip ] || tar -C /tmp/c -xJf "$src/.vtkbundle-cli/cli.tar.xz"
  ss=/tmp/c/bin/spaceskip
  export LD_LIBRARY_PATH=$LD_LIBRARY_PATH:/tmp/c/lib
fi
ab=/tmp/visrtx/bin/anari_bench
{
  date -u +%Y-%m-%dT%H:%M:%SZ
  nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
  cat /tmp/visrtx/VERSIONS
  echo "spaceskip: ${ss:-none}"
} > "$out/env.txt" 2>&1
$ab --list > "$out/renderers.txt" 2>&1
sdv=${SD:+--sample-distance $SD}
summary=$out/summary.md
echo "# VisRTX (ANARI) vs SpaceSkip: TF $tf, $size, $frames frames, sample distance ${SD:-0.5 voxel}" > "$summary"
for vol in "$@"; do
  raw=$vol
  if [[ $vol == gen:* ]]; then
    IFS=: read -r _ shape n <<< "$vol"
    type=uint8; [ "$shape" = noise ] && type=float32
    raw=$data/${shape}_${n}x${n}x${n}_$type.raw
    [ -f "$raw" ] || "$ss" generate "$shape" --dims "$n" "$n" "$n" -o "$raw" || { echo "cannot generate $vol"; continue; }
  fi
  name=$(basename "$raw" .raw)
  log=$out/$name.log
  : > "$log"
  # logged LIMIT TITLE COMMAND...: the command and its output and exit status in the log.
  logged() { local limit=$1 title=$2; shift 2; echo "== $title$*" >> "$log"; timeout "$limit" "$@" >> "$log" 2>&1; echo "rc=$?" >> "$log"; }
  for s in default fast; do
    logged 600 "" $ab $raw --library ${LIBRARY:-visrtx} --settings $s --tf $tf --size $size --frames $frames --edits $edits $sdv \
      --accumulate $accum -o $out/$name-visrtx-$s.png --csv $out/visrtx.csv
  done
  if [ -n "$ss" ]; then
    common="--backend cuda --tf $tf --size $size $sdv ${SS_OPTS---ert 0.99}"
    logged 900 "" $ss bench $raw --builders naive,auto --frames $frames --edits $edits $common
    logged 600 "" $ss render $raw --camera 0,15 $common -o $out/$name-spaceskip.png
    # Quality at the first view: each image against a reference drawn by SpaceSkip's Naive with
    # exact trilinear sampling at a quarter of the sample distance and no early termination.
    refsd=$(awk -v d="${SD:-0.5}" 'BEGIN {print d / 4}')
    for img in visrtx-default visrtx-fast spaceskip; do
      logged 600 "reference vs $img: " $ss render $raw --camera 0,15 --backend cuda --builder naive --tf $tf \
        --size $size --sample-distance $refsd -o $out/$name-reference.png --compare $out/$name-$img.png
    done
  fi
  { echo; echo "## $name"; echo '```'; grep -v '^\[anari PERF' "$log"; echo '```'; } >> "$summary"
done
# The CSV as a markdown table.
{
  echo
  echo "## anari_bench rows"
  awk -F, 'NR == 1 {h = "|"; s = "|"; for (i = 1; i <= NF; i++) {h = h " " $i " |"; s = s " --- |"}; print h; print s; next}
           {r = "|"; for (i = 1; i <= NF; i++) r = r " " $i " |"; print r}' "$out/visrtx.csv"
} >> "$summary"
echo "wrote $summary"
