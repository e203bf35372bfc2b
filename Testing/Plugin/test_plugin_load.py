"""The plugin loads; 'Space Skipping Volume' is offered for image data; every mapper property
exists with its domain and documentation; the statistics are read-only information properties."""
from paraview.simple import *
import ssptest

ssptest.load_plugin()
ok = ssptest.Checker()

pxm = servermanager.ProxyManager()
ok.check(pxm.SMProxyManager.GetPrototypeProxy("representations", "SpaceSkipVolumeRepresentation")
         is not None, "proxy representations/SpaceSkipVolumeRepresentation is defined")

reader = ssptest.open_data()
view = ssptest.make_view()
disp = Show(reader, view)
types = disp.Representation.Available
ok.check("Space Skipping Volume" in types, "image data offers 'Space Skipping Volume' (%s)" % types)
ok.check("Volume" in types, "the stock 'Volume' type is still offered")

enums = {
    "Builder": ["Naive", "Grid", "LBVH", "LBVHCPU", "KdTreeCPU", "KdTreeGPU", "KdTreeGPUFast",
                "Hybrid", "DistanceGrid", "Auto"],
    "LeafCriterion": ["Shallow", "Deep"],
    "Backend": ["Auto", "CPU", "CUDA"],
    "FilterMode": ["Exact", "Hardware"],
}
for name, entries in enums.items():
    prop = disp.GetProperty(name)
    ok.check(prop is not None, "%s exists" % name)
    if prop is not None:
        ok.check(list(prop.Available) == entries, "%s entries %s" % (name, list(prop.Available)))

ranges = {"MaxLeafSize": (0, 1024), "BinCount": (0, 64),  # BinCount 0: the sweep
          "MacroCellSize": (1, 64)}
for name, (lo, hi) in ranges.items():
    dom = disp.GetProperty(name).SMProperty.GetDomain("range")
    ok.check(dom is not None and dom.GetMinimum(0) == lo and dom.GetMaximum(0) == hi,
             "%s range domain [%s, %s]" % (name, lo, hi))
dom = disp.GetProperty("SampleDistance").SMProperty.GetDomain("range")
ok.check(dom is not None and dom.GetMinimumExists(0) and dom.GetMinimum(0) == 0.0,
         "SampleDistance range domain min 0")
ok.check(disp.GetPropertyValue("MacroCellSize") == 8, "MacroCellSize defaults to 8 (%r)"
         % disp.GetPropertyValue("MacroCellSize"))
ok.check(disp.GetPropertyValue("Builder") == "Auto", "Builder defaults to Auto (%r)"
         % disp.GetPropertyValue("Builder"))
ok.check(disp.GetProperty("EarlyRayTermination").SMProperty.GetDomain("bool") is not None,
         "EarlyRayTermination boolean domain")

for name in ["Builder", "LeafCriterion", "MaxLeafSize", "BinCount", "MacroCellSize",
             "SampleDistance", "Backend", "EarlyRayTermination", "FilterMode"]:
    smprop = disp.GetProperty(name).SMProperty
    doc = smprop.GetDocumentation()
    ok.check(doc is not None and len(doc.GetDescription() or "") > 40,
             "%s has documentation" % name)
    ok.check(not smprop.GetInformationOnly(), "%s is settable" % name)

for name in ["BuilderUsed", "BackendUsed", "LastBuildSeconds", "LastClassifySeconds",
             "LastRenderSeconds", "NodeCount", "LeafCount", "TreeHeight", "Occupancy",
             "BuildCount", "ClassifyCount", "ColorUpdateCount", "FrameCount", "BuilderChoice",
             "SampleDistanceUsed"]:
    prop = disp.GetProperty(name)
    ok.check(prop is not None and prop.SMProperty.GetInformationOnly(),
             "%s is an information (read-only) property" % name)

disp.SetRepresentationType("Space Skipping Volume")
ok.check(disp.Representation == "Space Skipping Volume", "SetRepresentationType took")
ok.done()
