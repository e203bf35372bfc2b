"""PyVista's Plotter.add_volume, drawn by vtkSpaceSkippingVolumeMapper.

    import pyvista as pv
    import spaceskip.pyvista
    pl = pv.Plotter()
    spaceskip.pyvista.add_volume(pl, pv.Wavelet(), cmap="viridis", opacity="sigmoid")
    pl.show()

PyVista chooses a volume mapper by name only (add_volume's `mapper=` takes 'fixed_point', 'gpu',
'open_gl', 'smart' or 'ugrid'; the table is local to add_volume, so no name can be registered).
So `add_volume` here calls PyVista's with the same arguments, then hands each volume it made to
a vtkSpaceSkippingVolumeMapper (`use_mapper`): the same dataset (or pipeline input), scalar mode,
scalar array, blend mode, cropping and clipping planes. Colours and opacity live in the volume's
property (PyVista's VolumeProperty built from its lookup table and clim), which stays as is.

Interpolation: PyVista leaves VTK's default, nearest. The mapper samples scalar volumes
trilinearly only (its nearest sampling serves label maps), so `use_mapper` sets the property to
linear, with a warning, so that the property says what is drawn; docs/pip.md.

What still speaks to PyVista's own mapper: `actor.mapper` is now ours, which lacks PyVista's
Python attributes (`lookup_table`, `scalar_range`, ...); `plotter.mapper` and the scalar bar keep
PyVista's.
"""
import warnings

from .vtkSpaceSkip import vtkSpaceSkippingVolumeMapper

__all__ = ["add_volume", "use_mapper"]

_NEAREST = 0  # VTK_NEAREST_INTERPOLATION


def use_mapper(volume, mapper=None):
    """Draw `volume` (a vtkVolume, e.g. PyVista's Volume actor) with a vtkSpaceSkippingVolumeMapper.

    Copies from its current mapper the input (pipeline connection or dataset), scalar mode,
    selected scalar array, blend mode, cropping and clipping planes. Returns the new mapper.
    """
    old = volume.GetMapper()
    if mapper is None:
        mapper = vtkSpaceSkippingVolumeMapper()
    if old is None:
        raise ValueError("spaceskip.pyvista.use_mapper: the volume has no mapper to take the input from")
    if old.GetNumberOfInputConnections(0) == 0:
        raise ValueError("spaceskip.pyvista.use_mapper: the volume's mapper has no input")
    # The same output port: a filter's, or the trivial producer of SetInputData's dataset.
    mapper.SetInputConnection(old.GetInputConnection(0, 0))
    mapper.SetScalarMode(old.GetScalarMode())
    if old.GetArrayAccessMode() == 0:  # VTK_GET_ARRAY_BY_ID
        mapper.SelectScalarArray(old.GetArrayId())
    elif old.GetArrayName():
        mapper.SelectScalarArray(old.GetArrayName())
    mapper.SetBlendMode(old.GetBlendMode())
    mapper.SetCropping(old.GetCropping())
    mapper.SetCroppingRegionPlanes(old.GetCroppingRegionPlanes())
    mapper.SetCroppingRegionFlags(old.GetCroppingRegionFlags())
    if old.GetClippingPlanes() is not None:
        mapper.SetClippingPlanes(old.GetClippingPlanes())
    prop = volume.GetProperty()
    if prop is not None and prop.GetInterpolationType() == _NEAREST:
        warnings.warn("spaceskip.pyvista: vtkSpaceSkippingVolumeMapper samples scalar volumes "
                      "trilinearly only; the volume property's interpolation is set to linear "
                      "(PyVista left VTK's default, nearest)", stacklevel=3)
        prop.SetInterpolationTypeToLinear()
    volume.SetMapper(mapper)
    return mapper


def add_volume(plotter, volume, *args, **kwargs):
    """`plotter.add_volume(volume, *args, **kwargs)`, drawn by vtkSpaceSkippingVolumeMapper.

    Takes PyVista's arguments (except `mapper`, which names PyVista's own mappers) and returns
    what PyVista returns: the Volume actor, or a list of them for a MultiBlock.
    """
    if kwargs.get("mapper") is not None:
        raise TypeError("spaceskip.pyvista.add_volume: `mapper` names PyVista's own mappers; "
                        "leave it out (the volume is drawn by vtkSpaceSkippingVolumeMapper)")
    kwargs.pop("mapper", None)
    # PyVista's smart mapper would pick a render mode on first render; 'gpu' only builds the
    # pipeline input here, which use_mapper then takes.
    actors = plotter.add_volume(volume, *args, mapper="gpu", **kwargs)
    for actor in actors if isinstance(actors, list) else [actors]:
        use_mapper(actor)
    return actors
