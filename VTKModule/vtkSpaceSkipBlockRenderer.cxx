// vtkSpaceSkipBlockRenderer: one vtkSpaceSkippingVolumeMapper per image block of a composite
// input, drawn back to front (vtkMultiBlockVolumeMapper's scheme).
#include "vtkSpaceSkipBlockRenderer.h"

#include "spaceskip/PieceOrder.h"
#include "vtkSpaceSkipPieceCompositing.h"

#include "vtkCamera.h"
#include "vtkCellData.h"
#include "vtkCompositeDataIterator.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkMath.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPointData.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkScalarsToColors.h"
#include "vtkSpaceSkipCompositor.h"
#include "vtkStructuredData.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "spaceskip/Tuning.h"
#include "spaceskip/Types.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <set>

namespace
{
// Above this many image blocks the per-block engines and frame buffers are said to be costly.
constexpr size_t kManyBlocks = 64;

// The parent's settings, as vtkMultiBlockVolumeMapper hands its own to each block's mapper.
// `padded`: the block is a copy holding the drawn scalars alone, as its active point scalars.
void CopySettings(vtkSpaceSkippingVolumeMapper* from, vtkSpaceSkippingVolumeMapper* to, bool padded)
{
  to->SetBuilder(from->GetBuilder());
  to->SetLeafCriterion(from->GetLeafCriterion());
  to->SetMaxLeafSize(from->GetMaxLeafSize());
  to->SetBinCount(from->GetBinCount());
  to->SetMacroCellSize(from->GetMacroCellSize());
  to->SetSampleDistance(from->GetSampleDistance());
  to->SetBackend(from->GetBackend());
  to->SetFilterMode(from->GetFilterMode());
  to->SetEarlyRayTermination(from->GetEarlyRayTermination());
  to->SetEightBitComposite(from->GetEightBitComposite());
  to->SetGPUComposite(from->GetGPUComposite());
  to->SetUseJittering(from->GetUseJittering());
  to->SetDeviceMemoryBudget(from->GetDeviceMemoryBudget());
  to->SetTuning(from->GetTuning());
  to->SetVectorMode(from->GetVectorMode());
  to->SetVectorComponent(from->GetVectorComponent());
  to->SetBlendModeOverride(from->GetBlendModeOverride());
  to->SetBlendMode(from->GetBlendMode());
  to->SetAverageIPScalarRange(from->GetAverageIPScalarRange());
  to->SetScalarMode(padded ? VTK_SCALAR_MODE_USE_POINT_DATA : from->GetScalarMode());
  if (padded)
  {
    // the active scalars: nothing to select
  }
  else if (from->GetArrayAccessMode() == VTK_GET_ARRAY_BY_ID)
  {
    to->SelectScalarArray(from->GetArrayId());
  }
  else
  {
    to->SelectScalarArray(from->GetArrayName());
  }
  to->SetCropping(from->GetCropping());
  to->SetCroppingRegionFlags(from->GetCroppingRegionFlags());
  to->SetCroppingRegionPlanes(from->GetCroppingRegionPlanes());
  if (to->GetClippingPlanes() != from->GetClippingPlanes())
  {
    to->SetClippingPlanes(from->GetClippingPlanes());
  }
}

// Finite range of what the block mapper will draw from `image` (its converter's choice of
// component or magnitude); false when the block has no such point scalars.
bool BlockRange(vtkSpaceSkippingVolumeMapper* parent, vtkImageData* image, double range[2])
{
  int cellFlag = 0;
  vtkDataArray* scalars = vtkAbstractMapper::GetScalars(image, parent->GetScalarMode(),
    parent->GetArrayAccessMode(), parent->GetArrayId(), parent->GetArrayName(), cellFlag);
  if (!scalars || cellFlag != 0 || scalars->GetNumberOfTuples() == 0)
  {
    return false;
  }
  const int n = scalars->GetNumberOfComponents();
  int comp = 0;
  if (n > 1)
  {
    comp = parent->GetVectorMode() == vtkScalarsToColors::MAGNITUDE
      ? -1
      : std::min(std::max(parent->GetVectorComponent(), 0), n - 1);
  }
  scalars->GetFiniteRange(range, comp);
  return range[0] <= range[1];
}

// The point scalars the parent draws from `image` (its scalar mode and array), or null.
vtkDataArray* SelectedScalars(vtkSpaceSkippingVolumeMapper* parent, vtkImageData* image)
{
  int cellFlag = 0;
  vtkDataArray* scalars = vtkAbstractMapper::GetScalars(image, parent->GetScalarMode(),
    parent->GetArrayAccessMode(), parent->GetArrayId(), parent->GetArrayName(), cellFlag);
  return scalars && cellFlag == 0 ? scalars : nullptr;
}

// The cells of an image block that no ghost array marks as duplicates, [lo, hi) per axis in
// its own extent's indices (as the mapper's PieceOf); false when all are duplicates.
bool OwnCells(vtkImageData* image, int cells[6])
{
  int ext[6];
  image->GetExtent(ext);
  for (int a = 0; a < 3; ++a)
  {
    cells[2 * a] = ext[2 * a];
    cells[2 * a + 1] = ext[2 * a + 1];
  }
  vtkUnsignedCharArray* g = image->GetCellData()->GetGhostArray();
  if (!g || g->GetNumberOfTuples() == 0)
  {
    return true;
  }
  const vtkIdType n = g->GetNumberOfTuples();
  const unsigned char* v = g->GetPointer(0);
  const unsigned char dup = vtkDataSetAttributes::DUPLICATECELL;
  vtkIdType first = 0, last = n - 1;
  while (first < n && (v[first] & dup))
  {
    ++first;
  }
  while (last >= 0 && (v[last] & dup))
  {
    --last;
  }
  if (first > last)
  {
    return false;
  }
  int ijk[3], ijk1[3];
  vtkStructuredData::ComputeCellStructuredCoordsForExtent(first, ext, ijk);
  vtkStructuredData::ComputeCellStructuredCoordsForExtent(last, ext, ijk1);
  for (int a = 0; a < 3; ++a)
  {
    cells[2 * a] = ijk[a];
    cells[2 * a + 1] = ijk1[a] + 1;
  }
  return true;
}

// Copies the points of `from` (extent fromExt, array src) inside `box` into `to` (extent
// toExt, array dst of the same type and components): row by row for standard layouts.
void CopyRegion(vtkDataArray* src, const int fromExt[6], vtkDataArray* dst, const int toExt[6],
  const int box[6])
{
  const int nc = src->GetNumberOfComponents();
  const vtkIdType fx = fromExt[1] - fromExt[0] + 1, fy = fromExt[3] - fromExt[2] + 1;
  const vtkIdType tx = toExt[1] - toExt[0] + 1, ty = toExt[3] - toExt[2] + 1;
  const int rowLength = box[1] - box[0] + 1;
  const bool raw = src->HasStandardMemoryLayout() && dst->HasStandardMemoryLayout() &&
    src->GetDataType() == dst->GetDataType();
  const size_t tupleBytes = static_cast<size_t>(src->GetDataTypeSize()) * nc;
  for (int k = box[4]; k <= box[5]; ++k)
  {
    for (int j = box[2]; j <= box[3]; ++j)
    {
      const vtkIdType s =
        ((k - fromExt[4]) * fy + (j - fromExt[2])) * fx + (box[0] - fromExt[0]);
      const vtkIdType d = ((k - toExt[4]) * ty + (j - toExt[2])) * tx + (box[0] - toExt[0]);
      if (raw)
      {
        std::memcpy(dst->GetVoidPointer(d * nc), src->GetVoidPointer(s * nc),
          tupleBytes * static_cast<size_t>(rowLength));
      }
      else
      {
        for (int i = 0; i < rowLength; ++i)
        {
          dst->SetTuple(d + i, s + i, src);
        }
      }
    }
  }
}
} // namespace

