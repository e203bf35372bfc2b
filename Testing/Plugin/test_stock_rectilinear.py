"""A vtkRectilinearGrid source: Space Skipping Volume is offered for it (ParaView puts rectilinear
grids in the image representation) and draws a uniformly spaced grid exactly as the image of the
same points, and as ParaView's own Volume draws that image (PSNR). ParaView's own Volume on the
grid itself is printed (VTK's GPU mapper samples a grid through its coordinates and differs from
its own image of the same points). A non-uniform grid is drawn through its coordinates (AxisWarp:
trilinear within the grid's cells, nothing resampled); printed against ParaView's Volume on it."""
from paraview.simple import *
import ssptest

ssptest.load_plugin()
ok = ssptest.Checker()
reader = ssptest.open_data()
reader.UpdatePipeline()
image = reader.GetClientSideObject().GetOutputDataObject(0)
view = ssptest.make_view()


def grid_source(name, coord):
    """The shell's points as a vtkRectilinearGrid, coordinate i of each axis at coord(i)."""
    from vtkmodules.vtkCommonCore import vtkDoubleArray
    from vtkmodules.vtkCommonDataModel import vtkRectilinearGrid
    grid = vtkRectilinearGrid()
    grid.SetExtent(image.GetExtent())
    axes = []
    for a in range(3):
        c = vtkDoubleArray()
        for i in range(ssptest.DIMS[a]):
            c.InsertNextValue(coord(a, i))
        axes.append(c)
    grid.SetXCoordinates(axes[0])
    grid.SetYCoordinates(axes[1])
    grid.SetZCoordinates(axes[2])
    grid.GetPointData().ShallowCopy(image.GetPointData())
    src = TrivialProducer(registrationName=name)
    src.GetClientSideObject().SetOutput(grid)
    src.UpdatePipeline()
    return src


def shots(source, tag):
    disp = Show(source, view)
    out = {}
    for rep in ["Space Skipping Volume", "Volume"]:
        disp.SetRepresentationType(rep)
        ColorBy(disp, ("POINTS", ssptest.ARRAY))
        ssptest.set_transfer_functions()
        disp.ScalarOpacityUnitDistance = 4.0
        if rep == "Space Skipping Volume":
            disp.Builder = "Naive"
            disp.Backend = "CPU"
        ssptest.set_camera(view)
        out[rep] = ssptest.read_png(ssptest.render_to(view, "rect_%s_%s.png" % (tag, rep.replace(" ", "_"))))
    types = disp.GetProperty("Representation").Available
    Hide(source, view)
    return out, types


OURS, STOCK = "Space Skipping Volume", "Volume"
img, _ = shots(reader, "image")
uniform, types = shots(grid_source("uniform", lambda a, i: float(i)), "uniform")
ok.check(OURS in types, "Space Skipping Volume is offered for a rectilinear grid")
p = ssptest.psnr(uniform[OURS], img[OURS])
ok.check(p >= 60.0 and ssptest.lit_fraction(uniform[OURS]) > 0.01,
         "uniform grid: ours draws the image's picture (PSNR %.2f dB >= 60)" % p)
p = ssptest.psnr(uniform[OURS], img[STOCK])
ok.check(p >= 40.0, "uniform grid: ours vs ParaView's Volume on the image (PSNR %.2f >= 40 dB)" % p)
print("ParaView's Volume: grid vs image of the same points %.2f dB; ours vs it on the grid %.2f dB"
      % (ssptest.psnr(uniform[STOCK], img[STOCK]), ssptest.psnr(uniform[OURS], uniform[STOCK])))

n = ssptest.DIMS[0] - 1
capture = ssptest.WarningCapture()
stretched, _ = shots(grid_source("stretched", lambda a, i: n * (0.5 * i / n + 0.5 * (i / n) ** 2)
                                 if a == 0 else float(i)), "stretched")
said = capture.stop()
lit = ssptest.lit_fraction(stretched[OURS])
ok.check(lit > 0.01, "non-uniform grid: drawn through its coordinates (%.3f lit)" % lit)
ok.check("resampled" not in said, "non-uniform grid: not resampled (no warning)")
print("non-uniform grid: ours (through the coordinates) vs ParaView's Volume on the grid %.2f dB"
      % ssptest.psnr(stretched[OURS], stretched[STOCK]))
ok.done()
