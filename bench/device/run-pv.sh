#!/usr/bin/env bash
# On a GPU machine without ParaView, X or GL loaders: ParaView's own engine (pvbatch, pvpython) with
# the SpaceSkip plugin built with CUDA, from the parts of bench/device/bundle-pv.sh and the X part
# of bundle-vtk.sh (all parked in BUNDLE beforehand, one device call per part). Starts the bundled
# Xvfb, picks NVIDIA's GLX (REQUIRE_NVIDIA_GL: stop if only Mesa works), then runs the phases:
#   probe        ParaView's version, GL_RENDERER, the backend ours used (pv-probe.py)
#   tests        the plugin's pvpython tests (Testing/Plugin/test_*.py; PV_TESTS to choose), each
#                with the environment ctest gives it, ours on CUDA (TEST_BACKEND), the stock Volume
#                on NVIDIA's GL
#   parallel     test_parallel.py: N pvbatch ranks (mpirun) against serial pvbatch, on this GPU
#                (PARALLEL_ARGS, default "--imagereader Grid 2")
#   bench-stock  bench/cpu-vs-stock.py --backend CUDA: ours vs the stock Volume in one process
#                (STOCK_CASES "source:dims ...", default "sparse:512 wavelet:512"; STOCK_VIEW 1024)
#   bench-pvbatch  bench/pvbatch-orbit.py: pvbatch on 1 rank and mpirun -n N pvbatch (PVB_RANKS,
#                default "1 2"; each rank picks the GPU of its node-local rank) on a generated
#                volume (PVB_SHAPE nbody, PVB_N 2048: spaceskip generate, kept in PVB_DIR, default
#                /tmp/pvb), PVB_FRAMES 60 at 1024^2, each N-rank first frame against the 1-rank one;
#                PVB_STOCK=1: ParaView's Volume too (PVB_BACKEND CUDA, PVB_VIEW 1024)
#                PVB_SMP: VTK's SMP backend for ParaView's own passes (default STDThread);
#                PVB_VERBOSITY 5: each composited frame's phases in logs/pvbatch-N.log;
#                PVB_ARGS: more options of pvbatch-orbit.py (e.g. --shade);
#                PVB_HOST_AB=1: each run of ours again with --host-composite (A/B in one hold)
#                PVB_LOG=1: ParaView's rendering log (PARAVIEW_LOG_RENDERING_VERBOSITY=INFO) in
#                logs/pvbatch-N.log, summed up per rank by bench/pv-frame-phases.py (IceT's pass
#                against the rest of ParaView's frame)
#   bench-ts     bench/time-series-vs-stock.py --backend CUDA (TS_DIMS 512, TS_STEPS 10, TS_ROUNDS 2,
#                --raw; TS_WORKDIR keeps the written steps for a later run; TS_ARGS more options,
#                e.g. "--cache 4000" for ParaView's animation cache)
#
#   bench/device/run-pv.sh OUTDIR [PHASE...]     (default: probe tests parallel bench-stock bench-ts)
#   env: BUNDLE (default /tmp/bun), DEADLINE (epoch seconds: later phases are skipped),
#        PLUGIN_LIBS (a folder of libraries to load before the bundle's)
#        PLUGIN_DIR (a folder with a newer SpaceSkip.so and libvtkSpaceSkipRepresentation.so: the
#        plugin's XML and representation without repacking the bundle; also put first in the
#        library path)
# OUTDIR receives env.txt, pv.log (everything printed) and logs.tgz (each test's output).
set -uo pipefail
out=${1:?usage: run-pv.sh OUTDIR [PHASE...]}
shift
phases=${*:-probe tests parallel bench-stock bench-ts}  # bench-pvbatch on request
src=$(cd "$(dirname "$0")/../.." && pwd)
bundle=${BUNDLE:-/tmp/bun}
mkdir -p "$out"
out=$(cd "$out" && pwd)
work=$(mktemp -d)
status=0
has() { case " $phases " in *" $1 "*) return 0 ;; *) return 1 ;; esac; }
log() { echo "[$(date -u +%H:%M:%S)] $*" | tee -a "$out/pv.log"; }
late() { [ -n "${DEADLINE:-}" ] && [ "$(date +%s)" -ge "$DEADLINE" ]; }

# --- unpack: the parts of pv.tar.xz, checked against the first part's checksum; the X part ------
B=$work/bundle
mkdir -p "$B"
cat "$bundle"/pv.tar.xz.[0-9] > "$work/pv.tar.xz"
(cd "$work" && sha256sum -c "$bundle/pv.tar.xz.sha256") >> "$out/pv.log" 2>&1 ||
  { log "the parts in $bundle do not make pv.tar.xz (missing or stale part)"; exit 1; }
