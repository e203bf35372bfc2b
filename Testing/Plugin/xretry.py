"""Runs a test command; reruns it (up to 3 tries) only when it failed because the X server
refused a connection: Xvfb here resets a few percent of new connections (measured: 45 of 400
xcb_connect calls in a row failed with XCB_CONN_ERROR; strace shows ECONNRESET right after
connect; a fresh Xvfb: 17 of 400). ParaView then either aborts ("bad X server connection") or,
when its rendering-capability probe failed, reports that remote rendering is not available.
Any other failure is reported as is.
Root cause found later: Xvfb resets itself whenever its last client disconnects, and a client
connecting during that reset is refused. scripts/test.sh now starts Xvfb with -noreset
(measured: 3 parallel loops of 150 xdpyinfo, 23/450 refused without -noreset, 0/450 with it);
this retry stays only as a guard for machines whose Xvfb was started without it. Usage: python3 xretry.py COMMAND..."""
import subprocess
import sys

MARKS = ("bad X server connection",
         "require remote rendering which, however, is not available")
for attempt in range(1, 4):
    p = subprocess.run(sys.argv[1:], stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    out = p.stdout.decode(errors="replace")
    sys.stdout.write(out)
    sys.stdout.flush()
    if p.returncode == 0 or not any(m in out for m in MARKS):
        sys.exit(p.returncode)
    print("xretry: attempt %d failed to connect to the X server; retrying" % attempt)
sys.exit(p.returncode)
