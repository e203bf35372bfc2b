"""Stock properties of ParaView's Volume representation on a Space Skipping Volume: shading with
the render view's light kit (UseLight, ParaView's default) against its headlight alone, and Blend
Mode "Slice" with its Slice Type plane (SliceFunction) moved and turned. Each switch or move changes
the image as it does for ParaView's own Volume, and the two representations agree (PSNR >= 40 dB)
at every setting; every builder keeps Naive's slice and light-kit images."""
from paraview.simple import *
import ssptest

ssptest.load_plugin()
ok = ssptest.Checker()
reader, view, disp = ssptest.make_scene(builder="Naive", backend="CPU", size=(240, 240))
view.UseLight = 1  # ParaView's default: the light kit
headlight = AddLight(view=view)
headlight.Coords = "Headlight"
headlight.Enable = 0
c = [(d - 1) / 2.0 for d in ssptest.DIMS]


def set_lighting(kit):
    """The light kit, or (kit False) one headlight of intensity 1, as a plain VTK renderer has."""
    view.UseLight = 1 if kit else 0
    headlight.Enable = 0 if kit else 1


versus = ssptest.VersusStock(view, disp, ok, "slicelights")
shoot, both, changes = versus.shoot, versus.both, versus.changes


def lit_enough(a, fraction):
    return ssptest.lit_fraction(a) > fraction




disp.Shade = 0
disp.BlendMode = "Composite"
composite = both("composite")
# The Properties panel shows the stock Volume Rendering group (Blend Mode, Slice Type, Shade, Use
# Cropping) and the cropping box for our representation too (ParaView 5.11 names only "Volume").
shown = ssptest.groups_shown_for(disp)
ok.check(shown == {"Volume Rendering": True, "Cropping Parameters": True},
         "the panel's stock volume groups are shown for Space Skipping Volume (%s)" % shown)

# Shading with the light kit and with the headlight alone.
disp.Shade = 1
disp.Ambient = 0.2
disp.Diffuse = 0.7
disp.Specular = 0.4
disp.SpecularPower = 20.0
set_lighting(True)
kit = both("shade-lightkit")
changes("Shade with the light kit", composite, kit)
set_lighting(False)
head = both("shade-headlight")
changes("light kit vs headlight", kit, head, max_psnr=35.0)
set_lighting(True)

# Slice: ParaView 5.11's Slice Type plane (SliceFunction, a Plane proxy of the implicit_functions
# group that the Volume representation exposes) set and moved the way a user does it; the Space
# Skipping Volume shares the very same plane, so each position matches ParaView's Volume and each
# move changes both images alike. No "no slice function" warning may come while a plane is set;
# without one, ours warns once and slices through the centre.
disp.Shade = 0
disp.BlendMode = "Slice"
ssptest.set_transfer_functions(
    opacity_points=[0.0, 0.3, 0.5, 0.0, 40.0, 0.5, 0.5, 0.0, 255.0, 1.0, 0.5, 0.0])
warnings = ssptest.WarningCapture()
disp.SliceFunction = "Plane"
disp.SliceFunction.Origin = [c[0] + 4.0, c[1] - 3.0, c[2] + 2.0]
disp.SliceFunction.Normal = [0.3, 0.5, 0.81]
sliced = both("slice")
ok.check(lit_enough(sliced[0], 0.1), "Blend Mode Slice draws a slice (%.1f%% lit)"
         % (100 * ssptest.lit_fraction(sliced[0])))
changes("Blend Mode Slice", composite, sliced)
disp.SliceFunction.Origin = [c[0] - 9.0, c[1] + 5.0, c[2] - 4.0]  # off centre
moved = both("slice-moved")
changes("moving the plane's origin", sliced, moved)
disp.SliceFunction.Normal = [1.0, 0.0, 0.0]
turned = both("slice-turned")
changes("turning the plane's normal", moved, turned)
disp.Shade = 1
sliced_kit = (shoot("slice-shade-lightkit", "Space Skipping Volume"),
              shoot("slice-shade-lightkit", "Volume"))
disp.SetRepresentationType("Space Skipping Volume")
changes("Shade with the light kit on the slice", turned, sliced_kit, max_psnr=35.0)
# Shaded slices against ParaView's Volume on a float copy of the shell. With the 8-bit shell,
# Mesa's llvmpipe filters the stock Volume's unorm8 texture in whole 1/255 steps: where the shell
# fades to 0 its gradient rounds to zero and the stock draws black where ours is lit (35-37 dB, the
# stock side black at every pixel that differs by more than 20/255); with float data both agree.
uint8_psnr = ssptest.psnr(sliced_kit[0], sliced_kit[1])
print("shaded slice, 8-bit shell: PSNR Space Skipping Volume vs Volume %.2f dB (llvmpipe's 8-bit "
      "texture filtering, see above)" % uint8_psnr)
ok.check(uint8_psnr >= 30.0, "shaded slice on the 8-bit shell close to ParaView's Volume "
         "(PSNR %.2f >= 30 dB)" % uint8_psnr)
as_float = Calculator(Input=reader, AttributeType="Point Data", ResultArrayName=ssptest.ARRAY,
                      Function="%s*1.0" % ssptest.ARRAY, ResultArrayType="Float")
