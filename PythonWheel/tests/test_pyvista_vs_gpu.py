"""The installed `spaceskip` wheel drawn through PyVista against PyVista's own 'gpu' mapper.

    python test_pyvista_vs_gpu.py [OUT_DIR]        (an X display or EGL/OSMesa for the pip vtk)

Runs five_lines.py (the five-line PyVista script of docs/pip.md: spaceskip.pyvista.add_volume on
a wavelet) and checks that its volume was drawn by vtkSpaceSkippingVolumeMapper; then draws the
same scene with PyVista's add_volume(mapper='gpu') (vtkGPUVolumeRayCastMapper) and the volume
property set to linear interpolation, as spaceskip.pyvista sets it (the mapper samples scalar
volumes trilinearly only). Fails unless both images show the volume (over 10 % of the pixels off
the background) and PSNR(ours, gpu) >= 40 dB over RGB, over the whole image and over the pixels
off the background in either (the volume and the scalar bar). Writes ours.png and gpu.png to OUT_DIR.
"""
import os
import runpy
import sys
import tempfile
import warnings

import numpy as np
import pyvista as pv

MIN_PSNR = 40.0
here = os.path.dirname(os.path.abspath(__file__))
out = sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="spaceskip-pyvista-")
os.makedirs(out, exist_ok=True)
ours_png, gpu_png = os.path.join(out, "ours.png"), os.path.join(out, "gpu.png")

# Ours: the five-line script as a user runs it.
argv = sys.argv
sys.argv = ["five_lines.py", ours_png]
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    g = runpy.run_path(os.path.join(here, "five_lines.py"))
sys.argv = argv
for w in caught:
    print("warning:", w.message)
vol = g["vol"]
mapper = vol.GetMapper()
print("five_lines.py: %s drew %s on %s" % (type(vol).__name__, mapper.GetClassName(),
                                           g["pl"].render_window.GetClassName()))
ok = mapper.GetClassName() == "vtkSpaceSkippingVolumeMapper"
ok &= vol.GetProperty().GetInterpolationTypeAsString() == "Linear"

# PyVista's 'gpu' mapper: the same lines with its own mapper, interpolation linear as ours draws.
pl = pv.Plotter(off_screen=True, window_size=(400, 400))
ref = pl.add_volume(pv.Wavelet(extent=(-24, 24) * 3), cmap="viridis", opacity="sigmoid", mapper="gpu")
ref.prop.interpolation_type = "linear"
pl.camera_position = [(90, 60, 75), (0, 0, 0), (0, 0, 1)]
pl.screenshot(gpu_png)
caps = pl.render_window.ReportCapabilities().splitlines()
print("reference: %s; %s" % (ref.GetMapper().GetClassName(),
      "; ".join(l.strip() for l in caps if l.startswith("OpenGL renderer string"))))
ok &= ref.GetMapper().GetClassName() == "vtkOpenGLGPUVolumeRayCastMapper"



def rgb(png):
    img = pv.read(png)
    return np.asarray(img.point_data[img.array_names[0]], dtype=np.float64)[:, :3]


a, b = rgb(ours_png), rgb(gpu_png)


def psnr(x, y):
    mse = np.mean((x - y) ** 2)
    return float("inf") if mse == 0 else 10 * np.log10(255.0 ** 2 / mse)


volume = np.zeros(len(a), dtype=bool)  # pixels where either image shows more than the background
for name, img in (("ours", a), ("gpu", b)):
    off = np.any(np.abs(img - img[0]) > 2, axis=1)  # img[0], a corner pixel: the background
    print("%s: %.1f %% of the pixels off the background" % (name, 100 * np.mean(off)))
    ok &= np.mean(off) > 0.10
    volume |= off
whole, vol_only = psnr(a, b), psnr(a[volume], b[volume])
print("PSNR(ours, gpu) = %.1f dB over the image, %.1f dB over the %.1f %% of pixels off the background "
      "(need >= %.0f for both); max |diff| %d; images in %s" % (
          whole, vol_only, 100 * np.mean(volume), MIN_PSNR, np.max(np.abs(a - b)), out))
ok &= whole >= MIN_PSNR and vol_only >= MIN_PSNR
print("PASS" if ok else "FAIL")
sys.exit(0 if ok else 1)
