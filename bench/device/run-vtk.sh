#!/usr/bin/env bash
# On a GPU machine without VTK, X or GL loaders (docs/gpu.md): unpacks the bundle made by
# bench/device/bundle-vtk.sh, starts its Xvfb, picks NVIDIA's GL for the clients
# (__GLX_VENDOR_LIBRARY_NAME=nvidia; falls back to Mesa and says so), runs every VTK mapper test
# with the CUDA backend forced (SPACESKIP_BACKEND=cuda) against the CPU baselines and thresholds
# (then once more as written: Auto/CPU per test, as CI runs them),
# compute-sanitizer memcheck on mapper tests, and the window benchmark beside the CLI's kernel
# timings for the same cases. Writes everything into OUTDIR.
#
#   bench/device/run-vtk.sh OUTDIR [PHASE...]
#   PHASE: tests (every mapper test in the X window, NVIDIA's GLX) tests-egl (the same in an EGL
#          pbuffer window: SPACESKIP_TEST_WINDOW=egl) memcheck (compute-sanitizer memcheck on every
#          mapper test, or MEMCHECK_TESTS, in MEMCHECK_WINDOW: x or egl) bench-nbody1024 bench-menger1024 bench-nbody2048 bench-host bench-float
#          bench-ert bench-hw (N-body 2048^3, the mapper's FilterMode Hardware (texture unit)
#          against Exact: HW_ITEMS, default DistanceGrid,DistanceGrid:hw,Auto,Auto:hw)
#          bench-frame (issue 13, the frame around the kernel: N-body 2048^3 Auto:hw with the
#          window benchmark's switches :full (whole window blended), :float (float interop
#          texture), alone and together, twice in one process: FRAME_ITEMS) interop-memcheck (compute-sanitizer memcheck on the window
#          benchmark with the image kept on the GPU, 8-bit and float: memcheck.log)
#          bench-floor (N-body FLOOR_N^3, default 128, in the 1024^2 window: the frame around a
#          kernel of a few hundredths of a ms, CUDA blend against GL's: FLOOR_ITEMS)
#          bench-ab (window benchmark processes alternating SPACESKIP_PART_RANGES: AB_RUNS,
#          AB_ITEMS) bench-oldnew (window benchmark processes alternating this bundle's binaries
#          and an older bundle's, OLD_VTK (a vtk.tar.xz, e.g. carried to the same machine in an
#          earlier call): OLDNEW_RUNS (default "old new old new"), OLDNEW_ITEMS, at N-body
#          OLDNEW_N^3 (2048)) nsys-frame (Nsight Systems timeline of the window benchmark, N-body 2048^3 Auto:hw and
#          :full:float, 8 frames and 2 edits each: CUDA API and GPU work per call, OpenGL
#          calls, waits; summaries in nsys.log, the CUDA/GL traces as CSV in logs.tgz)
#          bench-depth (N-body 1024^3 with an opaque point actor: the depth readback a
#          volume-only scene skips) bench-modes (issue 12: MIP with value-range skipping vs Naive, and the cost of
#          shading, window and CLI, N-body and Menger 1024^3: modes.log) bench-scatter (issue 34:
#          volumetric scattering on vs off in one process, and vtkGPUVolumeRayCastMapper with it:
#          scatter.log) bench-time-series (issue 38: playback of time steps (TS_SHAPE: nbody, or rm
#          for the mixing layer; TS_CASES), ours against
#          vtkGPUVolumeRayCastMapper in one window, and the CLI's upload bound: time-series.log) core (Core's GoogleTest binary, then compute-sanitizer memcheck and racecheck on
#          its CUDA tests: core.log) auto (the CLI's Builder Auto against fixed builders, dense and
#          sparse 1024^3: cli-bench.log)
#          (default: all, in this order: tests memcheck bench-nbody1024 bench-nbody2048 bench-menger1024
#          bench-host bench-float bench-ert)
#   env:   BUNDLE (default ./.vtkbundle), XDISPLAY (77), FRAMES (16), TESTS_ASIS (1: the tests once more
#          without the CUDA override), DEADLINE (epoch seconds: phases that would
#          start after it are skipped), MEMCHECK_TESTS, BENCH_BUILDERS, VTK_GPU (1: also time
#          vtkGPUVolumeRayCastMapper in the 1024^3 benchmarks), REQUIRE_NVIDIA_GL (set: stop
#          when only Mesa works), BENCH_N (every benchmark at this size instead: quick checks),
#          EDIT_CUT (the window benchmark's --edit-cut: 0.3 by default, changing N-body's occupied
#          cells; 0.2 changes none, the older edit path)
#
# OUTDIR receives at most 8 files (the device tool's limit): env.txt, tests.log, memcheck.log,
# bench.log, bench.csv, cli-bench.log, cli-bench.csv, logs.tgz (everything).
set -uo pipefail
out=${1:?usage: run-vtk.sh OUTDIR [PHASE...]}
shift
phases=${*:-tests memcheck bench-nbody1024 bench-nbody2048 bench-menger1024 bench-host bench-float bench-ert}
src=$(cd "$(dirname "$0")/../.." && pwd)
bundle=${BUNDLE:-$src/.vtkbundle}
mkdir -p "$out"
out=$(cd "$out" && pwd)
work=$(mktemp -d)
frames=${FRAMES:-16}
status=0
has() { case " $phases " in *" $1 "*) return 0 ;; *) return 1 ;; esac; }
log() { echo "[$(date -u +%H:%M:%S)] $*" | tee -a "$work/run.log"; }
late() { [ -n "${DEADLINE:-}" ] && [ "$(date +%s)" -ge "$DEADLINE" ]; }

