"""Runs a test command; reruns it (up to 3 tries) only when it failed because the X server
refused the connection ("bad X server connection"): Xvfb here refuses a few percent of rapid
connections (measured: 45 of 400 xcb_connect calls in a row failed with XCB_CONN_ERROR).
Any other failure is reported as is. Usage: python3 xretry.py COMMAND..."""
import subprocess
import sys

MARK = "bad X server connection"
for attempt in range(1, 4):
    p = subprocess.run(sys.argv[1:], stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    out = p.stdout.decode(errors="replace")
    sys.stdout.write(out)
    sys.stdout.flush()
    if p.returncode == 0 or MARK not in out:
        sys.exit(p.returncode)
    print("xretry: attempt %d failed to connect to the X server; retrying" % attempt)
sys.exit(p.returncode)
