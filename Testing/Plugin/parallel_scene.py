"""Renders the reference scene to argv[1]; run by pvbatch serially and under mpiexec.
Prints how the data was distributed (the ranks that hold a piece of the volume)."""
import os
import sys
from paraview.simple import *
import ssptest

out = sys.argv[1]
builder = sys.argv[2] if len(sys.argv) > 2 else "Grid"


def progress(what):
    print("SPACESKIP_PARALLEL step: " + what)
    sys.stdout.flush()


ssptest.load_plugin()
reader, view, disp = ssptest.make_scene(builder=builder, backend="CPU")
if os.environ.get("SPACESKIP_STOCK_VOLUME"):
    # For comparison runs (not a test): the same scene with ParaView's own volume mapper.
    disp.SetRepresentationType("Volume")
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
s = ssptest.stats(disp)
print("SPACESKIP_PARALLEL rank0_stats=%s" % s)
