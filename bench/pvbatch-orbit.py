"""Frame rate of ParaView's own engine (pvbatch, serial or `mpiexec -n N pvbatch`) on a raw volume
read by ParaView's Image Reader, each rank reading and drawing its piece, the frames composited by
ParaView (IceT, or the plugin's float compositing), each frame waited for on rank 0: ours ('Space
Skipping Volume') or ParaView's stock 'Volume' (--stock).

The camera orbits the volume (--turn degrees a frame); the first frame (the read, upload, build and
Auto's measuring) is timed apart (first_s), and so is everything from the reader's creation to the
end of the first frame (to_first_s: the read, ParaView's data information, the representation's
update, which ResetCamera already makes, and the first frame). Prints one line starting with
PVBATCH_ORBIT (ranks, fps, first frame, backend, builder) and, with --reference, the PSNR and largest difference of the first frame
against a reference image (e.g. the one-rank image: N ranks == 1 rank).

  [mpiexec -n N] pvbatch bench/pvbatch-orbit.py --plugin SpaceSkip.so --raw FILE_XxYxZ_uint8.raw
      [--view 1024] [--frames 60] [--backend CUDA] [--builder Auto] [--stock] [--shade] [--png first.png]
      [--reference first-1rank.png]
The raw file's name gives its dimensions and type (spaceskip generate writes such names:
`spaceskip generate nbody --dims 2048 2048 2048 -o /tmp/nbody_2048x2048x2048_uint8.raw`).
"""
import argparse
import math
import os
import re
import statistics
import time

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", required=True)
parser.add_argument("--raw", required=True, help="NAME_XxYxZ_TYPE.raw, TYPE uint8 or uint16 or float32")
parser.add_argument("--view", type=int, default=1024)
parser.add_argument("--frames", type=int, default=60)
parser.add_argument("--turn", type=float, default=6.0)
parser.add_argument("--backend", default="Auto")
parser.add_argument("--builder", default="Auto")
parser.add_argument("--stock", action="store_true", help="ParaView's own Volume instead of ours")
parser.add_argument("--outline", action="store_true",
                    help="ParaView's Outline instead of a volume: the floor of ParaView's own frame (passes, IceT)")
parser.add_argument("--shade", action="store_true", help="shaded (under MPI the pieces then take a ghost layer)")
parser.add_argument("--host-composite", action="store_true",
                    help="ours with Keep Image On GPU off: frames and MPI pieces through host memory")
parser.add_argument("--png", default="", help="save the first frame here")
parser.add_argument("--reference", default="", help="compare the first frame with this image")
parser.add_argument("--result", default="", help="append the result lines to this file too (pvbatch -v N "
                    "loses the script's printed lines)")
args = parser.parse_args()


def report(line):
    print(line, flush=True)
    if args.result:
        with open(args.result, "a") as f:
            f.write(line + "\n")


from paraview import simple  # noqa: E402
from paraview import servermanager  # noqa: E402

m = re.search(r"_(\d+)x(\d+)x(\d+)_(uint8|uint16|float32)\.raw$", args.raw)
if not m:
    raise SystemExit("pvbatch-orbit: %s: the name must end in _XxYxZ_TYPE.raw" % args.raw)
dims = [int(m.group(i)) for i in (1, 2, 3)]
scalar = {"uint8": "unsigned char", "uint16": "unsigned short", "float32": "float"}[m.group(4)]

simple._DisableFirstRenderCameraReset()
simple.LoadPlugin(args.plugin, remote=False, ns=vars(simple))
ranks = servermanager.vtkProcessModule.GetProcessModule().GetNumberOfLocalPartitions()

