"""What a pvbatch/pvpython run on the GPU machine actually uses (bench/device/run-pv.sh): ParaView's
version, the render window's GL vendor/renderer, and the backend and builder 'Space Skipping Volume'
used for a small sparse volume, beside the stock 'Volume' in the same window.

  pvbatch --no-mpi bench/device/pv-probe.py PLUGIN
"""
import sys

from paraview import simple
from paraview import servermanager

simple.LoadPlugin(sys.argv[1], remote=False, ns=vars(simple))
print("ParaView", servermanager.vtkSMProxyManager.GetParaViewSourceVersion())
src = simple.Wavelet(WholeExtent=[-32, 31, -32, 31, -32, 31])
view = simple.CreateView("RenderView")
view.ViewSize = [256, 256]
disp = simple.Show(src, view)
disp.SetRepresentationType("Space Skipping Volume")
simple.ColorBy(disp, ("POINTS", "RTData"))
view.ResetCamera()
simple.Render(view)
disp.UpdatePropertyInformation()
print("ours: backend %s, builder %s" % (disp.GetPropertyValue("BackendUsed"), disp.GetPropertyValue("BuilderUsed")))
for line in view.GetRenderWindow().ReportCapabilities().splitlines():
    if line.startswith(("OpenGL vendor", "OpenGL renderer", "OpenGL version")):
        print(line.replace("OpenGL vendor string", "GL_VENDOR").replace("OpenGL renderer string", "GL_RENDERER"))
disp.SetRepresentationType("Volume")
simple.Render(view)
print("stock Volume drew in the same window")