//------------------------------------------------------------------------------
vtkSpaceSkipBlockRenderer::vtkSpaceSkipBlockRenderer() = default;
vtkSpaceSkipBlockRenderer::~vtkSpaceSkipBlockRenderer() = default;

//------------------------------------------------------------------------------
bool vtkSpaceSkipBlockRenderer::IsComposite(vtkDataObject* input)
{
  return vtkCompositeDataSet::SafeDownCast(input) != nullptr;
}

//------------------------------------------------------------------------------
vtkImageData* vtkSpaceSkipBlockRenderer::FirstImage(vtkDataObject* input)
{
  auto* cds = vtkCompositeDataSet::SafeDownCast(input);
  if (!cds)
  {
    return nullptr;
  }
  vtkSmartPointer<vtkCompositeDataIterator> it;
  it.TakeReference(cds->NewIterator());
  for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
  {
    auto* image = vtkImageData::SafeDownCast(it->GetCurrentDataObject());
    if (image && image->GetNumberOfPoints() > 0)
    {
      return image;
    }
  }
  return nullptr;
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipBlockRenderer::ComputeBounds(vtkDataObject* input, double bounds[6])
{
  vtkMath::UninitializeBounds(bounds);
  auto* cds = vtkCompositeDataSet::SafeDownCast(input);
  if (!cds)
  {
    return false;
  }
  bool any = false;
  vtkSmartPointer<vtkCompositeDataIterator> it;
  it.TakeReference(cds->NewIterator());
  for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
  {
    auto* image = vtkImageData::SafeDownCast(it->GetCurrentDataObject());
    if (!image || image->GetNumberOfPoints() == 0)
    {
      continue;
    }
    double b[6];
    image->GetBounds(b);
    for (int a = 0; a < 3; ++a)
    {
      bounds[2 * a] = any ? std::min(bounds[2 * a], b[2 * a]) : b[2 * a];
      bounds[2 * a + 1] = any ? std::max(bounds[2 * a + 1], b[2 * a + 1]) : b[2 * a + 1];
    }
    any = true;
  }
  return any;
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipBlockRenderer::Render(vtkSpaceSkippingVolumeMapper* parent,
  vtkDataObject* input, vtkRenderer* ren, vtkVolume* vol, const WarnFunction& warnOnce,
  std::string& problem)
{
  this->Active = true;
  if (this->SumImage)
  {
    this->SumImage->rgba.clear(); // DrawSum() draws this frame's blocks or nothing
  }
  auto* cds = vtkCompositeDataSet::SafeDownCast(input);
  std::vector<vtkImageData*> images;
  std::set<std::string> others;
  vtkSmartPointer<vtkCompositeDataIterator> it;
  it.TakeReference(cds->NewIterator());
  for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
  {
    vtkDataObject* leaf = it->GetCurrentDataObject();
    auto* image = vtkImageData::SafeDownCast(leaf);
    if (image)
    {
      if (image->GetNumberOfPoints() > 0)
      {
        images.push_back(image);
      }
    }
    else if (leaf)
    {
      others.insert(leaf->GetClassName());
    }
  }
  if (!others.empty())
  {
    std::string names;
    for (const std::string& n : others)
    {
      names += (names.empty() ? "" : ", ") + n;
    }
    warnOnce("composite input: blocks of type " + names +
      " are not drawn (vtkSpaceSkippingVolumeMapper draws vtkImageData blocks only; resample "
      "rectilinear or unstructured data to an image first)");
  }

  if (images.size() > kManyBlocks)
  {
    warnOnce("composite input with more than " + std::to_string(kManyBlocks) +
      " image blocks: each block has its own engine, hierarchy and frame-sized image buffer, so "
      "memory and time grow with the block count (merge blocks, e.g. with Merge Blocks or "
      "Resample To Image, for many small pieces)");
  }

  // One block mapper per image leaf, reused in leaf order; the surplus goes (with its GL
  // resources, while the context is current).
  while (this->Blocks.size() > images.size())
  {
    this->Blocks.back().Mapper->ReleaseGraphicsResources(ren->GetRenderWindow());
    this->Blocks.pop_back();
  }
  this->Blocks.resize(images.size());

  // The table range every block uses: the union of the blocks' ranges, i.e. the range one
  // image of all the blocks would have.
  double range[2] = { std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest() };
  bool anyScalars = false;
  for (vtkImageData* image : images)
  {
    double r[2];
    if (BlockRange(parent, image, r))
    {
      range[0] = std::min(range[0], r[0]);
      range[1] = std::max(range[1], r[1]);
      anyScalars = true;
    }
  }
  if (images.empty() && others.empty())
  {
    // An empty composite data set (e.g. a rank's share of a few partitions): nothing to draw.
    this->Blocks.clear();
    ++this->Frames;
    return true;
  }
  // Under MPI the range of all ranks' blocks (the representation gathers it).
  const double* wholeRange = parent->GetWholeScalarRange();
  if (anyScalars && wholeRange[0] <= wholeRange[1])
  {
    range[0] = wholeRange[0];
    range[1] = wholeRange[1];
  }
  if (images.empty() || !anyScalars)
  {
    problem = images.empty()
      ? "composite input without a vtkImageData block: nothing drawn"
      : "no block of the composite input has the selected point scalars: nothing drawn";
    this->Blocks.clear();
    return false;
  }

  // The blocks on one lattice when they lie on one (else each on its own, with one warning).
  for (size_t i = 0; i < images.size(); ++i)
  {
    Block& b = this->Blocks[i];
    if (!b.Mapper)
    {
      b.Mapper = vtkSmartPointer<vtkSpaceSkippingVolumeMapper>::New();
    }
    if (b.Image != images[i])
    {
      b.Image = images[i];
      b.Piece = nullptr;
    }
  }
  vtkVolumeProperty* prop = vol->GetProperty();
  // Shading's central differences (and slice mode's sample, up to half a voxel off the plane)
  // read one voxel past a block's own cells.
  const int layers =
    (prop && prop->GetShade(0)) || parent->EffectiveBlendMode() == vtkVolumeMapper::SLICE_BLEND ? 1 : 0;
  std::vector<unsigned long long> key{ static_cast<unsigned long long>(layers),
    static_cast<unsigned long long>(parent->GetScalarMode()),
    static_cast<unsigned long long>(parent->GetArrayAccessMode()),
    static_cast<unsigned long long>(parent->GetArrayId()),
    std::hash<std::string>()(parent->GetArrayName() ? parent->GetArrayName() : "") };
  for (int i = 0; i < 6; ++i)
  {
    key.push_back(static_cast<unsigned long long>(static_cast<long long>(parent->GetWholeExtent()[i])));
  }
  for (int a = 0; a < 3; ++a)
  {
    unsigned long long bits = 0;
    std::memcpy(&bits, &parent->GetWholeOrigin()[a], sizeof(bits));
    key.push_back(bits);
  }
  for (vtkImageData* image : images)
  {
    vtkDataArray* a = SelectedScalars(parent, image);
    key.insert(key.end(),
      { reinterpret_cast<unsigned long long>(image), image->GetMTime(),
        reinterpret_cast<unsigned long long>(a), a ? a->GetMTime() : 0ULL });
  }
  if (key != this->PlanKey)
  {
    this->PlanKey = key;
    std::string why;
    this->OnLattice = this->PlanLattice(parent, layers, why);
    this->OffLatticeWhy = why;
  }
  if (!this->OnLattice)
  {
    warnOnce("composite input: the image blocks are not drawn on one sample lattice (" +
      this->OffLatticeWhy +
      "): each block samples from its own box entry, so its faces may show seams (resample the "
      "blocks to one image, e.g. with Resample To Image, for an exact render)");
  }

  vtkCamera* cam = ren->GetActiveCamera();
  double eye[3], dop[3];
  cam->GetPosition(eye);
  cam->GetDirectionOfProjection(dop);
  const bool parallel = cam->GetParallelProjection() != 0;
  vtkMatrix4x4* matrix = vol->GetMatrix();
  for (Block& b : this->Blocks)
  {
    CopySettings(parent, b.Mapper, this->OnLattice && b.Draws && b.Padded);
    b.Mapper->SetTableRange(range);
    b.Mapper->DeferDraw = true;
    if (this->OnLattice && b.Draws)
    {
      if (b.Mapper->GetInputDataObject(0, 0) != b.Piece)
      {
        b.Mapper->SetInputData(b.Piece);
      }
      b.Mapper->SetWholeExtent(this->WholeExtent);
      b.Mapper->SetBlockOwnedCells(b.Owned);
    }
    else
    {
      if (b.Mapper->GetInputDataObject(0, 0) != b.Image)
      {
        b.Mapper->SetInputData(b.Image);
      }
      const int none[6] = { 0, -1, 0, -1, 0, -1 };
      b.Mapper->SetWholeExtent(none);
      b.Mapper->SetBlockOwnedCells(nullptr);
    }
    double bounds[6];
    b.Image->GetBounds(bounds);
    double c[4] = { 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
      0.5 * (bounds[4] + bounds[5]), 1.0 };
    matrix->MultiplyPoint(c, c);
    const double d[3] = { c[0] - eye[0], c[1] - eye[1], c[2] - eye[2] };
    b.Depth = parallel ? vtkMath::Dot(d, dop) : vtkMath::Norm(d);
  }

  // Every block into its float image, front to back in visibility order, each ray going on
  // with the opacity the blocks in front gave it (so early ray termination stops where the
  // single image's ray stops), the images summed per pixel in float: the sum goes to the window
  // once (one rounding to 8 bits, not one per block).
  const std::vector<size_t> order = this->VisibilityOrder(ren, vol);
  int width = 0, height = 0, x0 = 0, y0 = 0;
  ren->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
  ++this->Frames;
  if (width <= 0 || height <= 0)
  {
    return true;
  }
  if (!this->SumImage)
  {
    this->SumImage.reset(new spaceskip::Image);
  }
  spaceskip::Image& sum = *this->SumImage;
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  sum.width = width;
  sum.height = height;
  sum.rgba.assign(pixels, spaceskip::vec4f{ 0, 0, 0, 0 });
  this->Alpha.assign(pixels, 0.f);
  // Composite and isosurface blending accumulate opacity along the ray; the other modes'
  // blocks are blended over one another (not exact across block faces: see README).
  const int mode = parent->EffectiveBlendMode();
  const int* given = parent->GetWholeExtent();
  const bool anchored = given[0] <= given[1] && given[2] <= given[3] && given[4] <= given[5];
  // MPI with a piece exchange: each block's image goes to the exchange on its own (another
  // rank's blocks may lie between two of ours along a ray), without the carried opacity.
  std::vector<vtkSpaceSkippingVolumeMapper::PieceImage>* pieces =
    this->OnLattice && anchored ? this->ExchangePieces : nullptr;
  const bool carry = this->OnLattice && !pieces &&
    (mode == vtkVolumeMapper::COMPOSITE_BLEND || mode == vtkVolumeMapper::ISOSURFACE_BLEND);
  bool drew = false;
  for (size_t i : order)
  {
    vtkSpaceSkippingVolumeMapper* m = this->Blocks[i].Mapper;
    m->IncomingAlpha = carry && drew ? this->Alpha.data() : nullptr;
    m->Render(ren, vol);
    m->IncomingAlpha = nullptr;
    int w = 0, h = 0;
    const float* img = m->GetDeferredImage(w, h);
    if (!img || w != width || h != height)
    {
      continue;
    }
    drew = true;
    if (pieces)
    {
      pieces->push_back(vtkSpaceSkipPieceCompositing::Crop(img, w, h, this->Blocks[i].Owned));
    }
    spaceskip::vec4f* out = sum.rgba.data();
    float* alpha = this->Alpha.data();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, size_t(1) << 14),
      [img, out, alpha, carry](const tbb::blocked_range<size_t>& r) {
        for (size_t p = r.begin(); p < r.end(); ++p)
        {
          const float* c = img + 4 * p;
          spaceskip::vec4f& acc = out[p];
          // carry: the block's colour is already weighted by what lies in front of it
          const float t = carry ? 1.f : 1.f - acc.w;
          acc.x += t * c[0];
          acc.y += t * c[1];
          acc.z += t * c[2];
          acc.w += t * c[3];
          alpha[p] = acc.w;
        }
      });
  }
  if (!drew)
  {
    return true; // the blocks said why (or none was in view)
  }
  if (pieces)
  {
    return true; // the parent hands them to the exchange (DrawSum() if that is off)
  }
  if (this->OnLattice && carry && anchored)
  {
    // Under MPI IceT blends the ranks' images in 8 bits and truncates: where a ray goes on into
    // another rank's blocks, this rank's colour is raised by half a unit, as a single piece's is
    // (VolumePiece::followBias; Tuning::pieceBias, in 1/255).
    const float bias = static_cast<float>(parent->GetTuning().pieceBias / 255.0);
    if (bias != 0.f)
    {
      this->AddFollowBias(ren, vol, bias);
    }
  }
  if (!this->DrawSum(ren, parent->GetEightBitComposite() != 0))
  {
    problem = "could not compile the compositing shader: nothing drawn";
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipBlockRenderer::PlanLattice(
  vtkSpaceSkippingVolumeMapper* parent, int layers, std::string& why)
{
  const size_t n = this->Blocks.size();
  vtkImageData* firstImage = this->Blocks[0].Image;
  double spacing[3], origin[3];
  firstImage->GetSpacing(spacing);
  firstImage->GetOrigin(origin);
  vtkMatrix3x3* dir = firstImage->GetDirectionMatrix();
  // The lattice's index space: the whole image's the parent was given (MPI: all ranks' blocks,
  // its first point at WholeOrigin, the same bits on every rank), else the first block's.
  const int* given = parent->GetWholeExtent();
  const bool anchored = given[0] <= given[1] && given[2] <= given[3] && given[4] <= given[5];
  if (anchored)
  {
    const double* o = parent->GetWholeOrigin();
    for (int a = 0; a < 3; ++a)
    {
      origin[a] = o[a];
    }
    if (given[0] != 0 || given[2] != 0 || given[4] != 0)
    {
      // the point of index given[lo] at WholeOrigin
      double shift[3] = { given[0] * spacing[0], given[2] * spacing[1], given[4] * spacing[2] };
      dir->MultiplyPoint(shift, shift);
      for (int a = 0; a < 3; ++a)
      {
        origin[a] -= shift[a];
      }
    }
  }
  this->Lattice = vtkSmartPointer<vtkImageData>::New();
  this->Lattice->SetOrigin(origin);
  this->Lattice->SetSpacing(spacing);
  this->Lattice->SetDirectionMatrix(dir);
  vtkImageData* ref = this->Lattice;
  std::vector<std::array<int, 6>> pts(n), cells(n), owned(n);
  std::vector<vtkDataArray*> arrays(n);
  for (size_t i = 0; i < n; ++i)
  {
    Block& b = this->Blocks[i];
    b.Piece = nullptr;
    vtkImageData* im = b.Image;
    double s[3];
    im->GetSpacing(s);
    for (int a = 0; a < 3; ++a)
    {
      if (!(std::abs(s[a] - spacing[a]) <= 1e-6 * std::abs(spacing[a])))
      {
        why = "blocks of different spacing";
        return false;
      }
    }
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        if (std::abs(im->GetDirectionMatrix()->GetElement(r, c) - dir->GetElement(r, c)) > 1e-9)
        {
          why = "blocks of different orientation";
          return false;
        }
      }
    }
    int ext[6];
    im->GetExtent(ext);
    double p[3], idx[3];
    im->TransformIndexToPhysicalPoint(ext[0], ext[2], ext[4], p);
    ref->TransformPhysicalPointToContinuousIndex(p, idx);
    int own[6];
    b.Draws = OwnCells(im, own);
    for (int a = 0; a < 3; ++a)
    {
      if (ext[2 * a] == ext[2 * a + 1])
      {
        why = "a block one point thick";
        return false;
      }
      const double r = std::round(idx[a]);
      if (!(std::abs(idx[a] - r) <= 1e-3))
      {
        why = "block origins a fraction of a voxel apart";
        return false;
      }
      const int shift = static_cast<int>(r) - ext[2 * a];
      pts[i][2 * a] = ext[2 * a] + shift;
      pts[i][2 * a + 1] = ext[2 * a + 1] + shift;
      cells[i][2 * a] = own[2 * a] + shift;
      cells[i][2 * a + 1] = own[2 * a + 1] + shift;
    }
    arrays[i] = SelectedScalars(parent, im);
    b.Draws = b.Draws && arrays[i] && arrays[i]->GetNumberOfTuples() == im->GetNumberOfPoints();
  }
  // The whole image: the union of the drawn blocks' points.
  bool any = false;
  int whole[6] = { 0, -1, 0, -1, 0, -1 };
  vtkDataArray* first = nullptr;
  for (size_t i = 0; i < n; ++i)
  {
    if (!this->Blocks[i].Draws)
    {
      continue;
    }
    if (first && (arrays[i]->GetDataType() != first->GetDataType() ||
                   arrays[i]->GetNumberOfComponents() != first->GetNumberOfComponents()))
    {
      why = "blocks with different scalar types";
      return false;
    }
    first = first ? first : arrays[i];
    for (int a = 0; a < 3; ++a)
    {
      whole[2 * a] = any ? std::min(whole[2 * a], pts[i][2 * a]) : pts[i][2 * a];
      whole[2 * a + 1] = any ? std::max(whole[2 * a + 1], pts[i][2 * a + 1]) : pts[i][2 * a + 1];
    }
    any = true;
  }
  if (!any)
  {
    why = "no block with the drawn scalars";
    return false;
  }
  if (anchored)
  {
    for (size_t i = 0; i < n; ++i)
    {
      for (int a = 0; a < 3 && this->Blocks[i].Draws; ++a)
      {
        if (pts[i][2 * a] < given[2 * a] || pts[i][2 * a + 1] > given[2 * a + 1])
        {
          why = "a block outside the whole extent given to the mapper";
          return false;
        }
      }
    }
    std::copy(given, given + 6, whole);
  }
  // Owned cells: the block's own (non-duplicate) cells, and the cell layer past its last points
  // where a neighbour starts one point further on (blocks that do not share their face points).
  // `cells` and `owned` are [lo, hi) per axis.
  auto sideBySide = [&](size_t i, size_t j, int axis) {
    for (int b = 0; b < 3; ++b)
    {
      if (b != axis && !(cells[i][2 * b] < cells[j][2 * b + 1] && cells[j][2 * b] < cells[i][2 * b + 1]))
      {
        return false;
      }
    }
    return true;
  };
  for (size_t i = 0; i < n; ++i)
  {
    owned[i] = cells[i];
    if (!this->Blocks[i].Draws)
    {
      continue;
    }
    for (int a = 0; a < 3; ++a)
    {
      const int h = cells[i][2 * a + 1]; // the first cell past the block's own
      if (h != pts[i][2 * a + 1])
      {
        continue; // ghost cells on that side: the next block's
      }
      bool gapNeighbour = false, covered = false;
      for (size_t j = 0; j < n; ++j)
      {
        if (j == i || !this->Blocks[j].Draws || !sideBySide(i, j, a))
        {
          continue;
        }
        gapNeighbour = gapNeighbour || pts[j][2 * a] == h + 1;
        covered = covered || (cells[j][2 * a] <= h && h < cells[j][2 * a + 1]);
      }
      if (gapNeighbour && !covered)
      {
        owned[i][2 * a + 1] = h + 1;
      }
    }
  }
  for (size_t i = 0; i < n; ++i)
  {
    for (size_t j = i + 1; j < n && this->Blocks[i].Draws; ++j)
    {
      bool overlap = this->Blocks[j].Draws;
      for (int a = 0; a < 3 && overlap; ++a)
      {
        overlap = owned[i][2 * a] < owned[j][2 * a + 1] && owned[j][2 * a] < owned[i][2 * a + 1];
      }
      if (overlap)
      {
        why = "blocks overlap by more than a face of points, and no ghost array marks the "
              "duplicated cells";
        return false;
      }
    }
  }

  // Each block as a piece of the whole: its arrays on the first block's lattice, or, when its
  // cells (and the layers around them) read points of other blocks, a copy padded with them.
  for (size_t i = 0; i < n; ++i)
  {
    Block& b = this->Blocks[i];
    if (!b.Draws)
    {
      continue;
    }
    int need[6];
    bool inside = true;
    for (int a = 0; a < 3; ++a)
    {
      need[2 * a] = std::max(whole[2 * a], owned[i][2 * a] - layers);
      need[2 * a + 1] = std::min(whole[2 * a + 1], owned[i][2 * a + 1] + layers);
      inside = inside && pts[i][2 * a] <= need[2 * a] && need[2 * a + 1] <= pts[i][2 * a + 1];
    }
    auto piece = vtkSmartPointer<vtkImageData>::New();
    b.Padded = !inside;
    if (inside)
    {
      piece->ShallowCopy(b.Image);
      piece->SetExtent(pts[i].data());
    }
    else
    {
      piece->SetExtent(need);
      const vtkIdType count = piece->GetNumberOfPoints();
      vtkSmartPointer<vtkDataArray> copy;
      copy.TakeReference(arrays[i]->NewInstance());
      copy->SetNumberOfComponents(arrays[i]->GetNumberOfComponents());
      copy->SetNumberOfTuples(count);
      copy->SetName(arrays[i]->GetName() ? arrays[i]->GetName() : "scalars");
      std::vector<unsigned char> filled(static_cast<size_t>(count), 0);
      // The other blocks' points, then the block's own (its values win where they overlap).
      for (size_t k = 0; k <= n; ++k)
      {
        const size_t j = k < n ? k : i;
        if ((k < n && j == i) || !this->Blocks[j].Draws)
        {
          continue;
        }
        int box[6];
        bool meets = true;
        for (int a = 0; a < 3; ++a)
        {
          box[2 * a] = std::max(need[2 * a], pts[j][2 * a]);
          box[2 * a + 1] = std::min(need[2 * a + 1], pts[j][2 * a + 1]);
          meets = meets && box[2 * a] <= box[2 * a + 1];
        }
        if (!meets)
        {
          continue;
        }
        CopyRegion(arrays[j], pts[j].data(), copy, need, box);
        for (int z = box[4]; z <= box[5]; ++z)
        {
          for (int y = box[2]; y <= box[3]; ++y)
          {
            for (int x = box[0]; x <= box[1]; ++x)
            {
              int ijk[3] = { x, y, z };
              filled[static_cast<size_t>(vtkStructuredData::ComputePointIdForExtent(need, ijk))] = 1;
            }
          }
        }
      }
      // Points no block has (a hole beside the block): the block's nearest point, as its border
      // reads when sampled alone.
      for (int z = need[4]; z <= need[5]; ++z)
      {
        for (int y = need[2]; y <= need[3]; ++y)
        {
          for (int x = need[0]; x <= need[1]; ++x)
          {
            int ijk[3] = { x, y, z };
            const vtkIdType d = vtkStructuredData::ComputePointIdForExtent(need, ijk);
            if (!filled[static_cast<size_t>(d)])
            {
              int src[3];
              for (int a = 0; a < 3; ++a)
              {
                src[a] = std::min(std::max(ijk[a], pts[i][2 * a]), pts[i][2 * a + 1]);
              }
              copy->SetTuple(d, vtkStructuredData::ComputePointIdForExtent(pts[i].data(), src), arrays[i]);
            }
          }
        }
      }
      piece->GetPointData()->SetScalars(copy);
    }
    piece->SetOrigin(origin);
    piece->SetSpacing(spacing);
    piece->SetDirectionMatrix(dir);
    b.Piece = piece;
    std::copy(owned[i].begin(), owned[i].end(), b.Owned);
  }
  std::copy(whole, whole + 6, this->WholeExtent);
  return true;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipBlockRenderer::ExchangeCamera(
  vtkRenderer* ren, vtkVolume* vol, double eye[3], double dir[3], bool& parallel) const
{
  const int none[3] = { 0, 0, 0 };
  if (this->Lattice && ren && vol && ren->GetActiveCamera())
  {
    vtkSpaceSkipPieceCompositing::CameraInIndexSpace(ren, vol, this->Lattice, none, eye, dir, parallel);
  }
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipBlockRenderer::DrawSum(vtkRenderer* ren, bool eightBit)
{
  auto* renWin = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  if (!renWin)
  {
    return false;
  }
  if (!this->SumImage || this->SumImage->rgba.empty())
  {
    return true; // no block drew this frame
  }
  if (!this->Compositor)
  {
    this->Compositor.reset(new vtkSpaceSkipCompositor);
  }
  return this->Compositor->Draw(
    renWin, *this->SumImage, this->SumImage->width, this->SumImage->height, eightBit);
}

//------------------------------------------------------------------------------
void vtkSpaceSkipBlockRenderer::AddFollowBias(vtkRenderer* ren, vtkVolume* vol, float bias)
{
  spaceskip::Image& sum = *this->SumImage;
  const int width = sum.width, height = sum.height;
  // NDC -> lattice index space: the camera's inverse projection, the volume's inverse matrix,
  // the lattice's physical-to-index map (as RayGen's primary rays, in double).
  vtkCamera* cam = ren->GetActiveCamera();
  vtkNew<vtkMatrix4x4> ndcToWorld;
  ndcToWorld->DeepCopy(cam->GetCompositeProjectionTransformMatrix(ren->GetTiledAspectRatio(), -1, 1));
  ndcToWorld->Invert();
  vtkNew<vtkMatrix4x4> worldToData;
  vtkMatrix4x4::Invert(vol->GetMatrix(), worldToData);
  vtkNew<vtkMatrix4x4> ndcToData;
  vtkMatrix4x4::Multiply4x4(worldToData, ndcToWorld, ndcToData);
  vtkImageData* lattice = this->Lattice;
  auto toIndex = [&](double nx, double ny, double nz, double out[3]) {
    double p[4] = { nx, ny, nz, 1.0 };
    ndcToData->MultiplyPoint(p, p);
    const double q[3] = { p[0] / p[3], p[1] / p[3], p[2] / p[3] };
    lattice->TransformPhysicalPointToContinuousIndex(q, out);
  };
  // The ray's parameter range [t0, t1] inside box [lo, hi]; false when it misses.
  auto slab = [](const double o[3], const double d[3], const double lo[3], const double hi[3],
                double& t0, double& t1) {
    t0 = -std::numeric_limits<double>::infinity();
    t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a)
    {
      if (d[a] == 0)
      {
        if (o[a] < lo[a] || o[a] > hi[a])
        {
          return false;
        }
        continue;
      }
      double u = (lo[a] - o[a]) / d[a], v = (hi[a] - o[a]) / d[a];
      if (u > v)
      {
        std::swap(u, v);
      }
      t0 = std::max(t0, u);
      t1 = std::min(t1, v);
    }
    return t0 < t1 && t1 > 0;
  };
  double wlo[3], whi[3];
  for (int a = 0; a < 3; ++a)
  {
    wlo[a] = this->WholeExtent[2 * a];
    whi[a] = this->WholeExtent[2 * a + 1];
  }
  std::vector<std::array<double, 6>> boxes;
  for (const Block& b : this->Blocks)
  {
    if (b.Draws)
    {
      boxes.push_back({ double(b.Owned[0]), double(b.Owned[2]), double(b.Owned[4]),
        double(b.Owned[1]), double(b.Owned[3]), double(b.Owned[5]) });
    }
  }
  spaceskip::vec4f* out = sum.rgba.data();
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int py = rows.begin(); py < rows.end(); ++py)
    {
      for (int px = 0; px < width; ++px)
      {
        spaceskip::vec4f& c = out[static_cast<size_t>(py) * width + px];
        if (!(c.w > 0.f))
        {
          continue;
        }
        const double nx = (px + 0.5) / width * 2 - 1, ny = (py + 0.5) / height * 2 - 1;
        double o[3], f[3], d[3];
        toIndex(nx, ny, -1, o);
        toIndex(nx, ny, 1, f);
        for (int a = 0; a < 3; ++a)
        {
          d[a] = f[a] - o[a];
        }
        double w0, w1;
        if (!slab(o, d, wlo, whi, w0, w1))
        {
          continue;
        }
        double localExit = -std::numeric_limits<double>::infinity();
        for (const auto& b : boxes)
        {
          double t0, t1;
          if (slab(o, d, b.data(), b.data() + 3, t0, t1))
          {
            localExit = std::max(localExit, t1);
          }
        }
        if (localExit < w1 - 1e-6 * std::abs(w1 - w0))
        {
          c.x += bias;
          c.y += bias;
          c.z += bias;
        }
      }
    }
  });
}