Hide(reader, view)
float_disp = ssptest.show_space_skipping(as_float, view, builder="Naive", backend="CPU")
ssptest.set_transfer_functions(
    opacity_points=[0.0, 0.3, 0.5, 0.0, 40.0, 0.5, 0.5, 0.0, 255.0, 1.0, 0.5, 0.0])
for name in ["Shade", "Ambient", "Diffuse", "Specular", "SpecularPower", "BlendMode"]:
    setattr(float_disp, name, getattr(disp, name))
float_disp.SliceFunction = "Plane"
for tag, origin, normal in [("float-slice-shade", [c[0] + 4.0, c[1] - 3.0, c[2] + 2.0],
                             [0.3, 0.5, 0.81]),
                            ("float-slice-shade-moved", [c[0] - 9.0, c[1] + 5.0, c[2] - 4.0],
                             [1.0, 0.0, 0.0])]:
    float_disp.SliceFunction.Origin = origin
    float_disp.SliceFunction.Normal = normal
    float_disp.SetRepresentationType("Space Skipping Volume")
    a = ssptest.read_png(ssptest.render_to(view, "slicelights_%s_ss.png" % tag))
    float_disp.SetRepresentationType("Volume")
    b = ssptest.read_png(ssptest.render_to(view, "slicelights_%s_stock.png" % tag))
    p = ssptest.psnr(a, b)
    print("%s: PSNR Space Skipping Volume vs Volume %.2f dB" % (tag, p))
    ok.check(p >= 40.0 and ssptest.lit_fraction(a) > 0.1,
             "%s: matches ParaView's Volume (PSNR %.2f >= 40 dB)" % (tag, p))
Hide(as_float, view)
Show(reader, view)
disp.SetRepresentationType("Space Skipping Volume")
log = warnings.stop()
ok.check("slice function" not in log and "centre of the volume" not in log,
         "with a plane set, no slice-function warning (%s)" % (log.strip()[:160] or "none"))
# Our property holds the Volume's Plane proxy itself (not a copy): the GUI's Slice Type widget and
# rep.SliceFunction edit the one plane.
ours_prop = disp.SMProxy.GetProperty("Builder").GetParent().GetProperty("SliceFunction")
ok.check(ours_prop.GetNumberOfProxies() == 1 and ours_prop.GetProxy(0) is not None and
         ours_prop.GetProxy(0).GetGlobalID() == disp.SliceFunction.SMProxy.GetGlobalID(),
         "the Space Skipping Volume's SliceFunction is the Volume's Plane proxy")
# No plane at all: one clear warning, the centre plane (normal z) as a fallback, no crash.
warnings = ssptest.WarningCapture()
plane_proxy = disp.SliceFunction
disp.SliceFunction = None
ssptest.render_to(view, "slicelights_noplane_ss.png")
ssptest.render_to(view, "slicelights_noplane_ss2.png")
log = warnings.stop()
ok.check(log.count("no slice function") == 1,
         "without a plane: one warning naming the missing slice function (%s)" % log.strip()[:200])
disp.SliceFunction = plane_proxy
for name in ["Grid", "KdTreeCPU", "LBVH", "DistanceGrid", "Hybrid"]:
    disp.Builder = name
    p = ssptest.psnr(sliced_kit[0], ssptest.read_png(ssptest.render_to(view, "slicelights_%s.png" % name)))
    ok.check(p >= 50.0, "%s keeps Naive's shaded slice (PSNR %.2f dB)" % (name, p))
disp.BlendMode = "Composite"
ssptest.set_transfer_functions()
for name in ["Grid", "KdTreeCPU", "DistanceGrid"]:
    disp.Builder = name
    p = ssptest.psnr(kit[0], ssptest.read_png(ssptest.render_to(view, "slicelights_kit_%s.png" % name)))
    ok.check(p >= 50.0, "%s keeps Naive's light-kit image (PSNR %.2f dB)" % (name, p))

# A saved state brings the plane back to the Space Skipping Volume (its SliceFunction refers to the
# Volume's Plane proxy, saved with the display).
disp.Builder = "Naive"
disp.BlendMode = "Slice"
disp.SliceFunction.Origin = [c[0] - 9.0, c[1] + 5.0, c[2] - 4.0]
disp.SliceFunction.Normal = [0.3, 0.5, 0.81]
before = ssptest.read_png(ssptest.render_to(view, "slicelights_state_before.png"))
state = ssptest.temp_path("slicelights_state.pvsm")
SaveState(state)
ResetSession()
ssptest.load_plugin()
warnings = ssptest.WarningCapture()
LoadState(state)
view = GetActiveViewOrCreate("RenderView")
disp = GetDisplayProperties(FindSource("ImageReader1"), view)
after = ssptest.read_png(ssptest.render_to(view, "slicelights_state_after.png"))
log = warnings.stop()
p = ssptest.psnr(before, after)
ok.check(disp.Representation == "Space Skipping Volume" and p >= 50.0 and "slice" not in log,
         "state saved and loaded: same slice (PSNR %.2f dB), no slice warning (%s)"
         % (p, log.strip()[:160] or "none"))
ok.done()
