"""SpaceSkip's Python package as the plugin embeds it: after LoadPlugin() in pvpython/pvbatch,
`from spaceskip import vtkSpaceSkippingVolumeMapper` works without touching sys.path.

ParaView 5.11 can embed only pure-Python modules in a plugin (paraview_add_plugin PYTHON_MODULES;
servermanager's ParaViewMetaPathFinder serves them, after sys.path). The compiled wrapper
(spaceskip.vtkSpaceSkip, VTKModule/Python) lies at ../../../python3.X/site-packages/spaceskip from
the plugin's folder, in the build and the install tree alike (the top-level CMakeLists.txt
checks that layout); this package's __path__ points there. When that folder is on sys.path
itself, Python imports it directly and this file is not used.
"""
import os
import sys


def _wrapped_package_dir():
    from paraview.modules.vtkRemotingCore import vtkPVPluginTracker
    tracker = vtkPVPluginTracker.GetInstance()
    for i in range(tracker.GetNumberOfPlugins()):
        if tracker.GetPluginName(i) == "SpaceSkip" and tracker.GetPluginLoaded(i):
            plugin_dir = os.path.dirname(os.path.abspath(tracker.GetPluginFileName(i)))
            return os.path.normpath(os.path.join(
                plugin_dir, os.pardir, os.pardir, os.pardir, "python%d.%d" % sys.version_info[:2],
                "site-packages", "spaceskip"))
    raise ImportError("spaceskip: the SpaceSkip plugin is not loaded")


_dir = _wrapped_package_dir()
if not os.path.isdir(_dir):
    raise ImportError("spaceskip: no wrapped module at %s (built with SPACESKIP_WRAP_PYTHON=OFF?)" % _dir)
__path__.append(_dir)  # noqa: F821 (set by the import system for a package)

from .vtkSpaceSkip import vtkSpaceSkippingVolumeMapper  # noqa: E402

__all__ = ["vtkSpaceSkippingVolumeMapper"]
