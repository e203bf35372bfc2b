# Sourced by bench/device/run-vtk.sh and run-pv.sh on the GPU machine: the bundled X server
# (x.tar.xz of bundle-vtk.sh, unpacked under $B/x) and where the machine keeps NVIDIA's GLX.
# Needs: B (the unpacked bundle), work (a scratch folder), log (a function); sets DISPLAY.
# Xvfb runs xkbcomp from its compiled-in directory (/usr/bin).
[ -x /usr/bin/xkbcomp ] || cp "$B/x/bin/xkbcomp" /usr/bin/xkbcomp
dpy=${XDISPLAY:-77}
export DISPLAY=:$dpy
start_xvfb() {  # [extra Xvfb options]: its GLX on the bundled Mesa swrast driver
  LD_LIBRARY_PATH=$B/x/lib LIBGL_DRIVERS_PATH=$B/x/lib/dri \
    "$B/x/bin/Xvfb" :$dpy -screen 0 1280x1024x24 -nolisten tcp -noreset -xkbdir "$B/x/share/xkb" "$@" \
    >> "$work/xvfb.log" 2>&1 &
  xpid=$!
  for _ in $(seq 50); do [ -S /tmp/.X11-unix/X$dpy ] && break; sleep 0.2; done
  log "Xvfb $* pid $xpid socket $(ls /tmp/.X11-unix/X$dpy 2>&1)"
}
stop_xvfb() {
  kill $xpid 2>/dev/null
  wait $xpid 2>/dev/null
  rm -f /tmp/.X11-unix/X$dpy /tmp/.X$dpy-lock
}
# NVIDIA's GLX vendor library: where the machine keeps it (its loader path is kept after ours).
sys_ldpath=${LD_LIBRARY_PATH:-}
nvglx=$( (ldconfig -p | awk '/libGLX_nvidia\.so\.0/ {print $NF}'; for d in ${sys_ldpath//:/ } \
  /usr/local/nvidia/lib64 /usr/local/nvidia/lib /usr/lib/x86_64-linux-gnu /usr/lib64; do
  ls "$d"/libGLX_nvidia.so.0 2>/dev/null; done) | head -1)
nvdir=${nvglx:+$(dirname "$nvglx")}
