"""Shared helpers of the SpaceSkip ParaView plugin tests (pvpython, pvbatch, paraview GUI).

Environment (set by CTest, see CMakeLists.txt): SPACESKIP_PLUGIN (the plugin .so),
SPACESKIP_DATA (Data/ folder), SPACESKIP_BASELINES (Baseline/ folder), SPACESKIP_TEMP (output
folder for images). A missing baseline fails the test and leaves the image in SPACESKIP_TEMP.
SPACESKIP_TEST_BACKEND (optional: CPU, CUDA or Auto) replaces the backend the tests ask for
(CPU: the CI machine has no GPU; bench/device/run-pv.sh sets CUDA on the GPU machine).
"""
import math
import os
import sys

DATA_FILE = "shell_64x64x64_uint8.raw"
DIMS = (64, 64, 64)
ARRAY = "ImageFile"  # the point array vtkImageReader produces
IMAGE_SIZE = (320, 320)


def env(name):
    value = os.environ.get(name)
    if not value:
        raise RuntimeError("environment variable %s is not set (run through ctest)" % name)
    return value


def launcher_env(extra=None):
    """The environment for a child mpiexec, pvserver or paraview: without the job state Open MPI
    put into this process when pvpython initialised MPI as a singleton (it would make the child
    mpiexec think it runs inside a job), but with the user's own Open MPI/PMIx settings
    (OMPI_MCA_*, PMIX_MCA_*, OPAL_PREFIX: e.g. OMPI_MCA_plm=isolated where no ssh exists)."""
    job_state = ("OMPI_MCA_ess", "OMPI_MCA_orte_", "OMPI_MCA_pmix", "OMPI_MCA_initial_wdir")

    def keep(k):
        if k.startswith(job_state):
            return False
        if k.startswith("OMPI_"):
            return k.startswith("OMPI_MCA_")
        if k.startswith("PMIX_"):
            return k.startswith("PMIX_MCA_")
        if k.startswith("OPAL_"):
            return k == "OPAL_PREFIX"
        return not k.startswith(("PRTE_", "HYDRA_", "PMI_"))
    env = {k: v for k, v in os.environ.items() if keep(k)}
    env.update(extra or {})
    return env


def temp_path(name):
    folder = env("SPACESKIP_TEMP")
    os.makedirs(folder, exist_ok=True)
    return os.path.join(folder, name)


def load_plugin():
    """Loads the plugin on the client and the (builtin or MPI) server."""
    from paraview import simple
    simple._DisableFirstRenderCameraReset()  # keep the test's camera on the first Render()
    simple.LoadPlugin(env("SPACESKIP_PLUGIN"), remote=False, ns=vars(simple))


def open_data():
    from paraview import simple
    reader = simple.ImageReader(FileNames=[os.path.join(env("SPACESKIP_DATA"), DATA_FILE)])
    reader.DataScalarType = "unsigned char"
    reader.DataExtent = [0, DIMS[0] - 1, 0, DIMS[1] - 1, 0, DIMS[2] - 1]
    reader.DataSpacing = [1.0, 1.0, 1.0]
    reader.DataOrigin = [0.0, 0.0, 0.0]
    return reader


def make_view(size=IMAGE_SIZE, view=None):
    from paraview import simple
    if view is None:
        view = simple.CreateView("RenderView")
    view.ViewSize = list(size)
    view.OrientationAxesVisibility = 0
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    view.Background = [0.0, 0.0, 0.0]
    view.EnableRenderOnInteraction = 0
    return view


def set_camera(view):
    c = [(d - 1) / 2.0 for d in DIMS]
    view.CameraFocalPoint = c
    view.CameraPosition = [c[0] + 70.0, c[1] + 45.0, c[2] + 95.0]
    view.CameraViewUp = [0.0, 1.0, 0.0]
    view.CameraViewAngle = 30.0
    view.CameraParallelProjection = 0


