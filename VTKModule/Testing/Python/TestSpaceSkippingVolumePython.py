"""vtkSpaceSkippingVolumeMapper from plain Python against ParaView's vtkmodules (python3, not pvpython).

A wavelet (vtkRTAnalyticSource) whose opacity is 0 below 200, so about half the macro cells are
empty; CPU backend. Checks: the wrapped mapper takes VTK's own vtkImageData/vtkVolume/vtkRenderer;
an all-transparent transfer function draws nothing (so the emptiness check below can fail) while
the real one draws; Grid and KdTreeCPU give Naive's image within 1/255; the statistics read back
(Grid has no tree: node count and height are checked on the k-d tree); time steps in
NewTimeStepArray's arrays written through numpy and played with PrefetchTimeStep, each frame equal
to the frame of the same values in an ordinary array.
Exit status 0 on success; an AssertionError (status 1) names what differed.
"""
import sys

import numpy
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonCore import VTK_FLOAT, VTK_INT
from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
from vtkmodules.vtkImagingCore import vtkRTAnalyticSource
from vtkmodules.vtkRenderingCore import (vtkColorTransferFunction, vtkRenderer, vtkRenderWindow,
                                         vtkVolume, vtkVolumeProperty, vtkWindowToImageFilter)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 (the OpenGL render window)

from spaceskip import vtkSpaceSkippingVolumeMapper
import spaceskip.vtkSpaceSkip  # the module itself, VTK-style

SIZE = 160


def grab(window):
    """The window's RGB pixels as an (h, w, 3) uint8 array."""
    w2i = vtkWindowToImageFilter()
    w2i.SetInput(window)
    w2i.SetInputBufferTypeToRGB()
    w2i.ReadFrontBufferOff()
    w2i.Update()
    img = w2i.GetOutput()
    w, h, _ = img.GetDimensions()
    return vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, 3).copy()


