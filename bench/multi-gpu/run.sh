#!/usr/bin/env bash
# The multi-GPU scaling run on a GPU machine (device kinds with 2 or 4 H100s): one MPI rank per
# GPU (spaceskip_mpi_pieces), N-body 2048^3 and a dense stand-in at 1024^2, 1, 2 and 4 ranks
# (as many as the machine has GPUs), frames waited for, compositing included; each multi-rank
# composite checked against the whole volume drawn alone on rank 0's GPU.
#
#   bench/multi-gpu/pack.sh [BUILD_DIR]           (development machine: .vtkbundle-mpi/mpi.tar.xz)
#   bench/multi-gpu/run.sh OUTDIR [SCENES...]     (GPU machine; the device tool carries .vtkbundle-mpi)
# SCENES: shape:dims (default nbody:2048 richtmyer_meshkov:1024). FRAMES (default 60), SIZE
# (default 1024), RANKS (default "1 2 4", cut to the GPU count), BUILDER (default Auto), SLABS=1
# (each rank makes only its slab: volumes larger than one GPU), CHECK=0 (no whole-volume
# reference: it needs the whole volume on rank 0's GPU), COMPOSITES (default "gpu": the images
# composited on the GPUs through CUDA IPC; "host": through host memory with MPI; "gpu host": both,
# one after the other), SPLITS (default "slabs": each rank draws a slab of the volume, the images
# blended; "image": each rank draws a band of the image's rows over the whole volume; "slabs
# image": both), BALANCE (default: slabs of equal visible voxels, bands by the last frame's render
# times; equal: equal cells or rows; SLABS=1 always cuts equal cells), RAY_SEGMENTS (segments a
# ray is cut into on the GPU; default: the engine's choice), RESIDENT (blocks per SM of a
# persistent launch; default: the engine's choice), HEAVIEST_FIRST (0: the blocks start in
# row-major order instead of the last frame's longest first; default: the engine's choice).
# The machine's own mpirun is used when it loads the carried binary's libmpi.so.40 (Open MPI 4.x
# ABI); otherwise the carried Debian Open MPI (orterun, OPAL_PREFIX).
set -u
out=${1:?usage: run.sh OUTDIR [SCENES...]}
shift
scenes=${*:-nbody:2048 richtmyer_meshkov:1024}
src=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out"
work=/tmp/spaceskip-mpi
rm -rf "$work" && mkdir -p "$work"
tar -xJf "$src/.vtkbundle-mpi/mpi.tar.xz" -C "$work"
export LD_LIBRARY_PATH=$work/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
exe=$work/bin/spaceskip_mpi_pieces
{
  date -u
  nvidia-smi --query-gpu=index,name,pci.bus_id,driver_version,memory.total --format=csv
  nvidia-smi topo -m 2>/dev/null | head -8
  echo "mpirun: $(command -v mpirun) $(mpirun --version 2>&1 | head -1)"
} > "$out/env.txt" 2>&1
mpirun=(mpirun)
if ! command -v mpirun > /dev/null || ldd "$exe" | grep -q "libmpi.so.40 => not found"; then
  # The carried Debian Open MPI 4.1.4 (its files under $work/ompi/usr).
  mkdir -p "$work/ompi" && tar -xJf "$work/ompi.tar.xz" -C "$work/ompi"
  export OPAL_PREFIX=$work/ompi/usr
  export LD_LIBRARY_PATH=$work/ompi/usr/lib/x86_64-linux-gnu:$LD_LIBRARY_PATH
  export PATH=$work/ompi/usr/bin:$PATH
  mpirun=("$work/ompi/usr/bin/orterun")
  echo "using the carried Open MPI: ${mpirun[*]}" >> "$out/env.txt"
fi
ldd "$exe" | grep -E "mpi|not found" >> "$out/env.txt"
gpus=$(nvidia-smi -L | wc -l)
frames=${FRAMES:-60}
size=${SIZE:-1024}
builder=${BUILDER:-Auto}
status=0
for scene in $scenes; do
  shape=${scene%%:*} dims=${scene##*:}
  for split in ${SPLITS:-slabs}; do
  for comp in ${COMPOSITES:-gpu}; do
  for n in ${RANKS:-1 2 4}; do
    [ "$n" -le "$gpus" ] || continue
    check=()
    [ "$n" -gt 1 ] && [ "${CHECK:-1}" = 1 ] && check=(--check)
    [ "${SLABS:-0}" = 1 ] && check+=(--slabs)
    [ -n "${BALANCE:-}" ] && check+=(--balance "$BALANCE")
    [ -n "${RAY_SEGMENTS:-}" ] && check+=(--ray-segments "$RAY_SEGMENTS")
    [ -n "${RESIDENT:-}" ] && check+=(--resident "$RESIDENT")
    [ -n "${HEAVIEST_FIRST:-}" ] && check+=(--heaviest-first "$HEAVIEST_FIRST")
    log="$out/$shape$dims-n$n-$split-$comp.log"
    echo "== $shape $dims^3, $n ranks, --split $split --composite $comp" | tee -a "$out/summary.txt"
    # NVLink multicast stays off (the machine's NCCL_NVLS_ENABLE=0 and friends, passed on).
    timeout "${RUN_TIMEOUT:-400}" "${mpirun[@]}" --allow-run-as-root --oversubscribe -n "$n" --bind-to none \
      -x LD_LIBRARY_PATH -x NCCL_NVLS_ENABLE -x TORCH_SYMM_MEM_DISABLE_MULTICAST -x NVSHMEM_DISABLE_NVLS \
      "$exe" --shape "$shape" --dims "$dims" --size "$size" --frames "$frames" --builder "$builder" \
      --backend cuda --composite "$comp" --split "$split" "${check[@]}" --png "$out/$shape$dims-n$n-$split-$comp.png" > "$log" 2>&1
    rc=$?
    [ $rc -eq 0 ] || status=1
    grep -E "^rank|^ranks|^setup|^frame|^tf_edit|^check|GPU compositing not used" "$log" | tee -a "$out/summary.txt"
    echo "rc=$rc" | tee -a "$out/summary.txt"
  done
  done
  done
done
exit $status