xz -dc "$work/pv.tar.xz" | tar -C "$B" -xf - && rm "$work/pv.tar.xz"
xz -dc "$bundle/x.tar.xz" | tar -C "$B" -xf - || { log "cannot unpack $bundle/x.tar.xz"; exit 1; }
P=$B/pv
log "bundle unpacked ($(head -1 "$P/COMMIT"))"
{
  echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  echo "host: $(hostname)  phases: $phases"
  nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv 2>&1
  echo "bundle built from: $(cat "$P/COMMIT")"
  # The device copy carries the working tree's files; its git HEAD can be an older commit.
  echo "git HEAD of the copied tree (may predate its files): $(cd "$src" && git rev-parse HEAD 2>/dev/null || echo none)"
  echo "cores: $(nproc)  os: $(. /etc/os-release 2>/dev/null; echo "$PRETTY_NAME")"
} > "$out/env.txt"

. "$src/bench/device/x-gl.sh"
start_xvfb
# Open MPI: the machine's own 4.x when it has one (its mpirun finds its own components), else the
# carried Debian one.
mpilib=
if ldconfig -p | grep -q "libmpi\.so\.40 "; then
  echo "Open MPI: the machine's ($(mpirun --version 2>&1 | head -1)); $(env | grep -E '^(OMPI_MCA|PMIX_MCA)' | tr '\n' ' ')" >> "$out/env.txt"
else
  mpilib=$P/lib-mpi
  echo "Open MPI: no libmpi.so.40 here: the carried libraries (no mpirun: the parallel phase and several pvbatch ranks skipped)" >> "$out/env.txt"
fi
# PLUGIN_LIBS: a folder of libraries loaded before the bundle's (e.g. a newer libvtkSpaceSkip.so:
# an A/B of a VTK-module change without repacking the bundle).
PLUGIN_LIBS=${PLUGIN_LIBS:-${PLUGIN_DIR:+$(cd "$PLUGIN_DIR" && pwd)}}
export LD_LIBRARY_PATH=${PLUGIN_LIBS:+$PLUGIN_LIBS:}$P/lib${mpilib:+:$mpilib}:$B/x/lib${nvdir:+:$nvdir}${sys_ldpath:+:$sys_ldpath}
export __GLX_VENDOR_LIBRARY_NAME=nvidia
export PYTHONHOME=$P/python PYTHONPATH=$P/python/dist-packages:$src/Testing/Plugin
# The plugin's tests ask for the CPU backend (CI has no GPU): here CUDA (TEST_BACKEND) instead.
export SPACESKIP_TEST_BACKEND=${TEST_BACKEND:-CUDA}
plugin_so=${PLUGIN_DIR:+$(cd "$PLUGIN_DIR" && pwd)/SpaceSkip.so}
export SPACESKIP_PLUGIN=${plugin_so:-$P/plugin/SpaceSkip.so} SPACESKIP_DATA=$src/Data \
  SPACESKIP_BASELINES=$src/Testing/Plugin/Baseline SPACESKIP_TEMP=$work/tmp
mkdir -p "$SPACESKIP_TEMP" "$work/logs"
pvbatch=$P/bin/pvbatch
pvpython=$P/bin/pvpython

probe() { timeout 120 "$pvbatch" --no-mpi "$src/bench/device/pv-probe.py" "$SPACESKIP_PLUGIN" > "$work/logs/probe.log" 2>&1; }
probe
cat "$work/logs/probe.log" >> "$out/pv.log"
if ! grep -q "GL_RENDERER.*NVIDIA" "$work/logs/probe.log"; then
  log "NVIDIA GL not used by pvbatch (see probe.log)"
  if [ -n "${REQUIRE_NVIDIA_GL:-}" ]; then
    stop_xvfb
    tar -C "$work" -czf "$out/logs.tgz" logs xvfb.log 2>/dev/null
    exit 3
  fi
  # The bundled Mesa (llvmpipe) instead, and say so.
  unset __GLX_VENDOR_LIBRARY_NAME
  export LIBGL_DRIVERS_PATH=$B/x/lib/dri
  probe
  cat "$work/logs/probe.log" >> "$out/pv.log"
  echo "FALLBACK: Mesa (NVIDIA's GLX did not work)" >> "$out/env.txt"
fi
{ grep -E "GL_RENDERER|ParaView|backend" "$work/logs/probe.log"; } >> "$out/env.txt"

run() {  # NAME TIMEOUT COMMAND...: logged under logs/NAME.log, its last lines and status in pv.log
  local name=$1 limit=$2 rc
  shift 2
  if late; then log "$name: skipped (DEADLINE)"; return; fi
  log "$name: $*"
  local t0=$SECONDS
  (cd "$work" && timeout "$limit" "$@") > "$work/logs/$name.log" 2>&1
  rc=$?
  [ $rc = 0 ] || status=1
  tail -n "${TAIL:-6}" "$work/logs/$name.log" | sed 's/^/    /' >> "$out/pv.log"
  log "$name: rc $rc, $((SECONDS - t0)) s"
}

