"""SpaceSkip for VTK Python: vtkSpaceSkippingVolumeMapper, wrapped against ParaView's VTK.

    from spaceskip import vtkSpaceSkippingVolumeMapper      # or: from spaceskip.vtkSpaceSkip import ...

One file, two places. Installed next to the compiled wrapper (spaceskip.vtkSpaceSkip, built from
VTKModule/Python into lib/python3.X/site-packages/spaceskip) it imports the wrapper directly.
The ParaView plugin embeds the same file (Plugin/spaceskip/__init__.py is a link to this one):
ParaView 5.11 can embed only pure-Python modules in a plugin (paraview_add_plugin PYTHON_MODULES;
servermanager's ParaViewMetaPathFinder serves them, after sys.path), so after LoadPlugin() in
pvpython/pvbatch the wrapper is not beside it. Then, and only then, this package's __path__ is
pointed at the wrapper's folder, ../../../python3.X/site-packages/spaceskip from the loaded
plugin's folder, in the build and the install tree alike (the top-level CMakeLists.txt checks
that layout).
"""
import os
import sys


def _wrapped_package_dir():
    """The compiled wrapper's folder, found from the loaded SpaceSkip plugin."""
    from paraview.modules.vtkRemotingCore import vtkPVPluginTracker
    tracker = vtkPVPluginTracker.GetInstance()
    for i in range(tracker.GetNumberOfPlugins()):
        if tracker.GetPluginName(i) == "SpaceSkip" and tracker.GetPluginLoaded(i):
            plugin_dir = os.path.dirname(os.path.abspath(tracker.GetPluginFileName(i)))
            return os.path.normpath(os.path.join(
                plugin_dir, os.pardir, os.pardir, os.pardir, "python%d.%d" % sys.version_info[:2],
                "site-packages", "spaceskip"))
    raise ImportError("spaceskip: the SpaceSkip plugin is not loaded")


try:
    from .vtkSpaceSkip import vtkSpaceSkippingVolumeMapper
except ImportError as _beside:
    # Embedded in the plugin: the wrapper lies elsewhere (see above).
    try:
        _dir = _wrapped_package_dir()
    except ImportError as _lookup:
        raise ImportError("%s; and the wrapper beside this file: %s" % (_lookup, _beside))
    if not os.path.isdir(_dir):
        raise ImportError("spaceskip: no wrapped module at %s (built with SPACESKIP_WRAP_PYTHON=OFF?)" % _dir)
    __path__.append(_dir)  # noqa: F821 (set by the import system for a package)
    from .vtkSpaceSkip import vtkSpaceSkippingVolumeMapper  # noqa: E402

__all__ = ["vtkSpaceSkippingVolumeMapper"]
