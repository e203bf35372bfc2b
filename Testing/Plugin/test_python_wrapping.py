"""pvpython: the wrapped vtkSpaceSkippingVolumeMapper, importable once the plugin is loaded.

1. `import spaceskip` fails before LoadPlugin (the build's Python folder is not on sys.path here)
   and works after it (the plugin embeds the package; Plugin/spaceskip/__init__.py).
2. A mapper made from Python keeps its parameters.
3. On the builtin session, the mapper behind a Space Skipping Volume display is reached from
   Python as a vtkSpaceSkippingVolumeMapper and its statistics equal the display's information
   properties (disp.UpdatePropertyInformation(); disp.GetPropertyValue(...)).
"""
import ssptest


def main():
    try:
        import spaceskip  # noqa: F401
    except ImportError:
        pass
    else:
        raise AssertionError("spaceskip imported before the plugin was loaded: %s" % spaceskip)

    ssptest.load_plugin()
    from spaceskip import vtkSpaceSkippingVolumeMapper
    import spaceskip.vtkSpaceSkip
    print("spaceskip.vtkSpaceSkip from", spaceskip.vtkSpaceSkip.__file__)

    m = vtkSpaceSkippingVolumeMapper()
    m.SetBuilderToKdTreeCPU()
    m.SetMaxLeafSize(32)
    m.SetMacroCellSize(4)
    assert m.GetBuilder() == m.KdTreeCPU and m.GetBuilderAsString() == "KdTreeCPU", m.GetBuilder()
    assert m.GetMaxLeafSize() == 32 and m.GetMacroCellSize() == 4
    assert m.GetBuilderUsed() == "none"  # nothing built yet

    from paraview import simple
    reader, view, disp = ssptest.make_scene(builder="KdTreeCPU", backend="CPU")
    simple.Render(view)
    rep = ssptest.mapper_of(disp)  # the vtkSpaceSkipVolumeRepresentation (builtin session)
    mapper = rep.GetActor().GetMapper()  # the vtkPVLODVolume's full-resolution mapper
    assert isinstance(mapper, vtkSpaceSkippingVolumeMapper), type(mapper)
    s = ssptest.stats(disp)
    print("display:", s["BuilderUsed"], s["BackendUsed"], s["NodeCount"], s["FrameCount"])
    print("mapper: ", mapper.GetBuilderUsed(), mapper.GetBackendUsed(), mapper.GetNodeCount(),
          mapper.GetFrameCount())
    assert mapper.GetBuilderUsed() == s["BuilderUsed"] == "KdTreeCPU", mapper.GetBuilderUsed()
    assert mapper.GetBackendUsed() == s["BackendUsed"] == "cpu", mapper.GetBackendUsed()
    assert mapper.GetNodeCount() == s["NodeCount"] and mapper.GetNodeCount() > 0
    assert mapper.GetFrameCount() == s["FrameCount"] >= 1
    assert mapper.GetSampleDistanceUsed() > 0.0

    # A property set on the display reaches the same mapper object.
    disp.MaxLeafSize = 16
    simple.Render(view)
    assert mapper.GetMaxLeafSize() == 16, mapper.GetMaxLeafSize()
    print("ok")


# A failed assert exits pvpython with status 1. Not sys.exit(): in pvpython 5.11 it tears the
# session down in an order that ends in an X error (GLXBadContext) and exit status 1 even after
# success (seen with and without this plugin's module imported).
main()
