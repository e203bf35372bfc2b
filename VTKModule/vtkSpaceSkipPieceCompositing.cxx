#include "vtkSpaceSkipPieceCompositing.h"

#include "vtkCamera.h"
#include "vtkCellData.h"
#include "vtkFloatArray.h"
#include "vtkPointData.h"
#include "vtkImageData.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkRenderer.h"
#include "vtkVolume.h"

#include "spaceskip/PeerImages.h"
#include "spaceskip/PieceOrder.h"
#include "spaceskip/Types.h"
#include "spaceskip/VolumePiece.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <string>

namespace vtkSpaceSkipPieceCompositing
{

//------------------------------------------------------------------------------
PieceImage Crop(const float* image, int width, int height, const int owned[6])
{
  PieceImage piece;
  std::copy(owned, owned + 6, piece.Owned);
  // The rectangle of the drawn pixels: rows scanned in parallel (a 1024^2 frame is 16 MB).
  struct Box
  {
    int X0, Y0, X1, Y1;
  };
  const Box none{ width, height, -1, -1 };
  const Box box = !image ? none
                         : tbb::parallel_reduce(
                             tbb::blocked_range<int>(0, height, 16), none,
                             [&](const tbb::blocked_range<int>& r, Box b) {
                               for (int y = r.begin(); y != r.end(); ++y)
                               {
                                 const float* c = image + 4 * size_t(y) * size_t(width);
                                 for (int x = 0; x < width; ++x, c += 4)
                                 {
                                   if (c[0] != 0.f || c[1] != 0.f || c[2] != 0.f || c[3] != 0.f)
                                   {
                                     b.X0 = std::min(b.X0, x);
                                     b.X1 = std::max(b.X1, x);
                                     b.Y0 = std::min(b.Y0, y);
                                     b.Y1 = std::max(b.Y1, y);
                                   }
                                 }
                               }
                               return b;
                             },
                             [](const Box& a, const Box& b) {
                               return Box{ std::min(a.X0, b.X0), std::min(a.Y0, b.Y0),
                                 std::max(a.X1, b.X1), std::max(a.Y1, b.Y1) };
                             });
  if (box.X1 < box.X0)
  {
    return piece;
  }
  piece.X = box.X0;
  piece.Y = box.Y0;
  piece.Width = box.X1 - box.X0 + 1;
  piece.Height = box.Y1 - box.Y0 + 1;
  piece.Pixels.resize(4 * size_t(piece.Width) * size_t(piece.Height));
  tbb::parallel_for(tbb::blocked_range<int>(0, piece.Height, 16), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y != r.end(); ++y)
    {
      const float* src = image + 4 * (size_t(box.Y0 + y) * size_t(width) + size_t(box.X0));
      std::copy(src, src + 4 * size_t(piece.Width),
        piece.Pixels.data() + 4 * size_t(y) * size_t(piece.Width));
    }
  });
  return piece;
}

//------------------------------------------------------------------------------
void CameraInIndexSpace(vtkRenderer* ren, vtkVolume* vol, vtkImageData* lattice,
  const int shift[3], double eye[3], double dir[3], bool& parallel)
{
  vtkCamera* cam = ren->GetActiveCamera();
  parallel = cam->GetParallelProjection() != 0;
  // world -> the volume's data coordinates -> continuous index
  double e[4], f[4], dop[3];
  cam->GetPosition(e);
  cam->GetDirectionOfProjection(dop);
  e[3] = f[3] = 1.0;
  for (int a = 0; a < 3; ++a)
  {
    f[a] = e[a] + dop[a];
  }
  vtkNew<vtkMatrix4x4> toData;
  vtkMatrix4x4::Invert(vol->GetMatrix(), toData);
  toData->MultiplyPoint(e, e);
  toData->MultiplyPoint(f, f);
  double ei[3], fi[3];
  lattice->TransformPhysicalPointToContinuousIndex(e, ei);
  lattice->TransformPhysicalPointToContinuousIndex(f, fi);
  for (int a = 0; a < 3; ++a)
  {
    eye[a] = ei[a] - shift[a];
    dir[a] = fi[a] - ei[a];
  }
}

//------------------------------------------------------------------------------
std::vector<const PieceImage*> FrontToBack(const std::vector<PieceImage>& pieces, const double eye[3],
  const double dir[3], bool parallel, int width, int height)
{
  std::vector<spaceskip::PieceBox> boxes;
  std::vector<const PieceImage*> parts;
  for (const PieceImage& p : pieces)
  {
    const int* o = p.Owned;
    if (p.Width > 0 && p.Height > 0 && o[0] < o[1] && o[2] < o[3] && o[4] < o[5] && p.X >= 0 &&
      p.Y >= 0 && p.X + p.Width <= width && p.Y + p.Height <= height &&
      (p.Device || p.Pixels.size() == 4 * size_t(p.Width) * size_t(p.Height)))
    {
      boxes.push_back({ double(o[0]), double(o[1]), double(o[2]), double(o[3]), double(o[4]), double(o[5]) });
      parts.push_back(&p);
    }
  }
  std::vector<const PieceImage*> ordered;
  for (size_t i : spaceskip::visibilityOrder(boxes, eye, dir, parallel))
  {
    ordered.push_back(parts[i]);
  }
  return ordered;
}

//------------------------------------------------------------------------------
bool ToHost(std::vector<PieceImage>& pieces, std::string& problem)
{
  for (PieceImage& p : pieces)
  {
    const size_t n = size_t(std::max(p.Width, 0)) * size_t(std::max(p.Height, 0));
    if (p.Device && p.Pixels.size() != 4 * n)
    {
      p.Pixels.resize(4 * n);
      if (n && !spaceskip::PeerImages::download(p.Device, n, p.Pixels.data(), problem))
      {
        return false;
      }
    }
  }
  return true;
}

