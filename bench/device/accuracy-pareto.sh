#!/usr/bin/env bash
# Speed/accuracy trade per data set (issue 13): `spaceskip accuracy` (sample distance 0.25-4 voxels
# x filter x ERT x jitter vs PSNR/SSIM to a 1/8-voxel reference) on each shape, one CSV per
# backend, then the Pareto plots when matplotlib is there (scripts/plot_pareto.py).
#   bench/device/accuracy-pareto.sh OUTDIR CLI
#   env: SHAPES (default the paper's stand-ins), N (volume edge, 256), SIZE (512x512),
#        BACKENDS ("cuda cpu"), CPU_N (edge for the CPU backend, 128), BUILDER (auto)
set -uo pipefail
out=${1:?usage: accuracy-pareto.sh OUTDIR CLI} cli=${2:?}
mkdir -p "$out"
shapes=${SHAPES:-aneurism xmas_tree magnetic stag_beetle kingsnake menger richtmyer_meshkov nbody}
for be in ${BACKENDS:-cuda cpu}; do
  n=${N:-256}; size=${SIZE:-512x512}
  [ "$be" = cpu ] && n=${CPU_N:-128} && size=${CPU_SIZE:-256x256}
  for s in $shapes; do
    timeout 200 "$cli" accuracy "gen:$s:$n" --backend "$be" --builder "${BUILDER:-auto}" --size "$size" \
      --camera 30,20 --csv "$out/acc-$be-$s.csv" > "$out/acc-$be-$s.log" 2>&1 || echo "$be $s failed" >> "$out/errors.txt"
  done
done
ls "$out"/acc-*.csv > /dev/null 2>&1 && /usr/bin/python3 -c "import matplotlib" 2>/dev/null &&
  /usr/bin/python3 "$(dirname "$0")/../../scripts/plot_pareto.py" "$out/pareto.png" "$out"/acc-*.csv
exit 0