def set_transfer_functions(lut_points=None, opacity_points=None):
    """Colour map over [0, 255] and an opacity ramp that is 0 below 40: the shell's inside and
    outside are empty, so the skipping structures have something to skip."""
    from paraview import simple
    lut = simple.GetColorTransferFunction(ARRAY)
    lut.AutomaticRescaleRangeMode = "Never"
    lut.RGBPoints = lut_points or [40.0, 0.23, 0.30, 0.75, 140.0, 0.87, 0.87, 0.87,
                                   255.0, 0.71, 0.02, 0.15]
    pwf = simple.GetOpacityTransferFunction(ARRAY)
    pwf.Points = opacity_points or [0.0, 0.0, 0.5, 0.0, 40.0, 0.0, 0.5, 0.0,
                                    255.0, 0.35, 0.5, 0.0]
    return lut, pwf


def show_space_skipping(source, view, builder="KdTreeCPU", backend="CPU"):
    from paraview import simple
    disp = simple.Show(source, view)
    disp.SetRepresentationType("Space Skipping Volume")
    simple.ColorBy(disp, ("POINTS", ARRAY))
    set_transfer_functions()
    disp.ScalarOpacityUnitDistance = 4.0
    disp.Builder = builder
    disp.Backend = os.environ.get("SPACESKIP_TEST_BACKEND") or backend
    return disp


def show_float_shell_vs_stock(view, opacity_top, second=None):
    """The bundled shell as a float copy shown as Space Skipping Volume (Naive, CPU) for tests that
    compare with ParaView's own Volume: llvmpipe filters the stock Volume's 8-bit texture in whole
    1/255 steps, which quantises its gradients (see test_stock_slice_lights.py); the opacity ramp
    from 40 up to `opacity_top` at 255, unit distance 1, composite blending; and both drawn at the
    stock sample distance: ParaView's Volume locks it to the input spacing
    (vtkVolumeMapper::SpacingAdjustedSampleDistance: half the mean spacing, scaled down below 100
    voxels per axis), ours defaults to half the smallest spacing. `second`: a Calculator
    expression for a second float point array named "second". Returns the display."""
    from paraview.simple import Calculator
    as_float = Calculator(Input=open_data(), AttributeType="Point Data", ResultArrayName=ARRAY,
                          Function="%s*1.0" % ARRAY, ResultArrayType="Float")
    if second:
        as_float = Calculator(Input=as_float, AttributeType="Point Data", ResultArrayName="second",
                              Function=second, ResultArrayType="Float")
    disp = show_space_skipping(as_float, view, builder="Naive", backend="CPU")
    set_camera(view)
    set_transfer_functions(opacity_points=[0.0, 0.0, 0.5, 0.0, 40.0, 0.0, 0.5, 0.0,
                                           255.0, opacity_top, 0.5, 0.0])
    disp.ScalarOpacityUnitDistance = 1.0
    disp.SampleDistance = stock_sample_distance()
    disp.BlendMode = "Composite"
    return disp


def builders_keep_naive(view, disp, ok, ref, builders, what, prefix):
    """Each of `builders` draws `ref` (Naive's image) within 50 dB; the display is left on Naive."""
    for b in builders:
        disp.Builder = b
        img = read_png(render_to(view, "%s_builder_%s.png" % (prefix, b)))
        p = psnr(ref, img)
        print("builder %s vs Naive: PSNR %.2f dB" % (b, p))
        ok.check(p >= 50.0, "builder %s keeps Naive's %s image (PSNR %.2f >= 50 dB)" % (b, what, p))
    disp.Builder = "Naive"


def stock_sample_distance():
    """The sample distance ParaView's Volume uses for the bundled data (see show_float_shell_vs_stock)."""
    n = ((DIMS[0] - 1) * (DIMS[1] - 1) * (DIMS[2] - 1)) ** 0.333
    return 0.5 * (0.01 + 0.99 * n / 100.0) if n < 100 else 0.5


def make_scene(builder="KdTreeCPU", backend="CPU", size=IMAGE_SIZE, view=None):
    """The reference scene: the bundled shell, fixed camera, fixed transfer functions."""
    reader = open_data()
    view = make_view(size, view)
    disp = show_space_skipping(reader, view, builder, backend)
    set_camera(view)
    return reader, view, disp


