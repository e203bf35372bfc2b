// A volume that is one piece of a larger one, rendered separately and composited in visibility
// order (ParaView's pvbatch/pvserver under MPI): where the piece lies in the whole volume's voxel
// lattice and which cells it draws. With it the engine samples exactly where a render of the
// whole volume would (render/RayGen.h), so the composited pieces give the serial image.
#pragma once
#include "Math.h"

namespace spaceskip {

struct VolumePiece {
  /// Voxels of the whole volume per axis; 0 (the default): the volume is whole (serial).
  vec3l wholeDims{0, 0, 0};
  /// World position of the whole volume's voxel (0,0,0). Rays are built relative to it, so every
  /// rank must pass the same bits (compute it the same way everywhere, e.g. VTK's
  /// TransformIndexToPhysicalPoint of the whole extent's first index).
  double wholeOrigin[3] = {0, 0, 0};
  /// Index of the piece's voxel (0,0,0) in the whole volume.
  vec3l offset{0, 0, 0};
  /// The cells the piece draws, [ownedLo, ownedHi) in whole-volume cell indices, inside the
  /// piece's own cells; voxels around them (ghost layers) are only read by interpolation and
  /// gradients. Pieces that share a face own the cells on either side: each sample is drawn once.
  vec3l ownedLo{0, 0, 0};
  vec3l ownedHi{0, 0, 0};
  /// Added to the premultiplied colour of pixels whose ray goes on into a piece behind this one.
  /// ParaView's IceT blends 8-bit pieces as front + floor(back * (255 - alpha) / 255), losing
  /// half a unit on average; 0.5 / 255 rounds the front piece up by as much. 0: the exact colour.
  float followBias = 0.f;

  bool active() const { return wholeDims.x > 0 && wholeDims.y > 0 && wholeDims.z > 0; }
  bool operator==(const VolumePiece& o) const {
    for (int a = 0; a < 3; ++a)
      if (wholeDims[a] != o.wholeDims[a] || wholeOrigin[a] != o.wholeOrigin[a] || offset[a] != o.offset[a] ||
          ownedLo[a] != o.ownedLo[a] || ownedHi[a] != o.ownedHi[a])
        return false;
    return followBias == o.followBias;
  }
  bool operator!=(const VolumePiece& o) const { return !(*this == o); }
};

}  // namespace spaceskip
