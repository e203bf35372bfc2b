"""Renders a scene to argv[1]; run by pvbatch serially and under mpiexec (test_parallel.py).
Usage: pvbatch parallel_scene.py OUT.png [builder] [scene]
  builder: a Space Skipping Volume builder (Grid, KdTreeCPU, ...), or "stock" for ParaView's own
           Volume representation on the same scene (for comparisons)
  scene:   "mni" (default: the bundled MNI152 T1 head, 99x117x95, 2 mm voxels, an origin off
           zero, oblique camera, a translucent transfer function that shows the tissue along the
           planes where the pieces meet), "shell" (the plugin tests' 64^3 reference scene) or
           "vtpd=PATH" (the MNI scene read from a partitioned data set file: its partitions go
           to the ranks as they are), "rect" (the MNI scene, each piece as the
           vtkRectilinearGrid of its points), "rectnu" (the same with non-uniform coordinates; drawn serially through
           its coordinates, its pieces under MPI resampled on the whole grid's lattice), "raw16=PATH" (the MNI head as 16-bit CT-like values,
           v * 12 + 24, read from a little-endian raw file by ParaView's Image Reader as a new
           user would: 'unsigned short', DataByteOrder, DataExtent), "vti=PATH" (the same 16-bit
           head from a .vti file, XML Image Data Reader). With raw16 and vti the view keeps
           ParaView's default FXAA (on), as a new user's does.
           With SPACESKIP_PARALLEL_SECOND=1 the MNI scenes are drawn through a 2-D transfer
           function whose y axis is a second array, the point's y coordinate (Use Transfer 2D,
           Use Gradient For Transfer 2D off, Color Array 2): under MPI each piece or partition
           holds part of that array's range.
Prints how the data was distributed (the ranks that hold a piece of the volume)."""
import os
import sys
from paraview.simple import *
import ssptest

out = sys.argv[1]
builder = sys.argv[2] if len(sys.argv) > 2 else "Grid"
scene = sys.argv[3] if len(sys.argv) > 3 else "mni"
second = bool(os.environ.get("SPACESKIP_PARALLEL_SECOND"))


def progress(what):
    print("SPACESKIP_PARALLEL step: " + what)
    sys.stdout.flush()


# scene "rect": each rank's image piece as the vtkRectilinearGrid of its points.
RECT_INFO = """
executive = self.GetExecutive()
inInfo = executive.GetInputInformation(0, 0)
outInfo = executive.GetOutputInformation(0)
outInfo.Set(executive.WHOLE_EXTENT(), inInfo.Get(executive.WHOLE_EXTENT()), 6)
"""
RECT_SCRIPT = """
from vtkmodules.vtkCommonCore import vtkDoubleArray
inp = self.GetInput()
out = self.GetOutput()
ext = inp.GetExtent()
out.SetExtent(ext)
setters = [out.SetXCoordinates, out.SetYCoordinates, out.SetZCoordinates]
import math
for a in range(3):
    c = vtkDoubleArray()
    for i in range(ext[2 * a], ext[2 * a + 1] + 1):
        c.InsertNextValue(inp.GetOrigin()[a] + (i + WARP * math.sin(0.37 * i)) * inp.GetSpacing()[a])
    setters[a](c)
out.GetPointData().ShallowCopy(inp.GetPointData())
out.GetCellData().ShallowCopy(inp.GetCellData())
"""

ssptest.load_plugin()
stock = builder == "stock" or bool(os.environ.get("SPACESKIP_STOCK_VOLUME"))
opaque = bool(os.environ.get("SPACESKIP_PARALLEL_OPAQUE"))
if scene == "shell":
    reader, view, disp = ssptest.make_scene(builder="Grid" if stock else builder, backend="CPU")