# --- unpack -----------------------------------------------------------------------------------
B=$work/bundle
mkdir -p "$B"
for t in vtk x; do
  xz -dc "$bundle/$t.tar.xz" | tar -C "$B" -xf - || { echo "cannot unpack $bundle/$t.tar.xz" >&2; exit 1; }
done
log "bundle unpacked ($(cat "$B/vtk/COMMIT" 2>/dev/null | head -1))"

{
  echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  echo "host: $(hostname)  phases: $phases  frames: $frames"
  nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv 2>&1
  echo "bundle built from: $(cat "$B/vtk/COMMIT" 2>/dev/null)"
  # The device copy carries the working tree's files; its git HEAD can be an older commit.
  echo "git HEAD of the copied tree (may predate its files): $(cd "$src" && git rev-parse HEAD 2>/dev/null || echo none)"
  echo "cores: $(nproc)  os: $(. /etc/os-release 2>/dev/null; echo "$PRETTY_NAME")"
} > "$work/env.txt"

# --- X server: the bundled Xvfb, its GLX on the bundled Mesa swrast driver ---------------------
. "$src/bench/device/x-gl.sh"
start_xvfb

# --- GL for the clients: NVIDIA first, Mesa (llvmpipe, bundled) as the fallback ---------------
{
  echo "LD_LIBRARY_PATH at start: $sys_ldpath"
  echo "libGLX_nvidia: ${nvglx:-not found}"
  ls -la /usr/local/nvidia/lib64 2>/dev/null | grep -iE "GLX|EGL|libGL|nvidia-gl|glcore|tls" | head -12
} >> "$work/env.txt"
# The bundle's X libraries after VTK's: without them NVIDIA's GLX client finds no config on
# the bundled Xvfb ("no decent config") and the tests fell back to Mesa.
export LD_LIBRARY_PATH=$B/vtk/lib:$B/x/lib${nvdir:+:$nvdir}${sys_ldpath:+:$sys_ldpath}
export __GLX_VENDOR_LIBRARY_NAME=nvidia
bench=$B/vtk/bin/spaceskip_window_bench
tests=$B/vtk/bin/vtkSpaceSkipCxxTests
cli=${CLI:-$B/vtk/bin/spaceskip}  # CLI: e.g. one carried apart (bench/device/pack-core.sh: its cli.tar.xz)
probe() { timeout 60 "$bench" --shape nbody --dims 64 --frames 2 --size 128 --builders Naive --edits 0 > "$work/probe.log" 2>&1; }
if probe && grep -q "GL_RENDERER.*NVIDIA" "$work/probe.log"; then
  gl="NVIDIA GL (__GLX_VENDOR_LIBRARY_NAME=nvidia)"