def main():
    assert spaceskip.vtkSpaceSkip.vtkSpaceSkippingVolumeMapper is vtkSpaceSkippingVolumeMapper

    source = vtkRTAnalyticSource()
    source.SetWholeExtent(-31, 32, -31, 32, -31, 32)
    source.Update()
    image = source.GetOutput()  # a vtkImageData from vtkmodules, handed to our module below
    lo, hi = image.GetScalarRange()

    color = vtkColorTransferFunction()
    color.AddRGBPoint(lo, 0.1, 0.2, 0.9)
    color.AddRGBPoint(230.0, 0.9, 0.9, 0.2)
    color.AddRGBPoint(hi, 0.9, 0.1, 0.1)
    opacity = vtkPiecewiseFunction()
    opacity.AddPoint(lo, 0.0)
    opacity.AddPoint(200.0, 0.0)
    opacity.AddPoint(hi, 0.4)
    prop = vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetInterpolationTypeToLinear()

    mapper = vtkSpaceSkippingVolumeMapper()
    mapper.SetInputData(image)
    mapper.SetBackendToCPU()
    assert mapper.GetBuilderUsed() == "none" and mapper.GetSampleDistanceUsed() == 0.0
    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    assert volume.GetMapper() is mapper, "the vtkVolume did not keep the wrapped mapper"

    renderer = vtkRenderer()
    renderer.AddVolume(volume)
    renderer.SetBackground(0.0, 0.0, 0.0)
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(SIZE, SIZE)
    window.AddRenderer(renderer)
    renderer.ResetCamera()
    renderer.GetActiveCamera().Azimuth(30.0)
    renderer.GetActiveCamera().Elevation(20.0)
    renderer.ResetCameraClippingRange()

    def render(builder):
        getattr(mapper, "SetBuilderTo" + builder)()
        window.Render()
        return grab(window)

    # An all-transparent transfer function draws nothing: the emptiness check can fail.
    transparent = vtkPiecewiseFunction()
    transparent.AddPoint(lo, 0.0)
    transparent.AddPoint(hi, 0.0)
    prop.SetScalarOpacity(transparent)
    blank = render("Naive")
    assert blank.max() == 0, "transparent volume drew %d pixels" % (blank.max(axis=2) > 0).sum()
    prop.SetScalarOpacity(opacity)

    naive = render("Naive")
    drawn = int((naive.max(axis=2) > 8).sum())
    print("Naive: %d of %d pixels drawn, max %d" % (drawn, SIZE * SIZE, naive.max()))
    assert drawn > SIZE * SIZE // 20, "the volume is (nearly) empty: %d pixels" % drawn
    assert mapper.GetBuilderUsed() == "Naive", mapper.GetBuilderUsed()

    grid = render("Grid")
    diff = int(numpy.abs(grid.astype(int) - naive.astype(int)).max())
    print("Grid vs Naive: max diff %d/255; occupancy %.3f, backend %s, sample distance %g"
          % (diff, mapper.GetOccupancy(), mapper.GetBackendUsed(), mapper.GetSampleDistanceUsed()))
    assert diff <= 1, "Grid differs from Naive by %d/255" % diff
    assert mapper.GetBuilderUsed() == "Grid", mapper.GetBuilderUsed()
    assert mapper.GetBackendUsed() == "cpu", mapper.GetBackendUsed()
    # Grid marches the macro-cell grid itself: no tree, so its node count is 0; see KdTreeCPU.
    assert 0.0 < mapper.GetSampleDistanceUsed() <= 1.0, mapper.GetSampleDistanceUsed()
    assert 0.0 < mapper.GetOccupancy() < 1.0, mapper.GetOccupancy()

    mapper.SetLeafCriterionToDeep()
    mapper.SetMaxLeafSize(32)
    assert mapper.GetMaxLeafSize() == 32 and mapper.GetLeafCriterion() == mapper.Deep
    kd = render("KdTreeCPU")
    diff = int(numpy.abs(kd.astype(int) - naive.astype(int)).max())
    print("KdTreeCPU vs Naive: max diff %d/255; nodes %d, height %d, builds %d, frames %d"
          % (diff, mapper.GetNodeCount(), mapper.GetTreeHeight(), mapper.GetBuildCount(),
             mapper.GetFrameCount()))
    assert diff <= 1, "KdTreeCPU differs from Naive by %d/255" % diff
    assert mapper.GetBuilderUsed() == "KdTreeCPU", mapper.GetBuilderUsed()
    assert mapper.GetNodeCount() > 0 and mapper.GetTreeHeight() > 0
    assert mapper.GetFrameCount() >= 4, mapper.GetFrameCount()  # grab() may render again

    # Time steps from Python: NewTimeStepArray's arrays written through numpy (no copy), the next
    # one handed to PrefetchTimeStep before each frame; each frame equals the frame of the same
    # values in an ordinary array (the wavelet shifted by k, as float).
    values = vtk_to_numpy(image.GetPointData().GetScalars()).astype(numpy.float32)
    n = image.GetNumberOfPoints()
    steps, expected = [], []
    mapper.SetBuilderToGrid()
    for k in range(3):
        a = mapper.NewTimeStepArray(VTK_FLOAT, 1, n)
        assert a is not None and a.GetNumberOfTuples() == n and a.GetDataType() == VTK_FLOAT
        vtk_to_numpy(a)[:] = values + 6.0 * k  # writes the array's own memory
        a.SetName("step")
        steps.append(a)
        plain = numpy_to_vtk(values + 6.0 * k, deep=1)
        plain.SetName("step")
        image.GetPointData().SetScalars(plain)
        window.Render()
        expected.append(grab(window))
    for i in range(5):
        image.GetPointData().SetScalars(steps[i % 3])
        mapper.PrefetchTimeStep(steps[(i + 1) % 3])
        window.Render()
        diff = int(numpy.abs(grab(window).astype(int) - expected[i % 3].astype(int)).max())
        assert diff <= 1, "time step %d differs from its ordinary array's frame by %d/255" % (i % 3, diff)
    assert mapper.GetTimeStepCount() >= 5, mapper.GetTimeStepCount()
    errors = []
    mapper.AddObserver("ErrorEvent", lambda obj, event: errors.append(event))  # observed: not printed
    assert mapper.NewTimeStepArray(VTK_INT, 1, 4) is None and len(errors) == 1  # refused, with an error
    print("time steps through NewTimeStepArray + PrefetchTimeStep: %d played, each == its static frame"
          % 5)
    print("ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