else:
    if scene.startswith("vtpd="):
        reader = XMLPartitionedDatasetReader(FileName=[scene[5:]])
    elif scene.startswith("raw16="):
        reader = ImageReader(FileNames=[scene[6:]])
        reader.DataScalarType = "unsigned short"
        reader.DataByteOrder = "LittleEndian"
        reader.DataExtent = [0, 98, 0, 116, 0, 94]
        reader.DataSpacing = [2.0, 2.0, 2.0]
        reader.DataOrigin = [-98.0, -134.0, -72.0]
    elif scene.startswith("vti="):
        reader = XMLImageDataReader(FileName=[scene[4:]])
    else:
        reader = ImageReader(FileNames=[os.path.join(ssptest.env("SPACESKIP_DATA"),
                                                     "mni152_t1_99x117x95_uint8.raw")])
        reader.DataScalarType = "unsigned char"
        reader.DataExtent = [0, 98, 0, 116, 0, 94]
        reader.DataSpacing = [2.0, 2.0, 2.0]
        reader.DataOrigin = [-98.0, -134.0, -72.0]
    if second:
        # A second point array, the point's y coordinate, for the 2-D function's y axis.
        reader = Calculator(Input=reader, AttributeType="Point Data", ResultArrayName="second",
                            Function="coordsY", ResultArrayType="Float")
    if scene in ("rect", "rectnu"):
        # The same head as a vtkRectilinearGrid of the same points, per rank's piece; "rectnu"
        # moves point i of each axis by 1.5 sin(0.37 i) of a step (steps 0.45..1.55 of the
        # image's: non-uniform, resampled by the mapper on the whole grid's lattice, which the
        # 4x cap on its points coarsens to 156 x 185 x 152).
        image_reader = reader
        reader = ProgrammableFilter(Input=image_reader)
        reader.OutputDataSetType = "vtkRectilinearGrid"
        reader.RequestInformationScript = RECT_INFO
        reader.Script = "WARP = %g\n" % (1.5 if scene == "rectnu" else 0.0) + RECT_SCRIPT
    view = ssptest.make_view((360, 360))
    disp = Show(reader, view)
    disp.SetRepresentationType("Space Skipping Volume")
    ColorBy(disp, ("POINTS", ssptest.ARRAY))
    # Skin and bone faint, grey and white matter stronger: the cut planes between the pieces run
    # through every kind of tissue, seen obliquely.
    # The 16-bit scenes hold v * 12 + 24 of the 8-bit head: the same functions over those values.
    ct = scene.startswith(("raw16=", "vti="))

    def hu(points):
        return [v * 12.0 + 24.0 if ct and i % 4 == 0 else v for i, v in enumerate(points)]
    ssptest.set_transfer_functions(
        lut_points=hu([0.0, 0.05, 0.05, 0.2, 70.0, 0.85, 0.45, 0.2, 140.0, 0.95, 0.9, 0.75,
                       243.0, 1.0, 1.0, 1.0]),
        # Opaque: tissue from value 60 up saturates most rays within a few voxels, in the front
        # piece where the pieces overlap along the ray (early ray termination decides there).
        opacity_points=hu([0.0, 0.0, 0.5, 0.0, 30.0, 0.0, 0.5, 0.0, 60.0, 0.4, 0.5, 0.0,
                           243.0, 1.0, 0.5, 0.0] if opaque else
                          [0.0, 0.0, 0.5, 0.0, 30.0, 0.0, 0.5, 0.0, 80.0, 0.03, 0.5, 0.0,
                           160.0, 0.12, 0.5, 0.0, 243.0, 0.3, 0.5, 0.0]))
    disp.ScalarOpacityUnitDistance = 2.0 if opaque else 10.0
    if second:
        # One box over values 30..243 and the middle 40 % of the second array's whole range
        # (the data information's range: all ranks' pieces), which the cut between 2 ranks'
        # pieces (along y) runs through.
        ylo, yhi = reader.PointData["second"].GetRange()
        tf2d = GetTransferFunction2D(ssptest.ARRAY)
        tf2d.AutomaticRescaleRangeMode = "Never"
        tf2d.Range = [0.0, 243.0, ylo, yhi]
        tf2d.Boxes = [30.0, ylo + 0.3 * (yhi - ylo), 213.0, 0.4 * (yhi - ylo), 1.0, 0.85, 0.6, 0.08]
        tf2d.SMProxy.InvokeCommand("Build")
        disp.TransferFunction2D = tf2d
        disp.UseTransfer2D = 1
        disp.UseGradientForTransfer2D = 0
        disp.ColorArray2Name = ["POINTS", "second"]
    if scene == "rectnu" or os.environ.get("SPACESKIP_PARALLEL_SHADE"):
        # Shaded: the central differences read one lattice point beyond a piece's own, which
        # the ghost layers hold (the representation asks an image for one, a grid for three).
        disp.Shade = 1
    if not stock:
        disp.Builder = builder
        # The CPU backend, or SPACESKIP_TEST_BACKEND's (as ssptest.make_scene): on a GPU machine
        # each rank draws on CUDA.
        disp.Backend = os.environ.get("SPACESKIP_TEST_BACKEND") or "CPU"
    view.CameraFocalPoint = [0.0, -18.0, 22.0]
    view.CameraPosition = [260.0, -330.0, 210.0]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.CameraViewAngle = 30.0
    view.CameraParallelProjection = 0