else
  cp "$work/probe.log" "$work/probe-nvidia.log"
  LD_DEBUG=libs probe 2>/dev/null; grep -iE "GLX_nvidia|glcore|libGLX|error" "$work/probe.log" | head -20 > "$work/probe-nvidia-ld.log"
  # Indirect GLX allowed: does NVIDIA's client want it on a non-NVIDIA server?
  stop_xvfb
  start_xvfb +iglx
  if probe && grep -q "GL_RENDERER.*NVIDIA" "$work/probe.log"; then
    gl="NVIDIA GL (__GLX_VENDOR_LIBRARY_NAME=nvidia, Xvfb +iglx)"
  else
    cp "$work/probe.log" "$work/probe-nvidia-iglx.log"
    stop_xvfb
    start_xvfb
    unset __GLX_VENDOR_LIBRARY_NAME
    export LD_LIBRARY_PATH=$B/vtk/lib:$B/x/lib${sys_ldpath:+:$sys_ldpath} LIBGL_DRIVERS_PATH=$B/x/lib/dri
    probe
    gl="FALLBACK: Mesa (NVIDIA GL failed: see probe-nvidia*.log)"
  fi
fi
log "client GL: $gl; $(grep GL_RENDERER "$work/probe.log")"
{ echo "client GL: $gl"; grep GL_RENDERER "$work/probe.log"; } >> "$work/env.txt"
cp "$work/env.txt" "$out/env.txt"
if [ -n "${REQUIRE_NVIDIA_GL:-}" ] && [ "${gl#FALLBACK}" != "$gl" ]; then
  log "REQUIRE_NVIDIA_GL set and NVIDIA GL failed: stopping"
  stop_xvfb
  tar -C "$work" --exclude=bundle -czf "$out/logs.tgz" . 2>/dev/null
  exit 3
fi

# --- the VTK mapper tests, CUDA forced --------------------------------------------------------
cxx=$src/VTKModule/Testing/Cxx/CMakeLists.txt
testnames=$(sed -n '/vtk_add_test_cxx/,/)/p' "$cxx" | grep -oE 'Test[A-Za-z0-9]+\.cxx(,NO_VALID)?')
run_tests() {  # BACKEND LOGNAME [WINDOW] (BACKEND "asis": each test's own Backend setting;
  # WINDOW "egl": the tests draw into an EGL window: SpaceSkipEglWindow.h)
  local be=$1 name=$2 win=${3:-x} pass=0 fail=0 skip=0 ongpu=0 t exe valid rc env=()
  mkdir -p "$work/tmp-$be-$win" "$work/data"
  for t in $testnames; do
    exe=${t%%.cxx*}
    valid=()
    case $t in *NO_VALID) ;; *) valid=(-V "$src/VTKModule/Testing/Data/Baseline/$exe.png") ;; esac
    echo "==== $exe (SPACESKIP_BACKEND=$be, window $win)" >> "$work/$name"
    [ "$be" = asis ] && env=(-u SPACESKIP_BACKEND) || env=(SPACESKIP_BACKEND=$be)
    env "${env[@]}" SPACESKIP_REPORT=1 SPACESKIP_TEST_WINDOW=$win timeout 300 "$tests" "$exe" -D "$work/data" \
      -T "$work/tmp-$be-$win" "${valid[@]}" > "$work/one.log" 2>&1
    rc=$?
    cat "$work/one.log" >> "$work/$name"
    grep -q "image on the GPU" "$work/one.log" && ongpu=$((ongpu + 1))
    case $rc in 0) pass=$((pass + 1)) ;; 125) skip=$((skip + 1)) ;; *) fail=$((fail + 1)) ;; esac
    echo "==== $exe rc=$rc renderer: $(grep -om1 'GL_RENDERER [^,]*' "$work/one.log")$(sed -n 's/^SPACESKIP_TEST_WINDOW=egl: / window: /p' "$work/one.log" | head -1)" >> "$work/$name"
    log "  $be $win $exe rc=$rc"
  done
  log "tests $be $win: $pass passed, $fail failed, $skip skipped; $ongpu kept an image on the GPU"
  echo "SUMMARY $be window $win: $pass passed, $fail failed, $skip skipped of $((pass + fail + skip));" \
    "$ongpu tests kept an image on the GPU (interop); renderers: $(grep -o 'GL_RENDERER [^,]*' "$work/$name" | sort | uniq -c | tr '\n' ';')" >> "$work/$name"
  [ $fail -eq 0 ] || status=1
}
summarize_tests() {  # LOGNAME (the summary first: the details are cut at 400 lines)
  grep -E "^SUMMARY" "$work/$1"
  grep -E "rc=|SpaceSkip: backend|Backend|PSNR|max diff|check failed|ERROR|Warning|error|RSS|device bytes" \
    "$work/$1" | head -400
}
if has tests && ! late; then
  log "VTK mapper tests, CUDA forced, X window ($gl)"
  run_tests cuda tests-cuda.log
  [ "${TESTS_ASIS:-1}" = 1 ] && run_tests asis tests-asis.log
  { summarize_tests tests-cuda.log; grep -hE "^SUMMARY" "$work"/tests-asis.log 2>/dev/null; } > "$out/tests.log"