//------------------------------------------------------------------------------
void Blend(const std::vector<PieceImage>& pieces, const double eye[3], const double dir[3],
  bool parallel, int width, int height, spaceskip::Image& out, double stopAt)
{
  const float stop = static_cast<float>(stopAt);
  out.width = width;
  out.height = height;
  out.rgba.assign(size_t(width) * size_t(height), spaceskip::vec4f{ 0, 0, 0, 0 });
  for (const PieceImage* piece : FrontToBack(pieces, eye, dir, parallel, width, height))
  {
    // Pieces one after another (front to back), each one's rows in parallel.
    const PieceImage& p = *piece;
    if (p.Pixels.size() != 4 * size_t(p.Width) * size_t(p.Height))
    {
      continue; // left in device memory (ToHost first)
    }
    tbb::parallel_for(tbb::blocked_range<int>(0, p.Height, 16), [&](const tbb::blocked_range<int>& r) {
      for (int y = r.begin(); y != r.end(); ++y)
      {
        const float* src = p.Pixels.data() + 4 * size_t(y) * size_t(p.Width);
        spaceskip::vec4f* dst = out.rgba.data() + size_t(p.Y + y) * size_t(width) + size_t(p.X);
        for (int x = 0; x < p.Width; ++x, src += 4, ++dst)
        {
          spaceskip::addBehind(*dst, spaceskip::vec4f{ src[0], src[1], src[2], src[3] }, stop);
        }
      }
    });
  }
}

//------------------------------------------------------------------------------
const void* BlendOnDevice(const std::vector<PieceImage>& pieces, const double eye[3],
  const double dir[3], bool parallel, int width, int height, double stopAt,
  spaceskip::PieceBlend& blend, void* stream, std::string& problem)
{
  std::vector<spaceskip::BlendSource> sources;
  for (const PieceImage* p : FrontToBack(pieces, eye, dir, parallel, width, height))
  {
    spaceskip::BlendSource b;
    b.host = !p->Device;
    b.pixels = p->Device ? p->Device : static_cast<const void*>(p->Pixels.data());
    b.rowPixels = size_t(p->Width);
    b.x = p->X;
    b.y = p->Y;
    b.w = p->Width;
    b.h = p->Height;
    sources.push_back(b);
  }
  return blend.blend(sources, width, height, static_cast<float>(stopAt), stream, problem);
}

//------------------------------------------------------------------------------
namespace
{
// The cells a piece drew (`piece`, or when inactive its whole extent) in the index space of
// `wholeExtent` (less its first index).
void OwnedCells(const spaceskip::VolumePiece& p, vtkImageData* input, const int wholeExtent[6], int owned[6])
{
  int ext[6];
  input->GetExtent(ext);
  const int shift[3] = { wholeExtent[0], wholeExtent[2], wholeExtent[4] };
  for (int a = 0; a < 3; ++a)
  {
    owned[2 * a] = p.active() ? static_cast<int>(p.ownedLo[a]) : ext[2 * a] - shift[a];
    owned[2 * a + 1] = p.active() ? static_cast<int>(p.ownedHi[a])
                                  : std::max(ext[2 * a + 1], ext[2 * a] + 1) - shift[a];
  }
}
}

//------------------------------------------------------------------------------
PieceImage CropPiece(const float* image, int width, int height, const spaceskip::VolumePiece& p,
  vtkImageData* input, const int wholeExtent[6])
{
  int owned[6];
  OwnedCells(p, input, wholeExtent, owned);
  return Crop(image, width, height, owned);
}

//------------------------------------------------------------------------------
PieceImage DevicePiece(const void* image, void* stream, int width, int height,
  const spaceskip::VolumePiece& p, vtkImageData* input, const int wholeExtent[6])
{
  PieceImage piece;
  OwnedCells(p, input, wholeExtent, piece.Owned);
  piece.Width = width;
  piece.Height = height;
  piece.Device = image;
  piece.Stream = stream;
  return piece;
}

//------------------------------------------------------------------------------
bool MapShared(std::vector<PieceImage>& pieces, spaceskip::PeerImages& peers, std::string& problem)
{
  bool all = true;
  for (PieceImage& p : pieces)
  {
    if (!p.Shared || p.Device)
    {
      continue;
    }
    spaceskip::PeerImages::Handle handle;
    std::copy_n(p.Handle, handle.size(), handle.begin());
    p.Device = peers.map(p.Source, handle, problem);
    all = all && p.Device;
  }
  return all;
}

//------------------------------------------------------------------------------
vtkImageData* EmptyPiece(const char* arrayName, int arrayId, vtkSmartPointer<vtkImageData>& cache,
  std::string& cacheName)
{
  const std::string name = arrayName ? arrayName : "";
  if (cache && cacheName == name)
  {
    return cache;
  }
  cacheName = name;
  cache = vtkSmartPointer<vtkImageData>::New();
  for (vtkDataSetAttributes* attributes :
    { static_cast<vtkDataSetAttributes*>(cache->GetPointData()),
      static_cast<vtkDataSetAttributes*>(cache->GetCellData()) })
  {
    for (int i = 0; i <= std::max(arrayId, 0) && i < 16; ++i)
    {
      vtkNew<vtkFloatArray> array;
      array->SetName(i == 0 && !name.empty() ? name.c_str() : ("empty piece " + std::to_string(i)).c_str());
      attributes->AddArray(array);
    }
    attributes->SetActiveScalars(attributes->GetAbstractArray(0)->GetName());
  }
  return cache;
}
}