# FXAA (on by default in 5.11) smooths the serial image's silhouettes but not the composited
# MPI image alike (24/255 along every silhouette, ParaView's own Volume too): off for both.
# The 16-bit reader scenes keep ParaView's default (on), as a new user's view does: under MPI
# ParaView applies FXAA to the composited frame, volumes included, and the representation turns
# it off while it composites (vtkSpaceSkipVolumeRepresentation::KeepFXAAOffVolumes).
if not scene.startswith(("raw16=", "vti=")):
    view.UseFXAA = 0
if stock:
    # ParaView's own volume mapper on the same scene.
    disp.SetRepresentationType("Volume")
else:
    # Early ray termination: a ray stops at opacity 1 - 1/255 inside its piece; where it stops
    # in a piece behind the front one, that piece drew on past the serial ray's stop (less than
    # 1/255 more, on some pixels). Off here for the exact comparisons, whose checks count the
    # pixels off at all; on (the default) in the opaque scene, which checks that bound.
    disp.EarlyRayTermination = 1 if opaque else 0
    # Float compositing of the ranks' pieces (on by default); "0": ParaView's 8-bit compositing.
    disp.FloatCompositing = int(os.environ.get("SPACESKIP_FLOAT_COMPOSITING", "1"))
# Under MPI the rendering of scene "rect" rebinds the name `disp` in this script's namespace to
# a function (its programmable filter runs there; seen with pvbatch 5.11): kept as `shown`.
shown = disp
progress("scene set up; remote rendering available: %s"
         % view.GetClientSideObject().GetRemoteRenderingAvailable())
Render(view)
progress("rendered")
SaveScreenshot(out, view, ImageResolution=list(view.ViewSize), TransparentBackground=0)
progress("saved")

# Which ranks hold which part of the volume: the process-id array of ParaView's own filter.
pids = ProcessIdScalars(Input=reader) if "ProcessIdScalars" in dir() else ProcessIds(Input=reader)
pids.UpdatePipeline()
rng = pids.PointData["ProcessId"].GetRange() if "ProcessId" in pids.PointData.keys() else None
n = servermanager.ActiveConnection.GetNumberOfDataPartitions()
print("SPACESKIP_PARALLEL ranks=%d process_id_range=%s" % (n, rng))
if not stock:
    s = ssptest.stats(shown)
    print("SPACESKIP_PARALLEL rank0_stats=%s" % s)
    # The piece the representation drew (all ranks' together): with or without a ghost layer.
    drawn = shown.GetRepresentedDataInformation()
    arrays = drawn.GetPointDataInformation()
    names = [arrays.GetArrayInformation(i).GetName() for i in range(arrays.GetNumberOfArrays())]
    print("SPACESKIP_PARALLEL drawn_points=%d ghost_array=%d" % (drawn.GetNumberOfPoints(), "vtkGhostType" in names))
