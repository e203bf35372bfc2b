"""The real GUI: starts `paraview` (PV_PLUGIN_PATH -> the plugin, as a user would install it)
with gui_scene.py, waits for its screenshot, grabs the whole window for the README, closes
paraview, and compares the view with the baseline.
Usage: pvpython test_gui.py PARAVIEW PLUGIN_DIR"""
import json
import os
import subprocess
import sys
import time
import ssptest

paraview, plugin_dir = sys.argv[1], sys.argv[2]
ok = ssptest.Checker()
here = os.path.dirname(os.path.abspath(__file__))
out = os.path.dirname(ssptest.temp_path("x"))
done = os.path.join(out, "gui_done.txt")
for name in ("gui_done.txt", "gui_view.png", "gui_window.png", "gui_first.png", "gui_labels.png"):
    if os.path.exists(os.path.join(out, name)):
        os.remove(os.path.join(out, name))

env = ssptest.launcher_env({"PV_PLUGIN_PATH": plugin_dir,
                            "SPACESKIP_GUI_SCENE": os.path.join(here, "gui_scene.py")})
log = open(os.path.join(out, "gui_paraview.log"), "w")
proc = subprocess.Popen([paraview, "--dr", "--script=" + env["SPACESKIP_GUI_SCENE"]],
                        env=env, stdout=log, stderr=subprocess.STDOUT)
try:
    deadline = time.time() + 150
    while not os.path.exists(done) and time.time() < deadline and proc.poll() is None:
        time.sleep(0.5)
    ok.check(os.path.exists(done), "paraview ran the script (rc %s)" % proc.poll())
    result = {}
    if os.path.exists(done):
        time.sleep(1.0)
        with open(done) as f:
            result = json.load(f)
        print("GUI result:", result)
        time.sleep(4.0)  # let the GUI paint its panels before the window grab
        try:
            from PIL import ImageGrab
            shot = ImageGrab.grab(xdisplay=os.environ.get("DISPLAY"))
            box = shot.convert("L").getbbox()  # the paraview window on the black screen
            (shot.crop(box) if box else shot).save(os.path.join(out, "gui_window.png"))
        except Exception as e:  # the grab is for documentation only
            print("note: no window grab (%s)" % e)
finally:
    proc.terminate()
    try:
        proc.wait(timeout=20)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
    log.close()

if not result:
    with open(os.path.join(out, "gui_paraview.log")) as f:
        print("paraview output (tail):\n" + f.read()[-3000:])
ok.check("error" not in result, "the GUI script succeeded %s" % result.get("error", ""))
ok.check(result.get("representation") == "Space Skipping Volume",
         "the GUI offers and uses 'Space Skipping Volume' (%s)" % result.get("representation"))
ok.check(result.get("groups_shown") == {"Volume Rendering": True, "Cropping Parameters": True},
         "the GUI's panel lists the stock Volume Rendering and cropping groups for Space Skipping "
         "Volume (%s)" % result.get("groups_shown"))
stats = result.get("stats", {})
ok.check(stats.get("FrameCount", 0) >= 1 and stats.get("BuildCount", 0) >= 1,
         "the mapper drew in the GUI (%s frames, %s builds)" % (stats.get("FrameCount"),
                                                                stats.get("BuildCount")))
# First contact: the representation chosen on a fresh display draws at once (the colour array
# picked as for ParaView's Volume) and the statistics panel is filled after the first render.
# The frames drawn in the GUI's own window (not only SaveScreenshot's): the mapper's progress
# events run Qt's event loop mid-frame, which paints behind VTK's GL state cache; a frame that did
# not put the window's GL state back drew nothing in the view (ParaView, with its VTK's OpenGL
# error reporting, logs "Error in cache state" and "OpenGL errors detected" then).
with open(os.path.join(out, "gui_paraview.log"), errors="replace") as f:
    gl_log = f.read()
gl_errors = [l for l in gl_log.splitlines() if "Error in cache state" in l or "OpenGL errors detected" in l]
ok.check(not gl_errors, "no GL state errors in the GUI's window (%d: %s)" % (len(gl_errors), gl_errors[:2]))
first = result.get("first", {})
fstats = first.get("stats", {})
ok.check(first.get("color_array", ["", ""])[1] == ssptest.ARRAY,
         "choosing the representation picks the colour array (%s)" % first.get("color_array"))
ok.check(fstats.get("FrameCount", 0) >= 1 and fstats.get("BuilderUsed") not in (None, "", "none")
         and fstats.get("LastRenderSeconds", 0) > 0 and 0 < fstats.get("Occupancy", 0) <= 1,
         "the statistics panel is filled after the first render, without asking (%s)" % fstats)
first_png = os.path.join(out, "gui_first.png")
if os.path.exists(first_png):
    a = ssptest.read_png(first_png)
    # ParaView's default background (not black here): pixels that differ from the corner's.
    lit = float((abs(a - a[0, 0]).max(axis=2) > 8).mean())
    ok.check(lit > 0.02, "the view is not empty right after choosing the representation (%.1f%% lit)"
             % (100 * lit))
else:
    ok.check(False, "the GUI saved no first-contact screenshot")
# A segmentation with a categorical colour map: the label-map mode, every pixel the background or
# a label's colour, the hidden label absent.
labels = result.get("labels", {})
ok.check(labels.get("label_map_used") == 1 and labels.get("hidden") == [9],
         "a categorical colour map on a label array draws a label map in the GUI (%s)" % labels)
labels_png = os.path.join(out, "gui_labels.png")
if os.path.exists(labels_png):
    import numpy
    a = ssptest.read_png(labels_png)
    shown = [ssptest.LABEL_COLOURS[i] for i in (1, 2, 5)]
    bad = ssptest.unexplained_colours(a, shown, background=tuple(a[0, 0]))
    nine = int((numpy.abs(a - numpy.round(numpy.array(ssptest.LABEL_COLOURS[9]) * 255.0)) <= 2).all(axis=2).sum())
    lit = ssptest.lit_fraction(abs(a - a[0, 0]))
    ok.check(lit > 0.02 and bad == 0 and nine == 0,
             "the GUI's label map: %.1f%% lit, %d pixels of no shown label's colour, %d of the hidden one"
             % (100 * lit, bad, nine))
else:
    ok.check(False, "the GUI saved no label screenshot")
view_png = os.path.join(out, "gui_view.png")
if os.path.exists(view_png):
    a = ssptest.read_png(view_png)
    ok.check(ssptest.lit_fraction(a) > 0.05, "the GUI view shows the volume (%.1f%% lit)"
             % (100 * ssptest.lit_fraction(a)))
    try:
        ssptest.compare_to_baseline(view_png, "SpaceSkipGUI.png", 40.0)
        ok.check(True, "GUI screenshot matches its baseline")
    except AssertionError as e:
        ok.check(False, str(e))
else:
    ok.check(False, "the GUI saved no screenshot")
ok.done()