//------------------------------------------------------------------------------
std::vector<size_t> vtkSpaceSkipBlockRenderer::VisibilityOrder(vtkRenderer* ren, vtkVolume* vol) const
{
  std::vector<size_t> ids;
  for (size_t i = 0; i < this->Blocks.size(); ++i)
  {
    if (!this->OnLattice || this->Blocks[i].Draws)
    {
      ids.push_back(i);
    }
  }
  auto byDepth = [this](std::vector<size_t>& v) {
    std::stable_sort(v.begin(), v.end(),
      [this](size_t a, size_t b) { return this->Blocks[a].Depth < this->Blocks[b].Depth; });
  };
  if (!this->OnLattice)
  {
    byDepth(ids); // vtkMultiBlockVolumeMapper's order: block centres, nearest first
    return ids;
  }
  // The camera in the blocks' index space.
  double e[3], d[3];
  bool parallel = false;
  const int none[3] = { 0, 0, 0 };
  vtkSpaceSkipPieceCompositing::CameraInIndexSpace(ren, vol, this->Lattice, none, e, d, parallel);
  // A binary space partition of the owned boxes by axis planes (spaceskip::visibilityOrder):
  // exact for any arrangement such planes separate (grids, k-d splits); else the box centres.
  std::vector<spaceskip::PieceBox> boxes;
  for (size_t k : ids)
  {
    const int* o = this->Blocks[k].Owned;
    boxes.push_back({ double(o[0]), double(o[1]), double(o[2]), double(o[3]), double(o[4]), double(o[5]) });
  }
  std::vector<size_t> out;
  for (size_t i : spaceskip::visibilityOrder(boxes, e, d, parallel))
  {
    out.push_back(ids[i]);
  }
  return out;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipBlockRenderer::ReleaseGraphicsResources(vtkWindow* win)
{
  for (Block& b : this->Blocks)
  {
    b.Mapper->ReleaseGraphicsResources(win);
  }
  if (this->Compositor)
  {
    this->Compositor->ReleaseGraphicsResources(win);
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkipBlockRenderer::Clear()
{
  this->Blocks.clear();
  this->Active = false;
  this->OnLattice = false;
  this->PlanKey.clear();
  this->SumImage.reset();
}

//------------------------------------------------------------------------------
double vtkSpaceSkipBlockRenderer::Occupancy() const
{
  double weighted = 0, voxels = 0;
  for (const Block& b : this->Blocks)
  {
    const double n = static_cast<double>(b.Image ? b.Image->GetNumberOfPoints() : 0);
    weighted += n * b.Mapper->GetOccupancy();
    voxels += n;
  }
  return voxels > 0 ? weighted / voxels : 0.0;
}

//------------------------------------------------------------------------------
const char* vtkSpaceSkipBlockRenderer::Names(
  const char* (vtkSpaceSkippingVolumeMapper::*getter)())
{
  std::vector<std::string> seen;
  for (const Block& b : this->Blocks)
  {
    const char* v = ((*b.Mapper).*getter)();
    const std::string s = v ? v : "";
    if (std::find(seen.begin(), seen.end(), s) == seen.end())
    {
      seen.push_back(s);
    }
  }
  this->NamesText.clear();
  for (const std::string& s : seen)
  {
    this->NamesText += (this->NamesText.empty() ? "" : "/") + s;
  }
  return this->NamesText.c_str();
}

//------------------------------------------------------------------------------
const char* vtkSpaceSkipBlockRenderer::GetCompositePath() const
{
  return this->Compositor ? this->Compositor->GetCompositePath().c_str() : "none";
}

//------------------------------------------------------------------------------
double vtkSpaceSkipBlockRenderer::MinSampleDistance() const
{
  double best = 0;
  for (const Block& b : this->Blocks)
  {
    const double v = b.Mapper->GetSampleDistanceUsed();
    if (v > 0 && (best == 0 || v < best))
    {
      best = v;
    }
  }
  return best;
}