fi
# The same tests in NVIDIA's EGL (a pbuffer; no X window): the GL of headless servers.
if has tests-egl && ! late; then
  egl_json=$(ls /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json /usr/share/glvnd/egl_vendor.d/10_nvidia.json 2>/dev/null | head -1)
  log "VTK mapper tests, CUDA forced, EGL window (${egl_json:-no NVIDIA EGL vendor file})"
  __EGL_VENDOR_LIBRARY_FILENAMES=$egl_json run_tests cuda tests-egl.log egl
  summarize_tests tests-egl.log > "$out/tests-egl.log"
fi

# --- compute-sanitizer memcheck on mapper tests (CUDA) ----------------------------------------
if has memcheck && ! late; then
  all_tests=$(for t in $testnames; do echo "${t%%.cxx*}"; done)
  for exe in ${MEMCHECK_TESTS:-$all_tests}; do
    late && { log "memcheck $exe skipped (deadline)"; echo "==== $exe skipped (deadline)" >> "$out/memcheck.log"; continue; }
    log "memcheck $exe"
    SPACESKIP_BACKEND=cuda SPACESKIP_REPORT=1 SPACESKIP_UNDER_SANITIZER=1 SPACESKIP_TEST_WINDOW=${MEMCHECK_WINDOW:-x} timeout 240 compute-sanitizer --tool memcheck \
      --error-exitcode 99 "$tests" "$exe" -D "$work/data" -T "$work/tmp-cuda" \
      > "$work/memcheck-$exe.log" 2>&1
    rc=$?
    log "memcheck $exe rc=$rc"
    [ $rc -eq 0 ] || status=1
    { echo "==== $exe rc=$rc"; grep -E "ERROR SUMMARY|Invalid|SpaceSkip: backend" "$work/memcheck-$exe.log" | head -20; tail -3 "$work/memcheck-$exe.log"; } >> "$out/memcheck.log"
  done
fi

