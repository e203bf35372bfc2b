"""SpaceSkip for VTK Python: vtkSpaceSkippingVolumeMapper, wrapped against ParaView's VTK.

    from spaceskip import vtkSpaceSkippingVolumeMapper      # or: from spaceskip.vtkSpaceSkip import ...
"""
from .vtkSpaceSkip import vtkSpaceSkippingVolumeMapper

__all__ = ["vtkSpaceSkippingVolumeMapper"]
