"""Stock volumetric shadows and scattering of ParaView's Volume representation on a Space Skipping
Volume: Volumetric Scattering Blending, Global Illumination Reach and Volume Anisotropy (shared
properties; shading on, ParaView's default light kit) on a float copy of the bundled shell. Turning
scattering on changes the image as it does for ParaView's own Volume, the two representations
agree (PSNR >= 40 dB) with it off and at several settings, and every builder keeps Naive's image
with it on (shadow rays skip empty space losslessly)."""
from paraview.simple import *
import ssptest

ssptest.load_plugin()
ok = ssptest.Checker()
view = ssptest.make_view(size=(140, 140))
# The shadow rays step as the primary rays: both at ParaView's Volume's sample distance.
disp = ssptest.show_float_shell_vs_stock(view, 0.3)
disp.Shade = 1
disp.Ambient = 0.2
disp.Diffuse = 0.7
disp.Specular = 0.3
disp.SpecularPower = 20.0

versus = ssptest.VersusStock(view, disp, ok, "scattering")
shoot, both, changes = versus.shoot, versus.both, versus.changes

disp.VolumetricScatteringBlending = 0.0
off = both("off")
warnings = ssptest.WarningCapture()
disp.VolumetricScatteringBlending = 0.6
disp.GlobalIlluminationReach = 0.5
half = both("blend0.6-reach0.5")
changes("Volumetric Scattering Blending 0.6", off, half)
# Pure scattering, shadow rays across the whole volume, forward scattering (the anisotropy alone
# is checked against vtkGPUVolumeRayCastMapper in TestSpaceSkippingVolumeScatteringVsGPU).
disp.VolumetricScatteringBlending = 2.0
disp.GlobalIlluminationReach = 1.0
disp.VolumeAnisotropy = 0.6
full = both("blend2-reach1-g0.6")
changes("Volumetric Scattering Blending 2, reach 1, Volume Anisotropy 0.6", half, full)
disp.VolumeAnisotropy = 0.0
log = warnings.stop()
ok.check("scatter" not in log.lower(), "no scattering warning while it is drawn (%s)"
         % (log.strip()[:160] or "none"))

# A skipping builder keeps Naive's image with scattering on (their shadow rays skip empty
# bricks; every builder against Naive: Scattering.EveryBuilderEqualsNaive in Core's tests). A
# shorter reach here: the CPU backend casts five shadow rays (the light kit's) per sample.
disp.SetRepresentationType("Space Skipping Volume")
disp.VolumetricScatteringBlending = 1.5
disp.GlobalIlluminationReach = 0.3
ref = ssptest.read_png(ssptest.render_to(view, "scattering_builder_Naive.png"))
ssptest.builders_keep_naive(view, disp, ok, ref, ["Grid"], "scattering", "scattering")
ok.done()
