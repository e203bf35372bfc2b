"""The stock Shade (with Ambient/Diffuse/Specular/SpecularPower), BlendMode and IsosurfaceValues
properties reach the Space Skipping Volume: switching each changes the image as it does for
ParaView's own Volume representation, and the two representations agree (PSNR) in each state.
The view keeps only its headlight (light kit off): the mapper shades with one light."""
from paraview.simple import *
import ssptest

ssptest.load_plugin()
ok = ssptest.Checker()

reader, view, disp = ssptest.make_scene(builder="KdTreeCPU", backend="CPU")
view.UseLight = 0  # no light kit ...
headlight = AddLight(view=view)  # ... one headlight, as a plain VTK renderer has
headlight.Coords = "Headlight"

states = [
    ("composite", dict(Shade=0, BlendMode="Composite")),
    ("shade", dict(Shade=1, Ambient=0.2, Diffuse=0.7, Specular=0.4, SpecularPower=20.0,
                   BlendMode="Composite")),
    ("isosurface", dict(Shade=0, BlendMode="Isosurface", IsosurfaceValues=[90.0, 160.0])),
    ("isosurface-shade", dict(Shade=1, BlendMode="Isosurface", IsosurfaceValues=[90.0, 160.0])),
]
images = {}
for name, props in states:
    for kind in ("Space Skipping Volume", "Volume"):
        disp.SetRepresentationType(kind)
        for k, v in props.items():
            setattr(disp, k, v)
        tag = "ss" if kind != "Volume" else "stock"
        images[(name, tag)] = ssptest.read_png(ssptest.render_to(view, "modes_%s_%s.png" % (name, tag)))
    ours, stock = images[(name, "ss")], images[(name, "stock")]
    lit = ssptest.lit_fraction(ours)
    p = ssptest.psnr(ours, stock)
    print("%s: lit %.3f, PSNR Space Skipping Volume vs Volume %.2f dB" % (name, lit, p))
    ok.check(lit > 0.02, "%s draws something (%.1f%% of the pixels)" % (name, 100 * lit))
    ok.check(p >= 40.0, "%s: matches ParaView's Volume (PSNR %.2f >= 40 dB)" % (name, p))
    if name != "composite":
        change = ssptest.psnr(ours, images[("composite", "ss")])
        stock_change = ssptest.psnr(stock, images[("composite", "stock")])
        print("  vs composite: ours %.2f dB, ParaView's Volume %.2f dB" % (change, stock_change))
        ok.check(change < 30.0 and stock_change < 30.0,
                 "%s changes the image (PSNR to composite: ours %.1f, stock %.1f dB)"
                 % (name, change, stock_change))

# The modes 5.11's Blend Mode menu lacks: Extra Blend Mode on ours; on ParaView's Volume the same
# vtkVolumeMapper blend mode set on its representation object directly (builtin session), since
# its proxy's domain has no such entry.
for k, v in states[0][1].items():
    setattr(disp, k, v)
extra = [("mip", "Maximum Intensity", 1), ("minip", "Minimum Intensity", 2),
         ("average", "Average Intensity", 3), ("additive", "Additive", 4)]
for name, text, mode in extra:
    # MinIP: the shell's rays all reach its empty (0) outside, so give 0 some opacity.
    ssptest.set_transfer_functions(
        opacity_points=[0.0, 0.5, 0.5, 0.0, 40.0, 0.1, 0.5, 0.0, 255.0, 0.35, 0.5, 0.0]
        if name == "minip" else None)
    disp.SetRepresentationType("Space Skipping Volume")
    disp.ExtraBlendMode = text
    ours = ssptest.read_png(ssptest.render_to(view, "modes_%s_ss.png" % name))
    disp.ExtraBlendMode = "As Blend Mode"
    disp.SetRepresentationType("Volume")
    stock_rep = disp.GetClientSideObject().GetActiveRepresentation()
    stock_rep.SetBlendMode(mode)
    stock = ssptest.read_png(ssptest.render_to(view, "modes_%s_stock.png" % name))
    stock_rep.SetBlendMode(0)
    p = ssptest.psnr(ours, stock)
    change = ssptest.psnr(ours, images[("composite", "ss")])
    print("%s: lit %.3f, PSNR vs ParaView's Volume %.2f dB, vs composite %.2f dB"
          % (name, ssptest.lit_fraction(ours), p, change))
    ok.check(ssptest.lit_fraction(ours) > 0.02, "%s draws something" % name)
    ok.check(change < 30.0, "%s changes the image (PSNR to composite %.1f dB)" % (name, change))
    ok.check(p >= 40.0, "%s: matches ParaView's Volume with the same blend mode (PSNR %.2f >= 40 dB)"
             % (name, p))
ok.done()