# --- window benchmark + the CLI's kernel timings, same volume, builders, camera and TF ---------
wb=${BENCH_BUILDERS:-Naive,Grid,LBVH,LBVHCPU,KdTreeCPU:mls32,KdTreeGPUFast:mls32,Hybrid,DistanceGrid,DistanceGrid:brick4}
cb=naive,grid,lbvh,lbvh-cpu,kdtree-cpu:mls32,kdtree-gpu-fast:mls32,hybrid,distance-grid,distance-grid:brick4
window_bench() {  # SHAPE N [--vtk-gpu] [--egl]
  local shape=$1 n=${BENCH_N:-$2}
  shift 2
  late && { log "skip bench $shape$n (deadline)"; return; }
  log "window bench $shape $n^3 $*"
  SPACESKIP_BACKEND=cuda timeout 420 "$bench" --shape "$shape" --dims "$n" --frames "$frames" \
    --size 1024 --builders "${ITEMS:-$wb}" --csv "$out/bench.csv" --png "$work/frame" \
    ${EDIT_CUT:+--edit-cut "$EDIT_CUT"} "$@" >> "$work/bench.log" 2>&1
  local rc=$?
  log "window bench rc=$rc"
  [ $rc -eq 0 ] || status=1  # 3: an item's GPU-path image differs from the host path's by > 1/255
  cp "$work/bench.log" "$out/bench.log"
  [ -n "${ITEMS:-}" ] && return  # a variant of a case benched above: no second CLI run
  log "CLI bench gen:$shape:$n"
  timeout 300 "$cli" bench "gen:$shape:$n" --backend cuda --builders "$cb" --size 1024x1024 \
    --frames "$frames" --csv "$work/cli-$shape$n.csv" >> "$work/cli-bench.log" 2>&1
  log "CLI bench rc=$?"
  cp "$work/cli-bench.log" "$out/cli-bench.log"
  if [ -f "$work/cli-$shape$n.csv" ]; then
    [ -f "$out/cli-bench.csv" ] || head -1 "$work/cli-$shape$n.csv" > "$out/cli-bench.csv"
    tail -n +2 "$work/cli-$shape$n.csv" >> "$out/cli-bench.csv"
  fi
}
vg=()
[ "${VTK_GPU:-1}" = 1 ] && vg=(--vtk-gpu)
# The benchmark's window: first a vtkGenericOpenGLRenderWindow on NVIDIA's headless EGL (--egl),
# else the tests' X window.
if has bench-nbody1024 || has bench-nbody2048 || has bench-menger1024 || has bench-modes || has bench-scatter || has bench-time-series || has bench-depth || has bench-hw || has bench-frame || has interop-memcheck || has nsys-frame || has bench-ab || has bench-floor || has bench-oldnew; then
  egl_json=$(ls /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json /usr/share/glvnd/egl_vendor.d/10_nvidia.json 2>/dev/null | head -1)
  [ -n "$egl_json" ] && export __EGL_VENDOR_LIBRARY_FILENAMES=$egl_json
  if timeout 60 "$bench" --egl --shape nbody --dims 64 --frames 2 --size 128 --builders Naive --edits 0 \
      > "$work/probe-egl.log" 2>&1 && grep -q "GL_RENDERER.*NVIDIA" "$work/probe-egl.log"; then
    vg+=(--egl)
    wgl="NVIDIA EGL ($egl_json), $(grep -om1 "[A-Za-z]* on EGL" "$work/probe-egl.log")"
  else
    wgl="the tests' X window ($gl): NVIDIA EGL failed, see probe-egl.log"
  fi
  log "window benchmark GL: $wgl; $(grep GL_RENDERER "$work/probe-egl.log")"
  { echo "window benchmark GL: $wgl"; grep GL_RENDERER "$work/probe-egl.log"; } >> "$work/env.txt"
  cp "$work/env.txt" "$out/env.txt"
fi
has bench-nbody1024 && window_bench nbody 1024 "${vg[@]}"
v2=()
for a in "${vg[@]}"; do [ "$a" = --vtk-gpu ] || v2+=("$a"); done
has bench-nbody2048 && window_bench nbody 2048 "${v2[@]}"
has bench-menger1024 && window_bench menger 1024 "${vg[@]}"
# The image through host memory (GPUComposite off; 8-bit, then 32-bit float upload) against the
# default CUDA-GL interop path.
has bench-host && ITEMS=Grid,DistanceGrid:brick4 window_bench nbody 1024 "${v2[@]}" --host-composite
has bench-float && ITEMS=Grid,DistanceGrid:brick4 window_bench nbody 1024 "${v2[@]}" --host-composite --float-composite
# A volume-only scene skips the depth readback; one opaque actor brings it back (same items as
# bench-nbody1024's DistanceGrid rows, for the ratio).
has bench-depth && ITEMS=Grid,DistanceGrid,DistanceGrid:brick4 window_bench nbody 1024 "${v2[@]}" --depth-actor
# The mapper's hardware filter (FilterMode Hardware: the texture unit's trilinear filter) against
# exact sampling, N-body 2048^3 (issue 13's window goal: >= 700 fps, TF edit <= 3 ms).
has bench-hw && ITEMS=${HW_ITEMS:-DistanceGrid,DistanceGrid:hw,Auto,Auto:hw} window_bench nbody 2048 "${v2[@]}"
# The frame around the kernel (issue 13): each change against the state before it, in one process.
has bench-frame && ITEMS=${FRAME_ITEMS:-Auto:hw,Auto:hw:full:float,Auto:hw:full,Auto:hw:float,Auto:hw,Auto:hw:full:float} \
  window_bench nbody 2048 "${v2[@]}"
