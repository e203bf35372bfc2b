"""Time series in ParaView (issue 38): a .pvd of steps whose balls move, played with the animation
scene (stepping AnimationTime over the data's time steps, then Play()), drawn by the Space
Skipping Volume: every frame equals a static render of that step's file (<= 1/255), the frames of
different steps differ (the check can fail), and the representation rebuilt for each step without
Auto measuring afresh (the step keeps the Builder Choice line). Prints the playback's frame times
beside ParaView's own Volume playing the same steps in the same view (a ratio, not a check)."""
import os
import time

import numpy
from paraview.simple import *
import ssptest

ssptest.load_plugin()
ok = ssptest.Checker()

N, STEPS = 48, 5


def step_balls(k):
    # Three balls drifting apart step by step (2 voxels a step at N = 48), a fourth growing.
    d = 0.04 * k
    return ((0.3 - d, 0.35, 0.4, 0.14), (0.7 + d, 0.6, 0.55, 0.12), (0.5, 0.75 - d, 0.3, 0.1),
            (0.5, 0.4, 0.7, 0.05 + 0.02 * k))


paths = []
for k in range(STEPS):
    p = ssptest.temp_path("time_step_%d.vti" % k)
    ssptest.write_sparse_vti(p, N, balls=step_balls(k), tube_radius=0.03)
    paths.append(p)
pvd = ssptest.temp_path("time_series.pvd")
with open(pvd, "w") as f:
    f.write('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n<Collection>\n')
    for k, p in enumerate(paths):
        f.write('<DataSet timestep="%g" file="%s"/>\n' % (0.5 * k, os.path.basename(p)))
    f.write('</Collection>\n</VTKFile>\n')

c = (N - 1) / 2.0


def scene_view():
    view = ssptest.make_view()
    view.CameraFocalPoint = [c, c, c]
    view.CameraPosition = [c + 55.0, c + 35.0, c + 75.0]
    view.CameraViewUp = [0.0, 1.0, 0.0]
    view.CameraViewAngle = 30.0
    return view


def show(source, view, representation="Space Skipping Volume"):
    disp = Show(source, view)
    disp.SetRepresentationType(representation)
    ColorBy(disp, ("POINTS", "density"))
    lut = GetColorTransferFunction("density")
    lut.AutomaticRescaleRangeMode = "Never"
    lut.RGBPoints = [20.0, 0.23, 0.30, 0.75, 140.0, 0.87, 0.87, 0.87, 255.0, 0.71, 0.02, 0.15]
    pwf = GetOpacityTransferFunction("density")
    pwf.Points = [0.0, 0.0, 0.5, 0.0, 20.0, 0.0, 0.5, 0.0, 255.0, 0.5, 0.5, 0.0]
    disp.ScalarOpacityUnitDistance = 2.0
    if representation != "Volume":
        disp.Builder = "Auto"
        disp.Backend = "CPU"
    return disp


# Static renders: each step's file on its own.
static = []
for k, p in enumerate(paths):
    r = XMLImageDataReader(FileName=[p])
    v = scene_view()
    d = show(r, v)
    static.append(ssptest.read_png(ssptest.render_to(v, "time_static_%d.png" % k)))
    Delete(d)
    Delete(r)
    Delete(v)

# Playback: the .pvd through the animation scene.
series = PVDReader(FileName=pvd)
times = list(series.TimestepValues)
ok.check(len(times) == STEPS, "the reader gives %d time steps (%d)" % (STEPS, len(times)))
view = scene_view()
disp = show(series, view)
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
frame_ms = []
choices = []
for k, t in enumerate(times):
    scene.AnimationTime = t
    t0 = time.perf_counter()
    Render(view)
    frame_ms.append(1e3 * (time.perf_counter() - t0))
    img = ssptest.read_png(ssptest.render_to(view, "time_played_%d.png" % k))
    diff = float(numpy.abs(img - static[k]).max())
    ok.check(diff <= 1.0, "step %d (t = %g) played equals its static render (max difference %.0f/255)" % (k, t, diff))
    if k > 0:
        moved = float(numpy.abs(static[k] - static[k - 1]).max())
        ok.check(moved > 40, "step %d differs from step %d (max %.0f/255)" % (k, k - 1, moved))
    choices.append(ssptest.stats(disp)["BuilderChoice"])
print("Builder Choice per step: %s" % choices)
ok.check(not any("measuring" in (ch or "") for ch in choices[1:]),
         "no step after the first shows Auto measuring afresh")

# Play() from the start: the last frame is the last step.
scene.AnimationTime = times[0]
scene.PlayMode = "Snap To TimeSteps"
scene.Play()
last = ssptest.read_png(ssptest.render_to(view, "time_played_last.png"))
diff = float(numpy.abs(last - static[-1]).max())
ok.check(diff <= 1.0, "after Play() the view shows the last step (max difference %.0f/255)" % diff)

# Frame times per step: ours vs ParaView's own Volume on the same steps, same view (printed).
def playback_ms(d):
    ms = []
    for rounds in range(2):
        for t in times:
            scene.AnimationTime = t
            t0 = time.perf_counter()
            Render(view)
            ms.append(1e3 * (time.perf_counter() - t0))
    return sorted(ms)[len(ms) // 2]


ours = playback_ms(disp)
disp.SetRepresentationType("Volume")
stock = playback_ms(disp)
print("playback at %d^3, %d steps: a step %.1f ms (Space Skipping Volume) vs %.1f ms (Volume): %.2fx"
      % (N, STEPS, ours, stock, stock / ours))
ok.done()
