// vtkSpaceSkipPieceCompositing: float compositing of piece images (MPI ranks' pieces, the blocks
// of partitioned input across ranks) for vtkSpaceSkippingVolumeMapper's PieceExchange.
// Internal to the module (not wrapped, not installed).
#ifndef vtkSpaceSkipPieceCompositing_h
#define vtkSpaceSkipPieceCompositing_h

#include "vtkSpaceSkippingVolumeMapper.h" // For PieceImage

#include <vector> // For the pieces

class vtkImageData;
class vtkRenderer;
class vtkVolume;
namespace spaceskip
{
struct Image;
}

namespace vtkSpaceSkipPieceCompositing
{
using PieceImage = vtkSpaceSkippingVolumeMapper::PieceImage;

/// The rectangle of the pixels `image` (`width` x `height` premultiplied RGBA floats, row 0 at
/// the bottom) drew, as a piece with the cells `owned`; empty when it drew none.
PieceImage Crop(const float* image, int width, int height, const int owned[6]);

/// The camera in the index space of `lattice`, less `shift` per axis: the eye, the direction of
/// projection, and whether the projection is parallel.
void CameraInIndexSpace(vtkRenderer* ren, vtkVolume* vol, vtkImageData* lattice,
  const int shift[3], double eye[3], double dir[3], bool& parallel);

/// `pieces` blended front to back in the order the rays meet their boxes
/// (spaceskip::visibilityOrder), in float, into `out` (`width` x `height`). Pieces without cells
/// or outside the viewport are left out.
void Blend(const std::vector<PieceImage>& pieces, const double eye[3], const double dir[3],
  bool parallel, int width, int height, spaceskip::Image& out);
}

#endif
