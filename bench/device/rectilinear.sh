#!/usr/bin/env bash
# On the GPU machine: rectilinear grids drawn through their coordinates (Core's AxisWarp), with the
# CLI (bench/device/pack-core.sh's cli.tar.xz unpacked; CLI=path of its wrapper):
#   - each volume as the image it is and as a rectilinear grid of the same points (--rectilinear:
#     x steps growing 1:3, z steps varying ~1:2), the same builders, alternated twice: what sampling
#     through the coordinates costs;
#   - with CLI_OLD (an earlier CLI), the image and the grid with the old and the new CLI
#     alternated: what a change to the samplers costs (new/old for each).
# Usage: CLI=... [CLI_OLD=...] [RECT_CASES="gen:nbody:1024 gen:rm:512"] [RECT_BUILDERS=...]
#        bash bench/device/rectilinear.sh OUTDIR
set -euo pipefail
out=${1:?OUTDIR}
mkdir -p "$out"
cases=${RECT_CASES:-"gen:nbody:1024 gen:rm:512"}
builders=${RECT_BUILDERS:-naive,grid,distance-grid,kdtree-gpu-fast}
common=(--backend cuda --builders "$builders" --frames 40 --size 1024x1024)
run() {  # TAG CLI ARGS...
  local tag=$1 cli=$2
  shift 2
  "$cli" bench "$@" "${common[@]}" --csv "$out/$tag.csv" > "$out/$tag.txt" 2>&1 || echo "FAILED: $tag" >> "$out/summary.txt"
}
for spec in $cases; do
  name=${spec//:/_}
  for rep in 1 2; do
    run "${name}_image_$rep" "$CLI" "$spec"
    run "${name}_rect_$rep" "$CLI" "$spec" --rectilinear
    if [ -n "${CLI_OLD:-}" ]; then
      run "${name}_old_$rep" "$CLI_OLD" "$spec"
      run "${name}_oldrect_$rep" "$CLI_OLD" "$spec" --rectilinear
    fi
  done
done
# One line per case and builder: fps of each run (the CSV's fps column).
python3 - "$out" <<'EOF' >> "$out/summary.txt"
import csv, glob, os, sys
out = sys.argv[1]
rows = {}
for f in sorted(glob.glob(os.path.join(out, "*.csv"))):
    tag = os.path.basename(f)[:-4]
    for r in csv.DictReader(open(f)):
        case, kind, rep = tag.rsplit("_", 2)
        rows.setdefault((case, r["builder"]), {}).setdefault(kind, []).append(float(r["fps"]))
print("case builder | image fps | rectilinear fps | rect/image | old image fps | new/old | old rect fps | new/old rect")
for (case, b), k in sorted(rows.items()):
    med = lambda xs: sorted(xs)[len(xs) // 2] if xs else float("nan")
    img, rect, old = med(k.get("image", [])), med(k.get("rect", [])), med(k.get("old", []))
    oldr = med(k.get("oldrect", []))
    nan = float("nan")
    print("%s %s | %.1f | %.1f | %.3f | %.1f | %.3f | %.1f | %.3f" % (case, b, img, rect, rect / img, old,
          img / old if old else nan, oldr, rect / oldr if oldr else nan))
EOF
cat "$out/summary.txt"
