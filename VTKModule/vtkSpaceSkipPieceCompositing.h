// vtkSpaceSkipPieceCompositing: float compositing of piece images (MPI ranks' pieces, the blocks
// of partitioned input across ranks) for vtkSpaceSkippingVolumeMapper's PieceExchange.
// Internal to the module (not wrapped, not installed).
#ifndef vtkSpaceSkipPieceCompositing_h
#define vtkSpaceSkipPieceCompositing_h

#include "vtkSpaceSkipPieceExchange.h" // For vtkSpaceSkipPieceImage

#include "vtkSmartPointer.h" // For EmptyPiece

#include <string> // For EmptyPiece
#include <vector> // For the pieces

class vtkImageData;
class vtkRenderer;
class vtkVolume;
namespace spaceskip
{
class PeerImages;
class PieceBlend;
struct Image;
struct VolumePiece;
}

namespace vtkSpaceSkipPieceCompositing
{
using PieceImage = vtkSpaceSkipPieceImage;

/// The rectangle of the pixels `image` (`width` x `height` premultiplied RGBA floats, row 0 at
/// the bottom) drew, as a piece with the cells `owned`; empty when it drew none.
PieceImage Crop(const float* image, int width, int height, const int owned[6]);

/// An image piece's frame left in device memory (`width` x `height` float4 written on `stream`,
/// a cudaStream_t) as a piece of the whole viewport, with the cells it drew as CropPiece() says.
PieceImage DevicePiece(const void* image, void* stream, int width, int height,
  const spaceskip::VolumePiece& piece, vtkImageData* input, const int wholeExtent[6]);

/// Maps the Shared pieces' images (another process's device memory, CUDA IPC) into this
/// process: their Device then reads them. False with `problem` when one could not be mapped (its
/// Device stays null: only its Pixels, if any, are drawn).
bool MapShared(std::vector<PieceImage>& pieces, spaceskip::PeerImages& peers, std::string& problem);

/// Crop() for an image piece: the cells it drew (`piece`, or when inactive its whole extent)
/// in the index space of `wholeExtent` (less its first index).
PieceImage CropPiece(const float* image, int width, int height, const spaceskip::VolumePiece& piece,
  vtkImageData* input, const int wholeExtent[6]);

/// What a process with an empty piece hands ParaView's vtkPVLODVolume as the mapper's input
/// (it draws a mapper only when GetInput() has the selected scalars): an empty image with empty
/// arrays, the first named `arrayName` (point and cell data, up to `arrayId`); `cache` keeps it
/// (made again when `cacheName`, the name it was made for, differs).
vtkImageData* EmptyPiece(const char* arrayName, int arrayId, vtkSmartPointer<vtkImageData>& cache,
  std::string& cacheName);

/// The camera in the index space of `lattice`, less `shift` per axis: the eye, the direction of
/// projection, and whether the projection is parallel.
void CameraInIndexSpace(vtkRenderer* ren, vtkVolume* vol, vtkImageData* lattice,
  const int shift[3], double eye[3], double dir[3], bool& parallel);

/// `pieces` blended front to back in the order the rays meet their boxes
/// (spaceskip::visibilityOrder), in float, into `out` (`width` x `height`). Pieces without cells
/// or outside the viewport are left out. A pixel whose opacity has reached `stopAt` (the early
/// ray termination threshold; above 1: never) takes nothing from the pieces behind: the single
/// image's ray stopped in front of them.
void Blend(const std::vector<PieceImage>& pieces, const double eye[3], const double dir[3],
  bool parallel, int width, int height, spaceskip::Image& out, double stopAt = 2.0);

/// The drawable pieces of `pieces` (cells, a rectangle inside the viewport, pixels in host or
/// device memory), front to back in the order the rays meet their boxes.
std::vector<const PieceImage*> FrontToBack(const std::vector<PieceImage>& pieces, const double eye[3],
  const double dir[3], bool parallel, int width, int height);

/// Copies the pixels of the pieces left in device memory (PieceImage::Device) to Pixels, for
/// Blend(); false with `problem` when a copy fails.
bool ToHost(std::vector<PieceImage>& pieces, std::string& problem);

/// Blend() on the GPU (the calling thread's CUDA device): the pieces in device memory read where
/// they are (this process's frame, the others' mapped through CUDA IPC), those in host memory
/// uploaded; queued on `stream` (a cudaStream_t). The blended image in device memory (`blend`'s,
/// valid until its next blend), or nullptr with `problem`.
const void* BlendOnDevice(const std::vector<PieceImage>& pieces, const double eye[3],
  const double dir[3], bool parallel, int width, int height, double stopAt,
  spaceskip::PieceBlend& blend, void* stream, std::string& problem);
}

#endif
