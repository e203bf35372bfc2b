"""SpaceSkip demo: loads the plugin in pvbatch, renders the bundled MNI152 brain (real MRI data)
with the "Space Skipping Volume" representation for several builders, and prints build and render
timings as the mapper measured them. Usage: pvbatch demo_pvbatch.py PLUGIN.so DATA_DIR OUT_DIR"""
import os
import sys
import time

from paraview import simple

plugin, data, out = sys.argv[1:4]
os.makedirs(out, exist_ok=True)
simple.LoadPlugin(plugin, remote=False, ns=vars(simple))

reader = simple.ImageReader(FileNames=[os.path.join(data, "mni152_t1_99x117x95_uint8.raw")])
reader.DataScalarType = "unsigned char"
reader.DataExtent = [0, 98, 0, 116, 0, 94]
reader.DataSpacing = [2.0, 2.0, 2.0]

view = simple.CreateView("RenderView")
view.ViewSize = [512, 512]
view.OrientationAxesVisibility = 0
view.Background = [0.08, 0.08, 0.1]
if hasattr(view, "UseColorPaletteForBackground"):
    view.UseColorPaletteForBackground = 0
rep = simple.Show(reader, view)
rep.SetRepresentationType("Space Skipping Volume")
simple.ColorBy(rep, ("POINTS", "ImageFile"))
lut = simple.GetColorTransferFunction("ImageFile")
lut.ApplyPreset("Cool to Warm", True)
pwf = simple.GetOpacityTransferFunction("ImageFile")
pwf.Points = [0, 0, 0.5, 0, 60, 0, 0.5, 0, 140, 0.15, 0.5, 0, 243, 0.8, 0.5, 0]
rep.EarlyRayTermination = 0  # the paper's protocol

view.CameraPosition = [450, -420, 220]
view.CameraFocalPoint = [98, 116, 94]
view.CameraViewUp = [0, 0, 1]
simple.ResetCamera(view)
simple.GetActiveCamera().Dolly(1.6)

print("%-14s %-8s %10s %10s %8s %8s %12s" % ("builder", "backend", "build_ms", "frame_ms", "nodes", "height", "wall_fps"))
for builder in ["Naive", "Grid", "DistanceGrid", "LBVH", "KdTreeCPU", "KdTreeGPUFast", "Hybrid"]:
    rep.Builder = builder
    simple.Render(view)  # builds the hierarchy
    frames, t0 = 3, time.perf_counter()
    for i in range(frames):
        cam = simple.GetActiveCamera()
        cam.Azimuth(120)
        simple.Render(view)
    wall = (time.perf_counter() - t0) / frames
    rep.UpdatePropertyInformation()
    print("%-14s %-8s %10.3f %10.2f %8d %8d %12.1f" % (
        rep.GetPropertyValue("BuilderUsed"), rep.GetPropertyValue("BackendUsed"),
        1e3 * rep.GetPropertyValue("LastBuildSeconds"), 1e3 * rep.GetPropertyValue("LastRenderSeconds"),
        rep.GetPropertyValue("NodeCount"), rep.GetPropertyValue("TreeHeight"), 1.0 / wall))
    sys.stdout.flush()
simple.SaveScreenshot(os.path.join(out, "mni152_paraview.png"), view, ImageResolution=[512, 512])
print("screenshot:", os.path.join(out, "mni152_paraview.png"))
