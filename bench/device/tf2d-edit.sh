#!/usr/bin/env bash
# On the GPU machine: opacity edit -> first frame with a 1-D and with a 2-D transfer function
# (value x gradient magnitude, the CLI's --tf2d) on N-body 2048^3 at 1024x1024, CUDA, the carried
# CLI (.vtkbundle-cli/cli.tar.xz, made by bench/device/pack-core.sh): each edit timed from
# setTransferFunction() to its frame finished on the device, as the mapper's interop path.
#   bash bench/device/tf2d-edit.sh OUT [N]      (N: the N-body size, default 2048)
set -uo pipefail
out=${1:?usage: tf2d-edit.sh OUT [N]}
n=${2:-2048}
src=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out" /tmp/c
[ -x /tmp/c/bin/spaceskip ] || tar -C /tmp/c -xJf "$src/.vtkbundle-cli/cli.tar.xz"
export LD_LIBRARY_PATH=/tmp/c/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
{
  date -u +%Y-%m-%dT%H:%M:%SZ
  nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
} > "$out/env.txt" 2>&1
for tf in "" "--tf2d 64"; do
  cmd="/tmp/c/bin/spaceskip bench gen:nbody:$n --backend cuda --builders auto,grid --size 1024x1024 --frames 8 --edits 20 $tf"
  echo "== $cmd" >> "$out/tf2d-edit.log"
  timeout 240 $cmd >> "$out/tf2d-edit.log" 2>&1
  echo "rc=$?" >> "$out/tf2d-edit.log"
done