if has tests; then
  for t in ${PV_TESTS:-plugin_load render properties tf_edits stock_cropping stock_components \
      stock_slice_lights stock_transfer2d stock_scattering stock_rectilinear modes partitioned labelmap \
      time_series hostile_properties}; do
    run "test_$t" 600 "$pvpython" "$src/Testing/Plugin/test_$t.py"
  done
fi
if has parallel && [ -z "$mpilib" ]; then
  # shellcheck disable=SC2086
  run parallel 600 "$pvpython" "$src/Testing/Plugin/test_parallel.py" \
    "$(command -v mpirun)" "$pvbatch" ${PARALLEL_ARGS:---imagereader Grid 2}
fi
if has bench-stock; then
  for c in ${STOCK_CASES:-sparse:512 wavelet:512}; do
    TAIL=4 run "stock-${c/:/-}" 600 "$pvpython" "$src/bench/cpu-vs-stock.py" --plugin "$SPACESKIP_PLUGIN" \
      --backend CUDA --source "${c%%:*}" --dims "${c##*:}" --view "${STOCK_VIEW:-1024}" --frames 20
  done
fi
if has bench-pvbatch; then
  # ParaView's data information (the array's range, for every representation alike) runs through
  # VTK's SMP tools, sequential unless told otherwise: at 512^3 it took 7.0 s against 0.78 s with
  # STDThread, and a whole 1-rank pvbatch run at 2048^3 took 424 s without it (2026-11-29).
  # PVB_SMP (default STDThread) sets VTK_SMP_BACKEND_IN_USE for the pvbatch runs.
  export VTK_SMP_BACKEND_IN_USE=${PVB_SMP:-STDThread}
  n=${PVB_N:-2048}
  shape=${PVB_SHAPE:-nbody}
  mkdir -p "${PVB_DIR:-/tmp/pvb}"
  raw=${PVB_DIR:-/tmp/pvb}/${shape}_${n}x${n}x${n}_uint8.raw
  [ -f "$raw" ] || run "generate-$shape-$n" 600 "$P/bin/spaceskip" generate "$shape" --dims "$n" "$n" "$n" -o "$raw"
  for stock in "" ${PVB_STOCK:+--stock}; do
    for r in ${PVB_RANKS:-1 2}; do
     # PVB_HOST_AB=1: ours also with Keep Image On GPU off (frames and pieces through host memory).
     for comp in "" ${PVB_HOST_AB:+--host-composite}; do
      [ -z "$comp" ] || [ -z "$stock" ] || continue
      # Several ranks need the machine's mpirun (as the parallel phase does).
      [ "$r" = 1 ] || [ -z "$mpilib" ] || { log "pvbatch-$r: skipped (no mpirun here)"; continue; }
      tag=pvbatch-$r${stock:+-stock}${comp:+-host}
      launch=("$pvbatch")
      [ "$r" = 1 ] || launch=(mpirun --allow-run-as-root --oversubscribe --bind-to none -n "$r" "$pvbatch")
      # PVB_VERBOSITY 5: the mapper logs each composited frame's phases (logs/pvbatch-N.log).
      [ -z "${PVB_VERBOSITY:-}" ] || launch+=(-v "$PVB_VERBOSITY")
      ref=()
      [ "$r" = 1 ] || ref=(--reference "$work/logs/pvbatch-1${stock:+-stock}.png")
      [ -z "${PVB_LOG:-}" ] || launch=(env PARAVIEW_LOG_RENDERING_VERBOSITY=INFO "${launch[@]}")
      TAIL=3 run "$tag" 600 "${launch[@]}" "$src/bench/pvbatch-orbit.py" --plugin "$SPACESKIP_PLUGIN" \
        --raw "$raw" --frames "${PVB_FRAMES:-60}" --backend "${PVB_BACKEND:-CUDA}" --view "${PVB_VIEW:-1024}" $stock \
        ${PVB_ARGS:-} $comp --png "$work/logs/$tag.png" --result "$work/logs/$tag.result" "${ref[@]}"
      [ -z "${PVB_LOG:-}" ] || env -u PYTHONHOME -u PYTHONPATH python3 "$src/bench/pv-frame-phases.py" "$work/logs/$tag.log" \
        >> "$work/logs/$tag.result" 2>&1
     done
    done
  done
  cat "$work"/logs/pvbatch-*.result >> "$out/pv.log" 2>/dev/null
fi
if has bench-ts; then
  TAIL=4 run "time-series" 600 "$pvpython" "$src/bench/time-series-vs-stock.py" --plugin "$SPACESKIP_PLUGIN" \
    --backend CUDA --dims "${TS_DIMS:-512}" --steps "${TS_STEPS:-10}" --rounds "${TS_ROUNDS:-2}" --raw \
    --workdir "${TS_WORKDIR:-$work/ts}" ${TS_ARGS:-}
fi
stop_xvfb
tar -C "$work" -czf "$out/logs.tgz" logs xvfb.log 2>/dev/null
log "done (status $status)"
exit $status
