"""Client/server: a pvserver started here on a free localhost port, pvpython connected to it with
the plugin loaded on both sides. The server renders the Space Skipping Volume; the client reads
the server's statistics (vtkSMSpaceSkipRepresentationProxy gathers them from the render server;
the client's own copy of the representation never renders and stays at "none"/0), the image
matches the built-in session's baseline, and Blend Mode Slice follows the Slice Type plane moved
from the client as ParaView's Volume does.

With MPIEXEC the server runs as `mpiexec -n 2 pvserver`: the volume is split over 2 ranks and
composited in float on rank 0 (Float Parallel Compositing), the same checks apply, and views
that put one rank's piece out of the frame, hide and show the volume, or zoom in, each render
within a time limit and match the 8-bit path (the property off) within 2/255; the exchange must
never give up (its warning) in those views.

Usage: pvpython test_clientserver.py PVSERVER [MPIEXEC]
The server is started under `timeout` and killed at the end, whatever happened.
"""
import os
import select
import socket
import subprocess
import sys
import time

from paraview.simple import *
from paraview import servermanager, simple
import ssptest

SERVER_SECONDS = 240  # the server's own time limit (ctest's is larger)


def free_port():
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.bind(("localhost", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def start_server(pvserver, port, mpiexec=None):
    mpi = [mpiexec, "--allow-run-as-root", "--oversubscribe", "-n", "2"] if mpiexec else []
    # pvpython may have initialised MPI (as a singleton): its job state would confuse mpiexec.
    env = ssptest.launcher_env()
    server = subprocess.Popen(
        ["timeout", "-s", "KILL", str(SERVER_SECONDS)] + mpi + [pvserver, "--server-port=%d" % port],
        env=env,
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True)
    # Wait (bounded) for its first line, "Waiting for client..." (the lines after it may stay in
    # the pipe's buffer); Connect() below retries until the server accepts.
    deadline = time.time() + 60
    lines = []
    while time.time() < deadline:
        ready, _, _ = select.select([server.stdout], [], [], 1.0)
        if ready:
            line = server.stdout.readline()
            if not line:
                break
            lines.append(line.rstrip())
            if "Waiting for client" in line:
                return server
        if server.poll() is not None:
            break
    stop_server(server)
    raise RuntimeError("pvserver did not start listening on port %d: %s" % (port, lines))


def stop_server(server):
    if server.poll() is None:
        try:
            os.killpg(server.pid, 9)  # timeout and pvserver: the session started above
        except ProcessLookupError:
            pass
    try:
        out, _ = server.communicate(timeout=30)
        if out:
            print("pvserver output:\n" + out)
        return out or ""
    except subprocess.TimeoutExpired:
        print("pvserver did not exit")
    return ""


ok = ssptest.Checker()
pvserver = sys.argv[1]
mpiexec = sys.argv[2] if len(sys.argv) > 2 else None
port = free_port()
server = start_server(pvserver, port, mpiexec)
try:
    connection = Connect("localhost", port, timeout=60)
    ok.check(connection is not None, "connected to pvserver on localhost:%d" % port)
    if connection is None:
        raise RuntimeError("no connection")
    ok.check(servermanager.ActiveConnection.IsRemote(), "the session is remote")
    # The plugin on the server (representation, mapper) and on the client (proxy class, XML).
    LoadPlugin(ssptest.env("SPACESKIP_PLUGIN"), remote=True, ns=globals())
    LoadPlugin(ssptest.env("SPACESKIP_PLUGIN"), remote=False, ns=globals())
    simple._DisableFirstRenderCameraReset()

    # The scene of test_render.py (its baseline), KdTreeCPU: a k-d tree with nodes to count.
    reader, view, disp = ssptest.make_scene(builder="KdTreeCPU", backend="CPU")
    img = ssptest.render_to(view, "clientserver_kdtree.png")
    a = ssptest.read_png(img)
    lit = ssptest.lit_fraction(a)
    ok.check(0.05 < lit < 0.9, "the volume covers %.1f%% of the image" % (100 * lit))
    try:
        ssptest.compare_to_baseline(img, "SpaceSkipRender.png", 40.0)
        ok.check(True, "the server's image matches the built-in session's baseline")
    except AssertionError as e:
        ok.check(False, str(e))

    # The statistics, as the Properties panel and scripts read them.
    disp.UpdatePropertyInformation()
    s = ssptest.stats(disp)
    print("statistics read by the client:", s)
    ok.check(s["BuilderUsed"] == "KdTreeCPU", "BuilderUsed is the server's KdTreeCPU (%r)"
             % s["BuilderUsed"])
    ok.check(s["BackendUsed"] == "cpu", "BackendUsed is the server's cpu (%r)" % s["BackendUsed"])
    ok.check(s["NodeCount"] > 0 and s["LeafCount"] > 0 and s["TreeHeight"] > 0,
             "nodes %s, leaves %s, height %s" % (s["NodeCount"], s["LeafCount"], s["TreeHeight"]))
    ok.check(s["FrameCount"] >= 1 and s["BuildCount"] >= 1,
             "frames %s, builds %s" % (s["FrameCount"], s["BuildCount"]))
    ok.check(s["LastRenderSeconds"] > 0 and s["SampleDistanceUsed"] > 0,
             "last frame %.4f s, sample distance %s" % (s["LastRenderSeconds"],
                                                       s["SampleDistanceUsed"]))
    ok.check(0.0 < s["Occupancy"] < 1.0, "occupancy %.3f" % s["Occupancy"])
    # One property at a time (the panel's path) reads the server's value as well.
    sub = disp.SMProxy.GetProperty("NodeCount").GetParent()
    ok.check(sub is not None and sub.GetClassName() == "vtkSMSpaceSkipRepresentationProxy",
             "the representation's proxy is vtkSMSpaceSkipRepresentationProxy (%s)"
             % (sub and sub.GetClassName()))
    if sub is not None:
        sub.UpdatePropertyInformation(sub.GetProperty("NodeCount"))
        ok.check(disp.GetPropertyValue("NodeCount") == s["NodeCount"],
                 "single-property update keeps the server's NodeCount")

    # Another frame and builder: the statistics follow the server.
    frames = s["FrameCount"]
    disp.Builder = "Grid"
    ssptest.render_to(view, "clientserver_grid.png")
    s2 = ssptest.stats(disp)
    ok.check(s2["BuilderUsed"] == "Grid" and s2["FrameCount"] > frames,
             "after a Grid frame: builder %r, frames %s > %s" % (s2["BuilderUsed"],
                                                                 s2["FrameCount"], frames))

    # Blend Mode "Slice" with its Slice Type plane: the Volume's Plane proxy is shared with the
    # server's Space Skipping Volume, so moving it moves our slice there as it moves the stock one.
    disp.Builder = "Naive"
    disp.BlendMode = "Slice"
    c = [(d - 1) / 2.0 for d in ssptest.DIMS]
    shots = []
    for i, (origin, normal) in enumerate([([c[0] + 4.0, c[1] - 3.0, c[2] + 2.0], [0.3, 0.5, 0.81]),
                                          ([c[0] - 9.0, c[1] + 5.0, c[2] - 4.0], [1.0, 0.0, 0.0])]):
        disp.SliceFunction.Origin = origin
        disp.SliceFunction.Normal = normal
        ours = ssptest.read_png(ssptest.render_to(view, "clientserver_slice%d_ss.png" % i))
        disp.SetRepresentationType("Volume")
        stock = ssptest.read_png(ssptest.render_to(view, "clientserver_slice%d_stock.png" % i))
        disp.SetRepresentationType("Space Skipping Volume")
        p = ssptest.psnr(ours, stock)
        ok.check(p >= 40.0 and ssptest.lit_fraction(ours) > 0.1,
                 "slice plane %d on the server matches ParaView's Volume (PSNR %.2f >= 40 dB)"
                 % (i, p))
        shots.append(ours)
    p = ssptest.psnr(shots[0], shots[1])
    ok.check(p < 30.0, "moving the plane moves the server's slice (PSNR %.2f dB)" % p)

    if mpiexec:
        # 2 server ranks: views where one rank's piece leaves the frame (its renderer would cull
        # it), the volume hidden and shown, a zoom. Float compositing vs the 8-bit path.
        disp.BlendMode = "Composite"
        disp.Builder = "Grid"
        # The 8-bit path's own differences off: FXAA smooths each rank's image apart, early ray
        # termination stops a ray in the front piece only (docs/paraview.md, Parallel (MPI)).
        view.UseFXAA = 0
        disp.EarlyRayTermination = 0
        n = servermanager.ActiveConnection.GetNumberOfDataPartitions()
        ok.check(n == 2, "the server runs 2 ranks (%d)" % n)
        cam = view.GetActiveCamera()

        def to_corner(sign):
            # Camera and focal point moved towards a corner of the 64^3 volume, zoomed in: the
            # frame shows that corner and little else.
            ssptest.set_camera(view)
            off = [sign * 0.42 * d for d in ssptest.DIMS]
            view.CameraFocalPoint = [a + b for a, b in zip(view.CameraFocalPoint, off)]
            view.CameraPosition = [a + b for a, b in zip(view.CameraPosition, off)]
            view.GetActiveCamera().Zoom(4.0)
        views = [("whole", lambda: None),
                 ("zoomed in on the low corner", lambda: to_corner(-1)),
                 ("zoomed in on the high corner", lambda: to_corner(1)),
                 ("zoomed and turned", lambda: (ssptest.set_camera(view), cam.Zoom(2.5),
                                                cam.Azimuth(150.0))),
                 ("hidden, then shown", lambda: (Hide(reader, view), Render(view), Show(reader, view)))]
        for i, (what, move) in enumerate(views):
            move()
            t0 = time.time()
            flt = ssptest.read_png(ssptest.render_to(view, "clientserver_mpi%d_float.png" % i))
            seconds = time.time() - t0
            disp.FloatCompositing = 0
            eight = ssptest.read_png(ssptest.render_to(view, "clientserver_mpi%d_8bit.png" % i))
            disp.FloatCompositing = 1
            d = int(abs(flt.astype(int) - eight.astype(int)).max())
            ok.check(seconds < 30.0 and d <= 2,
                     "2 ranks, %s: rendered in %.2f s, float vs 8-bit path max %d/255 (<= 2)"
                     % (what, seconds, d))
    Disconnect()
except Exception as e:  # reported as a failed check; the server goes below
    ok.check(False, "client/server run raised %s: %s" % (type(e).__name__, e))
finally:
    output = stop_server(server)
if mpiexec:
    ok.check("float compositing of the MPI ranks' pieces is off" not in output,
             "the server's ranks never gave up float compositing")
ok.done()
