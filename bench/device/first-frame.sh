#!/usr/bin/env bash
# On the GPU machine: the first frame (from the voxels in host memory: upload, brick ranges,
# classification, build, the frame read back; `spaceskip render` prints it) of the peer
# benchmark's scenes at 1024x1024, with Builder Auto, DistanceGrid and Naive, the carried CLI
# (.vtkbundle-cli/cli.tar.xz, made by bench/device/pack-core.sh).
#   bash bench/device/first-frame.sh OUT
set -uo pipefail
out=${1:?usage: first-frame.sh OUT}
src=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out" /tmp/c
[ -x /tmp/c/bin/spaceskip ] || tar -C /tmp/c -xJf "$src/.vtkbundle-cli/cli.tar.xz"
export LD_LIBRARY_PATH=/tmp/c/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > "$out/env.txt" 2>&1
for v in nbody:2048 nbody:1024 menger:1024 rm:1024 vessels:1024; do
  for b in auto distance-grid naive; do
    echo "== spaceskip render gen:$v --backend cuda --builder $b --size 1024x1024 --camera 0,15 --ert 0.99" >> "$out/first-frame.log"
    timeout 120 /tmp/c/bin/spaceskip render gen:$v --backend cuda --builder $b --size 1024x1024 --camera 0,15 \
      --ert 0.99 -o /tmp/first-frame.png >> "$out/first-frame.log" 2>&1
    echo "rc=$?" >> "$out/first-frame.log"
  done
done