def dense_wavelet_scene(n, view_size):
    """The benchmarks' dense volume: ParaView's Wavelet of n^3 points in a new render view of
    view_size (no orientation axes), shown and coloured by RTData. Returns (source, view, disp)."""
    from paraview.simple import Wavelet, CreateView, Show, ColorBy
    source = Wavelet(WholeExtent=[-(n // 2), n - n // 2 - 1] * 3)
    view = CreateView("RenderView")
    view.ViewSize = view_size
    view.OrientationAxesVisibility = 0
    disp = Show(source, view)
    ColorBy(disp, ("POINTS", "RTData"))
    return source, view, disp


def mapper_of(disp):
    """The vtkSpaceSkipVolumeRepresentation behind a display proxy (builtin session only)."""
    rep = disp.GetClientSideObject().GetActiveRepresentation()
    if rep is None or rep.GetClassName() != "vtkSpaceSkipVolumeRepresentation":
        raise AssertionError("active representation is %s" % (rep and rep.GetClassName()))
    return rep


def stats(disp):
    disp.UpdatePropertyInformation()
    names = ["BuilderUsed", "BackendUsed", "LastBuildSeconds", "LastClassifySeconds",
             "LastRenderSeconds", "NodeCount", "LeafCount", "TreeHeight", "Occupancy",
             "BuildCount", "ClassifyCount", "ColorUpdateCount", "FrameCount",
             "SampleDistanceUsed", "BuilderChoice", "CudaDeviceUsed", "CompositePathUsed",
             "PieceCompositingUsed"]
    return {n: disp.GetPropertyValue(n) for n in names}


def render_to(view, name):
    from paraview import simple
    path = temp_path(name)
    simple.Render(view)
    simple.SaveScreenshot(path, view, ImageResolution=list(view.ViewSize),
                          TransparentBackground=0)
    return path


# -- images ----------------------------------------------------------------------------------

def read_png(path):
    import numpy
    from vtkmodules.vtkIOImage import vtkPNGReader
    from vtkmodules.util.numpy_support import vtk_to_numpy
    if not os.path.exists(path):
        raise FileNotFoundError(path)
    r = vtkPNGReader()
    r.SetFileName(path)
    r.Update()
    img = r.GetOutput()
    w, h, _ = img.GetDimensions()
    a = vtk_to_numpy(img.GetPointData().GetScalars())
    a = a.reshape(h, w, -1)[:, :, :3].astype(numpy.float64)
    return a


def psnr(a, b):
    import numpy
    if a.shape != b.shape:
        raise ValueError("image sizes differ: %s vs %s" % (a.shape, b.shape))
    mse = numpy.mean((a - b) ** 2)
    return float("inf") if mse == 0 else 10.0 * math.log10(255.0 ** 2 / mse)


def lit_fraction(a, threshold=8):
    """Fraction of pixels that differ from the black background."""
    return float((a.max(axis=2) > threshold).mean())


def compare_to_baseline(path, baseline_name, min_psnr=40.0):
    base = os.path.join(env("SPACESKIP_BASELINES"), baseline_name)
    if not os.path.exists(base):
        raise AssertionError("no baseline %s; the rendered image is %s" % (base, path))
    value = psnr(read_png(path), read_png(base))
    print("PSNR %s vs %s: %.2f dB (need >= %.1f)" % (os.path.basename(path), baseline_name,
                                                     value, min_psnr))
    if value < min_psnr:
        raise AssertionError("%s differs from baseline %s: PSNR %.2f dB < %.1f dB"
                             % (path, base, value, min_psnr))
    return value


def write_sparse_vti(path, n, balls=((0.3, 0.35, 0.4, 0.16), (0.7, 0.6, 0.55, 0.13), (0.5, 0.75, 0.3, 0.1)),
                     tube_radius=0.04):
    """Writes an n^3 uint8 .vti (point array "density"): balls and a tube along x with smooth
    profiles in a background of exact zeros, as a user's sparse data set would be; built slice by
    slice (512^3 fits in memory). Returns the fraction of non-zero voxels."""
    import numpy
    data = numpy.zeros((n, n, n), numpy.uint8)
    y, x = numpy.mgrid[0:n, 0:n].astype(numpy.float32) / n
    for k in range(n):
        z = k / n
        v = numpy.zeros((n, n), numpy.float32)
        for cx, cy, cz, r in balls:
            d = numpy.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / r
            v = numpy.maximum(v, numpy.clip(1.0 - d, 0.0, 1.0))
        tube = numpy.sqrt((y - 0.5) ** 2 + (z - 0.65) ** 2) / tube_radius
        v = numpy.maximum(v, numpy.clip(1.0 - tube, 0.0, 1.0) * 0.8)
        data[k] = numpy.round(v * 255.0).astype(numpy.uint8)
    write_vti(path, data, "density")
    return float((data > 0).mean())


def write_vti(path, data, name):
    """A numpy array (z, y, x) as the point scalars `name` of an image data file."""
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOXML import vtkXMLImageDataWriter
    from vtkmodules.util.numpy_support import numpy_to_vtk
    img = vtkImageData()
    img.SetDimensions(data.shape[2], data.shape[1], data.shape[0])
    arr = numpy_to_vtk(data.ravel(), deep=1)
    arr.SetName(name)
    img.GetPointData().SetScalars(arr)
    w = vtkXMLImageDataWriter()
    w.SetFileName(path)
    w.SetInputData(img)
    w.Write()


def groups_shown_for(disp, labels=("Volume Rendering", "Cropping Parameters"),
                     representation="Space Skipping Volume"):
    """{label: True/False} for the display's property groups `labels`: whether their Properties
    panel decorators list Representation == `representation` (vtkSMSpaceSkipRepresentationProxy
    adds it beside ParaView's "Volume")."""
    def has(e):
        if (e.GetName() == "PropertyWidgetDecorator" and e.GetAttribute("type") == "GenericDecorator"
                and e.GetAttribute("property") == "Representation"
                and e.GetAttribute("value") == representation):
            return True
        return any(has(e.GetNestedElement(i)) for i in range(e.GetNumberOfNestedElements()))

    px = disp.SMProxy
    found = {}
    for i in range(px.GetNumberOfPropertyGroups()):
        g = px.GetPropertyGroup(i)
        if g.GetXMLLabel() in labels:
            found[g.GetXMLLabel()] = g.GetHints() is not None and has(g.GetHints())
    return found


class WarningCapture:
    """Collects the VTK warnings and errors of the client/builtin process until stop() (a
    vtkStringOutputWindow in place of ParaView's). pvpython routes print() through the same output
    window, so stop() replays everything captured on stdout and returns the warning and error
    messages alone (header line and message line of each)."""

    def __init__(self):
        from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow
        self.previous = vtkOutputWindow.GetInstance()
        self.window = vtkStringOutputWindow()
        vtkOutputWindow.SetInstance(self.window)

    def stop(self):
        from vtkmodules.vtkCommonCore import vtkOutputWindow
        vtkOutputWindow.SetInstance(self.previous)
        text = self.window.GetOutput()
        sys.stdout.write(text)
        sys.stdout.flush()
        lines = text.splitlines()
        found = []
        for i, line in enumerate(lines):
            if line.startswith(("Warning: In ", "ERROR: In ", "Generic Warning", "Generic Error")):
                found.append(line)
                if i + 1 < len(lines):
                    found.append(lines[i + 1])
        return "\n".join(found)


class Checker:
    """Collects failures so one run reports all of them; exit code 1 when any failed."""

    def __init__(self):
        self.failures = []

    def check(self, cond, message):
        print(("ok   " if cond else "FAIL ") + message)
        if not cond:
            self.failures.append(message)

    def done(self):
        if self.failures:
            print("%d check(s) failed" % len(self.failures))
            sys.stdout.flush()
            os._exit(1)
        print("all checks passed")


class VersusStock:
    """One display drawn as Space Skipping Volume and as ParaView's own Volume in `view`, the
    frames saved as PREFIX_NAME_ss.png / PREFIX_NAME_stock.png."""

    def __init__(self, view, disp, ok, prefix):
        self.view, self.disp, self.ok, self.prefix = view, disp, ok, prefix

    def shoot(self, name, kind):
        self.disp.SetRepresentationType(kind)
        tag = "ss" if kind != "Volume" else "stock"
        return read_png(render_to(self.view, "%s_%s_%s.png" % (self.prefix, name, tag)))

    def both(self, name):
        """Both images (ours, stock), ours shown after; checks that ours draws and matches the
        stock image (PSNR >= 40 dB)."""
        ours, stock = self.shoot(name, "Space Skipping Volume"), self.shoot(name, "Volume")
        self.disp.SetRepresentationType("Space Skipping Volume")
        p = psnr(ours, stock)
        lit = lit_fraction(ours)
        print("%s: lit %.3f, PSNR Space Skipping Volume vs Volume %.2f dB" % (name, lit, p))
        self.ok.check(lit > 0.02, "%s draws something (%.1f%% of the pixels)" % (name, 100 * lit))
        self.ok.check(p >= 40.0, "%s: matches ParaView's Volume (PSNR %.2f >= 40 dB)" % (name, p))
        return ours, stock

    def changes(self, what, a, b, max_psnr=30.0):
        """Checks that a setting changed both images: a and b are both()'s (ours, stock) pairs."""
        ours, stock = psnr(a[0], b[0]), psnr(a[1], b[1])
        print("  %s: PSNR ours %.2f dB, ParaView's Volume %.2f dB" % (what, ours, stock))
        self.ok.check(ours < max_psnr and stock < max_psnr,
                      "%s changes the image (ours %.1f, stock %.1f dB)" % (what, ours, stock))


# A label map (uint8 segmentation) of touching blobs whose ids are far apart, its colours and
# names: test_labelmap.py and the GUI's scene (gui_scene.py).
LABEL_N = 40
LABEL_BLOBS = [(14, 14, 14, 8, 1), (24, 15, 15, 7, 5), (16, 25, 18, 7, 9), (26, 26, 26, 6, 2)]
LABEL_COLOURS = {1: (0.9, 0.2, 0.2), 2: (1.0, 0.9, 0.1), 5: (0.2, 0.9, 0.2), 9: (0.2, 0.3, 1.0)}
LABEL_NAMES = {1: "one", 2: "two", 5: "five", 9: "nine"}


def write_label_blobs(path):
    """LABEL_BLOBS painted in order (later over earlier: touching borders) into a .vti, array
    "labels"."""
    import numpy
    n = LABEL_N
    z, y, x = numpy.mgrid[0:n, 0:n, 0:n].astype(numpy.float64)
    data = numpy.zeros((n, n, n), numpy.uint8)
    for cx, cy, cz, r, label in LABEL_BLOBS:
        inside = (x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2 <= r * r
        data[inside] = label
    write_vti(path, data, "labels")


def categorical_label_map(array):
    """`array`'s colour map made categorical as a user does in the colour map editor
    (Interpret Values As Categories, an annotation and an indexed colour per id), opaque from 0.5."""
    from paraview.simple import GetColorTransferFunction, GetOpacityTransferFunction
    lut = GetColorTransferFunction(array)
    lut.AutomaticRescaleRangeMode = "Never"
    ids = sorted(LABEL_COLOURS)
    lut.RGBPoints = sum(([float(i)] + list(LABEL_COLOURS[i]) for i in ids), [])
    pwf = GetOpacityTransferFunction(array)
    pwf.Points = [0.0, 0.0, 0.5, 0.0, 0.5, 1.0, 0.5, 0.0, 9.0, 1.0, 0.5, 0.0]
    lut.InterpretValuesAsCategories = 1
    lut.Annotations = sum(([str(i), LABEL_NAMES[i]] for i in ids), [])
    lut.IndexedColors = sum((list(LABEL_COLOURS[i]) for i in ids), [])
    return lut


def unexplained_colours(img, colours, tol=2, background=(0.0, 0.0, 0.0)):
    """Pixels whose colour is neither `background` (8-bit) nor one of `colours` (+-tol/255)."""
    import numpy
    known = [numpy.array(background, float)] + [numpy.round(numpy.array(c) * 255.0) for c in colours]
    good = numpy.zeros(img.shape[:2], bool)
    for c in known:
        good |= (numpy.abs(img - c) <= tol).all(axis=2)
    return int((~good).sum())