# The window's floor (issue 13): the same frame around a kernel of a few hundredths of a
# millisecond (N-body FLOOR_N^3, default 128, still drawn over the whole 1024^2 window): what
# the window costs besides the kernel, with the CUDA blend and with GL's (:glblend).
has bench-floor && ITEMS=${FLOOR_ITEMS:-Auto:hw,Auto:hw:glblend,Auto:hw,Auto:hw:glblend} \
  window_bench nbody "${FLOOR_N:-128}" "${v2[@]}"
# Part ranges off and on (SPACESKIP_PART_RANGES per process: the sub-brick masks on the edit's
# path or on the frame after it), N-body 2048^3, alternated: AB_RUNS (e.g. "0 1 0 1"), AB_ITEMS.
for r in ${AB_RUNS:-}; do
  has bench-ab || break
  echo "==== SPACESKIP_PART_RANGES=$r" >> "$work/bench.log"
  (export SPACESKIP_PART_RANGES=$r; ITEMS=${AB_ITEMS:-Auto,DistanceGrid,Auto:hw} window_bench nbody 2048 "${v2[@]}")
done
# This bundle against an older one (OLD_VTK), one window benchmark process each, alternated:
# the same items, machine and window, the binaries (and their libvtkSpaceSkip) of two commits.
if has bench-oldnew && [ -f "${OLD_VTK:-}" ]; then
  mkdir -p "$B/old"
  xz -dc "$OLD_VTK" | tar -C "$B/old" -xf - || log "cannot unpack $OLD_VTK"
  log "old bundle: $(cat "$B/old/vtk/COMMIT" 2>/dev/null | head -1)"
  for r in ${OLDNEW_RUNS:-old new old new}; do
    echo "==== $r bundle: $([ "$r" = old ] && cat "$B/old/vtk/COMMIT" 2>/dev/null | head -1 || cat "$B/vtk/COMMIT" 2>/dev/null | head -1)" >> "$work/bench.log"
    if [ "$r" = old ]; then
      (bench=$B/old/vtk/bin/spaceskip_window_bench
       export LD_LIBRARY_PATH=$B/old/vtk/lib${LD_LIBRARY_PATH#$B/vtk/lib}
       ITEMS=${OLDNEW_ITEMS:-Auto:hw,Auto} window_bench nbody "${OLDNEW_N:-2048}" "${v2[@]}")
    else
      ITEMS=${OLDNEW_ITEMS:-Auto:hw,Auto} window_bench nbody "${OLDNEW_N:-2048}" "${v2[@]}"
    fi
  done
fi
# The interop path under compute-sanitizer (the mapper tests draw through host memory on Mesa).
if has interop-memcheck && ! late; then
  log "interop memcheck"
  SPACESKIP_BACKEND=cuda timeout 400 compute-sanitizer --tool memcheck --error-exitcode 99 "$bench" --shape nbody \
    --dims 128 --frames 4 --size 256 --builders Auto:hw,Auto:hw:float,Grid,Grid:full "${v2[@]}" --edits 2 \
    > "$work/interop-memcheck.log" 2>&1
  rc=$?
  log "interop memcheck rc=$rc"
  [ $rc -eq 0 ] || status=1
  { echo "==== interop memcheck rc=$rc"; grep -E "ERROR SUMMARY|Invalid|image on the GPU|through host|^Auto|^Grid" "$work/interop-memcheck.log" | head -30; } >> "$out/memcheck.log"
fi
# Where the frame's time goes on the GPU and the host, call by call (Nsight Systems, when installed).
if has nsys-frame && ! late; then
  if command -v nsys > /dev/null; then
    log "nsys frame profile"
    SPACESKIP_BACKEND=cuda timeout 420 nsys profile --trace=cuda,opengl,osrt --sample=none --cpuctxsw=none \
      --force-overwrite=true -o "$work/frame" "$bench" --shape nbody --dims "${BENCH_N:-2048}" --frames 8 \
      --size 1024 --builders Auto:hw,Auto:hw:full:float --edits 2 "${v2[@]}" > "$work/nsys-run.log" 2>&1
    log "nsys rc=$?"
    for r in cuda_api_sum cuda_gpu_sum osrt_sum opengl_khr_range_sum; do
      nsys stats --report $r --format column "$work/frame.nsys-rep" >> "$work/nsys.log" 2>&1
    done
    nsys stats --report cuda_gpu_trace --report cuda_api_trace --format csv --output "$work/nsys" \
      "$work/frame.nsys-rep" >> "$work/nsys-run.log" 2>&1
    rm -f "$work/frame.nsys-rep" "$work/frame.sqlite"
    { grep -E "^item|^Auto|^empty" "$work/nsys-run.log"; cat "$work/nsys.log"; } > "$out/nsys.log"
  else
    log "nsys-frame: no nsys on this machine"
    echo "no nsys on this machine" > "$out/nsys.log"
  fi
fi
# Early ray termination on (VTK's mapper cannot turn it off): like for like with its rows above.
if has bench-ert; then
  ITEMS=Naive,Grid,KdTreeGPUFast:mls32,DistanceGrid:brick4 window_bench nbody 1024 "${v2[@]}" --ert
  ITEMS=Naive,Grid,KdTreeGPUFast:mls32,Hybrid window_bench menger 1024 "${v2[@]}" --ert
fi

# MIP: Naive takes every sample; every skipping builder marches the per-brick value ranges
# (render/Integrator.h, usesValueRanges). Shading: composite with and without --shade.
# Volumetric shadows and scattering (issue 34): shading alone (:noscatter) against scattering
# SCATTER (blending,reach,anisotropy; default 1,0.5,0) item by item in one process, N-body
# SCATTER_N^3 (2048) and the dense stand-in SCATTER_DENSE (rm) at SCATTER_DENSE_N^3 (1024); then
# vtkGPUVolumeRayCastMapper with the same settings (SCATTER_VTK_FRAMES frames, default 2) beside
# our Auto, at SCATTER_VTK_N^3 (1024). scatter.log.
if has bench-scatter; then
  sc=${SCATTER:-1,0.5,0}
  for c in "nbody ${SCATTER_N:-2048}" "${SCATTER_DENSE:-rm} ${SCATTER_DENSE_N:-1024}"; do
    set -- $c
    ITEMS=${SCATTER_ITEMS:-Auto:noscatter,Auto,Grid:noscatter,Grid,Auto:noscatter,Auto} window_bench "$1" "$2" "${v2[@]}" --scatter "$sc"
  done
  if [ "${VTK_GPU:-1}" = 1 ]; then
    for shape in nbody "${SCATTER_DENSE:-rm}"; do
      frames=${SCATTER_VTK_FRAMES:-2} ITEMS=Auto:noscatter,Auto window_bench "$shape" "${SCATTER_VTK_N:-1024}" "${vg[@]}" --scatter "$sc"
    done
  fi
  grep -E "^blend|^item|^Auto|^Grid|^Naive|^vtkGPU|volume |GL_RENDERER" "$work/bench.log" > "$out/scatter.log"
fi

# Time series (issue 38): TS_STEPS (100) steps of the N-body stand-in advected, TS_HELD (4) held,
# played by our mapper (TS_ITEMS, default Auto) and then vtkGPUVolumeRayCastMapper in the same
# window, each step a new scalar array (the window benchmark's --time-series; VTK's mapper plays
# TS_VTK_STEPS of them, default 20: its steps take up to seconds), for every case of
# TS_CASES ("512:uint8 512:float32 1024:uint8 1024:float32"); then, with the CLI in the bundle
# (BUNDLE_NO_CLI=0), its playback and upload bound for the same case. time-series.log.
if has bench-time-series; then
  for c in ${TS_CASES:-512:uint8 512:float32 1024:uint8 1024:float32}; do
    late && break
    tn=${c%%:*} tt=${c#*:}
    ts=${TS_SHAPE:-nbody}
    echo "==== time series $ts $tn^3 $tt" >> "$work/bench.log"
    ITEMS=${TS_ITEMS:-Auto} window_bench "$ts" "$tn" "${vg[@]}" --time-series "${TS_STEPS:-100}" \
      --steps-held "${TS_HELD:-4}" --step-type "$tt" --vtk-gpu-steps "${TS_VTK_STEPS:-20}"
    if [ -x "$cli" ]; then
      { echo "==== CLI time series $ts $tn^3 $tt"; timeout 300 "$cli" bench "gen:$ts:$tn" --backend cuda \
          --size 1024x1024 --time-series "${TS_STEPS:-100}" --steps-held "${TS_HELD:-4}" --step-type "$tt"; } \
        >> "$work/time-series-cli.log" 2>&1
    fi
  done
  { grep -E "^====|^item|^Auto|^Grid|^DistanceGrid|^Naive|^vtkGPU|^time series|volume |GL_RENDERER" "$work/bench.log"
    echo; cat "$work/time-series-cli.log" 2>/dev/null; } > "$out/time-series.log"
fi

if has bench-modes; then
  for shape in nbody menger; do
    for mode in "--blend composite" "--blend composite --shade" "--blend mip"; do
      late && break
      ITEMS=Naive,Grid,KdTreeGPUFast:mls32,DistanceGrid window_bench $shape 1024 "${vg[@]}" $mode
      cmode=${mode/--shade/--shade on}
      log "CLI bench gen:$shape:1024 $cmode"
      { echo "==== CLI gen:$shape:1024 $cmode"; timeout 300 "$cli" bench "gen:$shape:1024" --backend cuda \
          --builders naive,grid,kdtree-gpu-fast:mls32,distance-grid --size 1024x1024 --frames "$frames" $cmode; } \
        >> "$work/modes-cli.log" 2>&1
      log "CLI bench rc=$?"
    done
  done
  { grep -E "^blend|^item|^Naive|^Grid|^KdTree|^Distance|^vtkGPU|volume " "$work/bench.log"; echo; cat "$work/modes-cli.log"; } > "$out/modes.log"
fi

# --- Core's tests (CUDA included) and compute-sanitizer on its CUDA tests ------------------------
# CORE_TESTS: Core's test binary carried apart (e.g. xz'd beside a bundle built with BUNDLE_NO_CORE_TESTS=1).
coretests=${CORE_TESTS:-$B/vtk/bin/spaceskip_core_tests}
if has core && ! late && [ -x "$coretests" ]; then
  log "Core tests"
  timeout 400 "$coretests" > "$work/core-tests.log" 2>&1
  rc=$?
  log "Core tests rc=$rc"
  [ $rc -eq 0 ] || status=1
  { echo "==== spaceskip_core_tests rc=$rc"; grep -E "^\[  (PASSED|FAILED|SKIPPED) |tests ran|FAILED TEST" "$work/core-tests.log" | head -40; } > "$out/core.log"
  filter=${CORE_SANITIZE_FILTER:-CudaBackend.*:BlendModes.CudaEqualsCpu*:Volumes/CudaImage.EqualsCpuForEveryBuilder/nbody_*:DistanceField.TheCudaFieldEqualsTheCpuField:DeviceImage.*}
  for tool in memcheck racecheck; do
    late && break
    log "compute-sanitizer $tool on $filter"
    timeout 240 compute-sanitizer --tool $tool --error-exitcode 99 "$coretests" --gtest_filter="$filter" \
      > "$work/core-$tool.log" 2>&1
    rc=$?
    log "$tool rc=$rc"
    [ $rc -eq 0 ] || status=1
    { echo "==== $tool ($filter) rc=$rc"; grep -E "ERROR SUMMARY|RACECHECK SUMMARY|Invalid|Race|^\[  (PASSED|FAILED) " "$work/core-$tool.log" | head -20; } >> "$out/core.log"
  done
fi

# --- Builder Auto against fixed builders (CLI, kernel fps), a dense and a sparse volume ----------
if has auto && ! late; then
  for shape in menger nbody; do
    log "CLI bench auto gen:$shape:${BENCH_N:-1024}"
    timeout 300 "$cli" bench "gen:$shape:${BENCH_N:-1024}" --backend cuda --size 1024x1024 --frames "$frames" \
      --builders naive,grid,distance-grid,kdtree-gpu-fast:deep:mls128,lbvh,auto >> "$work/cli-bench.log" 2>&1
    log "CLI bench rc=$?"
  done
  cp "$work/cli-bench.log" "$out/cli-bench.log"
fi

stop_xvfb
tar -C "$work" --exclude=bundle -czf "$out/logs.tgz" . 2>/dev/null
log "done, status=$status"
exit $status