# From here to the end of the first frame: the read, ParaView's data information, the
# representation's update (ResetCamera updates the view) and the first frame (to_first_s).
start = time.perf_counter()
reader = simple.ImageReader(FileNames=[args.raw])
reader.DataScalarType = scalar
reader.DataByteOrder = "LittleEndian"
reader.DataExtent = [0, dims[0] - 1, 0, dims[1] - 1, 0, dims[2] - 1]
view = simple.CreateView("RenderView")
view.ViewSize = [args.view, args.view]
view.OrientationAxesVisibility = 0
view.UseFXAA = 0
disp = simple.Show(reader, view)
disp.SetRepresentationType("Outline" if args.outline else "Volume" if args.stock else "Space Skipping Volume")
simple.ColorBy(disp, ("POINTS", "ImageFile"))
# The paper's ramp: transparent at the lowest value, opacity rising linearly to the top.
lo, hi = reader.PointData["ImageFile"].GetRange()
lut = simple.GetColorTransferFunction("ImageFile")
lut.ApplyPreset("Cool to Warm", True)
lut.RescaleTransferFunction(lo, hi)
pwf = simple.GetOpacityTransferFunction("ImageFile")
pwf.Points = [lo, 0.0, 0.5, 0.0, hi, 1.0, 0.5, 0.0]
disp.Shade = 1 if args.shade else 0
if not args.stock and not args.outline:
    disp.Backend = args.backend
    disp.Builder = args.builder
    if args.host_composite:
        disp.GPUComposite = 0
view.ResetCamera()
cam = view.GetActiveCamera()
cam.Elevation(20.0)
window = view.GetRenderWindow()


def frame():
    t = time.perf_counter()
    simple.Render(view)
    window.WaitForCompletion()  # rank 0's window; the composite needs every rank's piece
    return time.perf_counter() - t


first = frame()
to_first = time.perf_counter() - start
if args.png:
    simple.SaveScreenshot(args.png, view, ImageResolution=[args.view, args.view])
times = []
for _ in range(args.frames):
    cam.Azimuth(args.turn)
    times.append(frame())
med = statistics.median(times)
used = ""
if not args.stock and not args.outline:
    disp.UpdatePropertyInformation()
    used = " backend=%s builder=%s device='%s' composite='%s' pieces='%s'" % (
        disp.GetPropertyValue("BackendUsed"), disp.GetPropertyValue("BuilderUsed"),
        disp.GetPropertyValue("CudaDeviceUsed"), disp.GetPropertyValue("CompositePathUsed"),
        disp.GetPropertyValue("PieceCompositingUsed"))
report("PVBATCH_ORBIT ranks=%d rep=%s%s%s volume=%dx%dx%d %s view=%d frames=%d fps=%.1f median_ms=%.3f "
       "first_s=%.3f to_first_s=%.3f%s" % (ranks, "Outline" if args.outline else "Volume" if args.stock else "SpaceSkip", " shaded" if args.shade else "",
                                            " host-composite" if args.host_composite else "",
                                            dims[0], dims[1], dims[2], m.group(4), args.view, args.frames, 1.0 / med,
                                            1e3 * med, first, to_first, used))

if args.reference and args.png:
    from vtkmodules.vtkIOImage import vtkPNGReader
    from vtkmodules.util.numpy_support import vtk_to_numpy

    def read(path):
        r = vtkPNGReader()
        r.SetFileName(path)
        r.Update()
        return vtk_to_numpy(r.GetOutput().GetPointData().GetScalars()).astype("float64")
    a, b = read(args.png), read(args.reference)
    if a.shape != b.shape:
        report("PVBATCH_ORBIT_COMPARE sizes differ: %s vs %s" % (a.shape, b.shape))
    else:
        mse = ((a - b) ** 2).mean()
        psnr = float("inf") if mse == 0 else 10 * math.log10(255.0 ** 2 / mse)
        over = float((abs(a - b).max(axis=-1) > 1).mean() * 100) if a.ndim > 1 else 0.0
        report("PVBATCH_ORBIT_COMPARE vs %s: PSNR %.2f dB, max |diff| %d/255, %.3f %% of pixels over 1/255"
               % (os.path.basename(args.reference), psnr, int(abs(a - b).max()), over))
