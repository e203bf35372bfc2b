# Sourced by the scripts that render (test.sh, demo.sh): without a DISPLAY, starts an Xvfb on
# :${SPACESKIP_XVFB_DISPLAY:-N} and stops it when the calling script exits (its EXIT trap).
# usage: source scripts/xvfb.sh N
if [ -z "${DISPLAY:-}" ]; then
  export DISPLAY=:${SPACESKIP_XVFB_DISPLAY:-$1}
  Xvfb "$DISPLAY" -screen 0 1280x1024x24 -nolisten tcp -noreset >/dev/null 2>&1 &
  xvfb_pid=$!
  trap 'kill $xvfb_pid 2>/dev/null || true' EXIT
  sleep 1
fi
