"""Run inside the paraview GUI (paraview --script=gui_scene.py) with PV_PLUGIN_PATH pointing at
the plugin: shows the bundled shell with 'Space Skipping Volume', saves the view, and writes
gui_done.txt (with the representation's statistics) for the driver, test_gui.py."""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(os.environ["SPACESKIP_GUI_SCENE"])))
from paraview.simple import *
import ssptest

out = os.environ["SPACESKIP_TEMP"]
try:
    import paraview.simple
    # First contact, as a new user meets it: a data set shown with ParaView's defaults, then
    # "Space Skipping Volume" chosen in the representation menu (SetRepresentationType, what the
    # menu calls): no colour array, transfer function or builder picked by hand. The statistics
    # are read as the Properties panel reads them, without asking for an update.
    first_view = GetActiveViewOrCreate("RenderView")  # the view in the GUI's layout
    first = ssptest.open_data()
    RenameSource("first contact", first)
    first_disp = Show(first, first_view)
    first_disp.SetRepresentationType("Space Skipping Volume")
    first_view.ResetCamera()
    Render(first_view)
    SaveScreenshot(os.path.join(out, "gui_first.png"), first_view, ImageResolution=list(ssptest.IMAGE_SIZE),
                   TransparentBackground=0)
    first_result = {
        "color_array": list(first_disp.ColorArrayName),
        "stats": {n: first_disp.GetPropertyValue(n) for n in
                  ("BuilderUsed", "BackendUsed", "LastRenderSeconds", "Occupancy", "FrameCount", "BuilderChoice")}}
    Delete(first)
    # A segmentation, as a user colours one: the label array shown as Space Skipping Volume, its
    # colour map made categorical (annotations, indexed colours): the label-map mode (Label Map
    # Auto) with one segment hidden from the panel's Hidden Labels.
    labels_path = os.path.join(out, "gui_labels.vti")
    ssptest.write_label_blobs(labels_path)
    labels = XMLImageDataReader(registrationName="segmentation", FileName=[labels_path])
    labels_disp = Show(labels, first_view)
    labels_disp.SetRepresentationType("Space Skipping Volume")
    ColorBy(labels_disp, ("POINTS", "labels"))
    ssptest.categorical_label_map("labels")
    labels_disp.Shade = 0
    labels_disp.ScalarOpacityUnitDistance = 1.0
    labels_disp.HiddenLabels = [9]
    first_view.ResetCamera()
    first_view.OrientationAxesVisibility = 0  # only the background and the labels in the image
    Render(first_view)
    SaveScreenshot(os.path.join(out, "gui_labels.png"), first_view, ImageResolution=list(ssptest.IMAGE_SIZE),
                   TransparentBackground=0)
    labels_disp.UpdatePropertyInformation()
    labels_result = {"label_map_used": labels_disp.GetPropertyValue("LabelMapUsed"),
                     "hidden": list(labels_disp.HiddenLabels)}
    Delete(labels)
    first_view.OrientationAxesVisibility = 1
    paraview.simple._DisableFirstRenderCameraReset()  # keep the scene's camera
    reader = ssptest.open_data()
    RenameSource("shell_64x64x64_uint8.raw", reader)
    view = GetActiveViewOrCreate("RenderView")
    ssptest.make_view(size=list(view.ViewSize), view=view)
    disp = ssptest.show_space_skipping(reader, view, builder="Grid", backend="CPU")
    ssptest.set_camera(view)
    SetActiveSource(reader)
    Render(view)
    SaveScreenshot(os.path.join(out, "gui_view.png"), view, ImageResolution=list(ssptest.IMAGE_SIZE),
                   TransparentBackground=0)
    result = {"representation": disp.SMProxy.GetProperty("Representation").GetElement(0),
              "stats": ssptest.stats(disp),
              "groups_shown": ssptest.groups_shown_for(disp),
              "first": first_result,
              "labels": labels_result}
except Exception as e:  # report to the driver instead of leaving it waiting
    import traceback
    result = {"error": traceback.format_exc()}
with open(os.path.join(out, "gui_done.tmp"), "w") as f:
    json.dump(result, f, default=str)
os.replace(os.path.join(out, "gui_done.tmp"), os.path.join(out, "gui_done.txt"))
