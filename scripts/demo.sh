#!/usr/bin/env bash
# The main job: set up, build, render a bundled/generated data set and print build/render timings.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/setup-debian.sh"
bash "$root/scripts/build.sh"
cli="$root/build/Core/spaceskip"
out=${DEMO_OUT:-$root/build/demo}
mkdir -p "$out"
echo "== render the bundled MNI152 brain (real MRI data) with grid skipping"
"$cli" render "$root/Data/mni152_t1_99x117x95_uint8.raw" --builder grid --tf ramp --camera 60,10 --size 512x512 -o "$out/mni152.png"
echo "== render a 256^3 Menger sponge (paper's data set shape), naive vs grid skipping"
"$cli" render gen:menger:256 --builder naive --size 512x512 -o "$out/menger_naive.png"
"$cli" render gen:menger:256 --builder grid --size 512x512 -o "$out/menger_grid.png" --compare "$out/menger_naive.png"
echo "== benchmark (paper protocol at 512x512 on the CPU backend: orthographic, rotating camera, no ERT)"
"$cli" bench gen:menger:256 gen:nbody:256 --builders naive,grid,distance-grid,auto --size 512x512 --frames 4 --json "$out/bench.json"
plugin="$root/build/lib/paraview-5.11/plugins/SpaceSkip/SpaceSkip.so"
if [ -f "$plugin" ]; then
  echo "== ParaView: pvbatch loads the SpaceSkip plugin and renders the MNI152 brain per builder"
  source "$root/scripts/xvfb.sh" 92
  timeout 600 pvbatch "$root/scripts/demo_pvbatch.py" "$plugin" "$root/Data" "$out"
fi
echo "images and bench.json in $out"
