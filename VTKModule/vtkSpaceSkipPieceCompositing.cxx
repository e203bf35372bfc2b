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

#include "spaceskip/PieceOrder.h"
#include "spaceskip/Types.h"
#include "spaceskip/VolumePiece.h"

#include <algorithm>
#include <string>

namespace vtkSpaceSkipPieceCompositing
{

//------------------------------------------------------------------------------
PieceImage Crop(const float* image, int width, int height, const int owned[6])
{
  PieceImage piece;
  std::copy(owned, owned + 6, piece.Owned);
  int x0 = width, y0 = height, x1 = -1, y1 = -1;
  for (int y = 0; image && y < height; ++y)
  {
    const float* c = image + 4 * size_t(y) * size_t(width);
    for (int x = 0; x < width; ++x, c += 4)
    {
      if (c[0] != 0.f || c[1] != 0.f || c[2] != 0.f || c[3] != 0.f)
      {
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
    }
  }
  if (x1 < x0)
  {
    return piece;
  }
  piece.X = x0;
  piece.Y = y0;
  piece.Width = x1 - x0 + 1;
  piece.Height = y1 - y0 + 1;
  piece.Pixels.resize(4 * size_t(piece.Width) * size_t(piece.Height));
  for (int y = 0; y < piece.Height; ++y)
  {
    const float* src = image + 4 * (size_t(y0 + y) * size_t(width) + size_t(x0));
    std::copy(src, src + 4 * size_t(piece.Width),
      piece.Pixels.data() + 4 * size_t(y) * size_t(piece.Width));
  }
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
void Blend(const std::vector<PieceImage>& pieces, const double eye[3], const double dir[3],
  bool parallel, int width, int height, spaceskip::Image& out, double stopAt)
{
  const float stop = static_cast<float>(std::min(stopAt, 2.0));
  std::vector<spaceskip::PieceBox> boxes;
  std::vector<const PieceImage*> parts;
  for (const PieceImage& p : pieces)
  {
    const int* o = p.Owned;
    if (p.Width > 0 && p.Height > 0 && o[0] < o[1] && o[2] < o[3] && o[4] < o[5] && p.X >= 0 &&
      p.Y >= 0 && p.X + p.Width <= width && p.Y + p.Height <= height &&
      p.Pixels.size() == 4 * size_t(p.Width) * size_t(p.Height))
    {
      boxes.push_back({ double(o[0]), double(o[1]), double(o[2]), double(o[3]), double(o[4]), double(o[5]) });
      parts.push_back(&p);
    }
  }
  out.width = width;
  out.height = height;
  out.rgba.assign(size_t(width) * size_t(height), spaceskip::vec4f{ 0, 0, 0, 0 });
  for (size_t i : spaceskip::visibilityOrder(boxes, eye, dir, parallel))
  {
    const PieceImage& p = *parts[i];
    for (int y = 0; y < p.Height; ++y)
    {
      const float* src = p.Pixels.data() + 4 * size_t(y) * size_t(p.Width);
      spaceskip::vec4f* dst = out.rgba.data() + size_t(p.Y + y) * size_t(width) + size_t(p.X);
      for (int x = 0; x < p.Width; ++x, src += 4, ++dst)
      {
        if (dst->w >= stop)
        {
          continue;
        }
        const float t = 1.f - dst->w;
        dst->x += t * src[0];
        dst->y += t * src[1];
        dst->z += t * src[2];
        dst->w += t * src[3];
      }
    }
  }
}

//------------------------------------------------------------------------------
PieceImage CropPiece(const float* image, int width, int height, const spaceskip::VolumePiece& p,
  vtkImageData* input, const int wholeExtent[6])
{
  int ext[6], owned[6];
  input->GetExtent(ext);
  const int shift[3] = { wholeExtent[0], wholeExtent[2], wholeExtent[4] };
  for (int a = 0; a < 3; ++a)
  {
    owned[2 * a] = p.active() ? static_cast<int>(p.ownedLo[a]) : ext[2 * a] - shift[a];
    owned[2 * a + 1] = p.active() ? static_cast<int>(p.ownedHi[a])
                                  : std::max(ext[2 * a + 1], ext[2 * a] + 1) - shift[a];
  }
  return Crop(image, width, height, owned);
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
