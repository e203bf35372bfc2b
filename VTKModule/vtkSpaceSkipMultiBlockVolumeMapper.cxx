// vtkSpaceSkipMultiBlockVolumeMapper: one vtkSpaceSkippingVolumeMapper per image block of a
// composite input (through BlockMapper), drawn front to back on one lattice and blended in float.
#include "vtkSpaceSkipMultiBlockVolumeMapper.h"

#include "vtkSpaceSkipCompositor.h"
#include "vtkSpaceSkipInputConverter.h"
#include "vtkSpaceSkipPieceCompositing.h"

#include "vtkCamera.h"
#include "vtkCompositeDataIterator.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkMath.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPointData.h"
#include "vtkRectilinearGrid.h"
#include "vtkRenderer.h"
#include "vtkScalarsToColors.h"
#include "vtkStructuredData.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "spaceskip/Lattice.h"
#include "spaceskip/PieceOrder.h"
#include "spaceskip/Types.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>

namespace
{
// Above this many image blocks the per-block engines and frame buffers are said to be costly.
constexpr size_t kManyBlocks = 64;

// The point scalars the settings draw from `image` (scalar mode and array), or null.
vtkDataArray* SelectedScalars(const vtkSpaceSkipSettings& s, vtkImageData* image)
{
  int cellFlag = 0;
  vtkDataArray* scalars = vtkAbstractMapper::GetScalars(image, s.ScalarMode, s.ArrayAccessMode,
    s.ArrayId, s.ArrayName.empty() ? nullptr : s.ArrayName.c_str(), cellFlag);
  return scalars && cellFlag == 0 ? scalars : nullptr;
}

// Finite range of what the block mapper will draw from `image` (its converter's choice of
// component or magnitude); false when the block has no such point scalars.
bool BlockRange(const vtkSpaceSkipSettings& s, vtkImageData* image, double range[2])
{
  vtkDataArray* scalars = SelectedScalars(s, image);
  if (!scalars || scalars->GetNumberOfTuples() == 0)
  {
    return false;
  }
  const int n = scalars->GetNumberOfComponents();
  int comp = 0;
  if (n > 1)
  {
    comp = s.VectorMode == vtkScalarsToColors::MAGNITUDE
      ? -1
      : std::min(std::max(s.VectorComponent, 0), n - 1);
  }
  scalars->GetFiniteRange(range, comp);
  return range[0] <= range[1];
}

// The block as the lattice planner sees it.
spaceskip::LatticeBlock ToLatticeBlock(vtkImageData* im, vtkDataArray* scalars)
{
  spaceskip::LatticeBlock b;
  im->GetSpacing(b.spacing);
  vtkMatrix3x3* dir = im->GetDirectionMatrix();
  for (int k = 0; k < 9; ++k)
  {
    b.direction[k] = dir->GetElement(k / 3, k % 3);
  }
  im->GetExtent(b.extent);
  im->TransformIndexToPhysicalPoint(b.extent[0], b.extent[2], b.extent[4], b.firstPoint);
  std::copy(b.extent, b.extent + 6, b.ownCells);
  b.hasOwnCells = vtkSpaceSkipInputConverter::UnmarkedCells(im, b.ownCells) != 0;
  b.hasScalars = scalars && scalars->GetNumberOfTuples() == im->GetNumberOfPoints();
  b.scalarType = scalars ? scalars->GetDataType() : 0;
  b.components = scalars ? scalars->GetNumberOfComponents() : 0;
  return b;
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

// A padded piece's scalars: the plan's copies in order, then the points no block has from the
// block's nearest point (as its border reads when sampled alone).
vtkSmartPointer<vtkDataArray> PaddedScalars(const spaceskip::LatticePiece& p,
  const std::vector<spaceskip::LatticePiece>& pieces, const std::vector<vtkDataArray*>& arrays,
  vtkDataArray* own)
{
  const int* need = p.need;
  const vtkIdType count = vtkStructuredData::GetNumberOfPoints(need);
  vtkSmartPointer<vtkDataArray> copy;
  copy.TakeReference(own->NewInstance());
  copy->SetNumberOfComponents(own->GetNumberOfComponents());
  copy->SetNumberOfTuples(count);
  copy->SetName(own->GetName() ? own->GetName() : "scalars");
  std::vector<unsigned char> filled(static_cast<size_t>(count), 0);
  for (const spaceskip::LatticeCopy& c : p.copies)
  {
    CopyRegion(arrays[c.block], pieces[c.block].points, copy, need, c.box);
    for (int z = c.box[4]; z <= c.box[5]; ++z)
    {
      for (int y = c.box[2]; y <= c.box[3]; ++y)
      {
        for (int x = c.box[0]; x <= c.box[1]; ++x)
        {
          int ijk[3] = { x, y, z };
          filled[static_cast<size_t>(vtkStructuredData::ComputePointIdForExtent(need, ijk))] = 1;
        }
      }
    }
  }
  for (int z = need[4]; z <= need[5]; ++z)
  {
    for (int y = need[2]; y <= need[3]; ++y)
    {
      for (int x = need[0]; x <= need[1]; ++x)
      {
        int ijk[3] = { x, y, z }, src[3];
        const vtkIdType d = vtkStructuredData::ComputePointIdForExtent(need, ijk);
        if (!filled[static_cast<size_t>(d)])
        {
          spaceskip::nearestOwnPoint(p, ijk, src);
          copy->SetTuple(d, vtkStructuredData::ComputePointIdForExtent(p.points, src), own);
        }
      }
    }
  }
  return copy;
}
} // namespace

vtkStandardNewMacro(vtkSpaceSkipMultiBlockVolumeMapper);

//------------------------------------------------------------------------------
vtkSpaceSkipMultiBlockVolumeMapper::vtkSpaceSkipMultiBlockVolumeMapper() = default;
vtkSpaceSkipMultiBlockVolumeMapper::~vtkSpaceSkipMultiBlockVolumeMapper() = default;

//------------------------------------------------------------------------------
int vtkSpaceSkipMultiBlockVolumeMapper::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataObjectTree");
  return 1;
}

//------------------------------------------------------------------------------
// vtkMultiBlockVolumeMapper's sequence: the blocks (re)loaded, sorted, each rendered; here into
// float images summed front to back, drawn once.
void vtkSpaceSkipMultiBlockVolumeMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  this->Problem.clear();
  if (this->SumImage)
  {
    this->SumImage->rgba.clear(); // DrawSum() draws this frame's blocks or nothing
  }
  std::vector<vtkImageData*> images;
  double range[2];
  if (!this->CollectImages(ren, images) || !this->TableRange(images, range))
  {
    return;
  }
  this->SecondAxisRange(images);
  this->UpdateLattice(images, vol);
  this->ConfigureBlocks(range, ren, vol);
  int width = 0, height = 0, x0 = 0, y0 = 0;
  ren->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
  ++this->Frames;
  if (width <= 0 || height <= 0 || !this->RenderBlocks(ren, vol, width, height) ||
    this->ExchangesPieces())
  {
    return; // none drew (they said why), or the owner hands the images to the exchange
  }
  if (this->OnLattice && this->Settings.HasWholeExtent())
  {
    // Under MPI IceT blends the ranks' images in 8 bits and truncates: where a ray goes on into
    // another rank's blocks, this rank's colour is raised by half a unit, as a single piece's is
    // (VolumePiece::followBias; Tuning::pieceBias, in 1/255).
    const float bias = static_cast<float>(this->Settings.Tuning.pieceBias / 255.0);
    if (bias != 0.f && this->CarriesOpacity())
    {
      this->AddFollowBias(ren, vol, bias);
    }
  }
  if (!this->DrawSum(ren, this->Settings.EightBitComposite))
  {
    this->Problem = "could not compile the compositing shader: nothing drawn";
  }
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipMultiBlockVolumeMapper::CollectImages(
  vtkRenderer* ren, std::vector<vtkImageData*>& images)
{
  auto* cds = vtkCompositeDataSet::SafeDownCast(this->GetInputDataObject(0, 0));
  std::set<std::string> others;
  // This frame's rectilinear leaves; those of earlier frames that are gone are dropped.
  std::map<vtkRectilinearGrid*, vtkSpaceSkipRectilinearImage> grids;
  vtkSmartPointer<vtkCompositeDataIterator> it;
  it.TakeReference(cds->NewIterator());
  for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
  {
    if (auto* grid = vtkRectilinearGrid::SafeDownCast(it->GetCurrentDataObject()))
    {
      auto found = this->Grids.find(grid);
      grids[grid] = found != this->Grids.end() ? std::move(found->second) : vtkSpaceSkipRectilinearImage();
    }
  }
  this->Grids.swap(grids);
  grids.clear();
  for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
  {
    vtkDataObject* leaf = it->GetCurrentDataObject();
    auto* image = vtkImageData::SafeDownCast(leaf);
    if (auto* grid = vtkRectilinearGrid::SafeDownCast(leaf))
    {
      // A rectilinear block as an image (its own arrays when uniform, else resampled), kept
      // per leaf and made again only when the leaf changed.
      std::string problem;
      image = grid->GetNumberOfPoints() > 0 ? this->Grids[grid].From(grid, this->Warn, problem) : nullptr;
      if (!image && !problem.empty())
      {
        this->Warn("composite input: a block is not drawn: " + problem);
      }
      leaf = image ? leaf : nullptr;
    }
    if (image && image->GetNumberOfPoints() > 0)
    {
      images.push_back(image);
    }
    else if (!image && leaf)
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
    this->Warn("composite input: blocks of type " + names +
      " are not drawn (vtkSpaceSkippingVolumeMapper draws vtkImageData and vtkRectilinearGrid "
      "blocks only; resample other data to an image first)");
  }
  if (images.size() > kManyBlocks)
  {
    this->Warn("composite input with more than " + std::to_string(kManyBlocks) +
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
  if (images.empty())
  {
    this->Blocks.clear();
    if (others.empty())
    {
      ++this->Frames; // an empty composite data set (a rank's share of a few partitions)
    }
    else
    {
      this->Problem = "composite input without a vtkImageData block: nothing drawn";
    }
    return false;
  }
  this->Blocks.resize(images.size());
  for (size_t i = 0; i < images.size(); ++i)
  {
    Block& b = this->Blocks[i];
    if (!b.Mapper)
    {
      b.Mapper = this->Factory();
    }
    if (b.Image != images[i])
    {
      b.Image = images[i];
      b.Piece = nullptr;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
// The union of the blocks' ranges (the range one image of all the blocks would have), or under
// MPI the range of all ranks' blocks (the representation gathers it).
bool vtkSpaceSkipMultiBlockVolumeMapper::TableRange(
  const std::vector<vtkImageData*>& images, double range[2])
{
  range[0] = std::numeric_limits<double>::max();
  range[1] = std::numeric_limits<double>::lowest();
  bool any = false;
  for (vtkImageData* image : images)
  {
    double r[2];
    if (BlockRange(this->Settings, image, r))
    {
      range[0] = std::min(range[0], r[0]);
      range[1] = std::max(range[1], r[1]);
      any = true;
    }
  }
  if (!any)
  {
    this->Problem = "no block of the composite input has the selected point scalars: nothing drawn";
    this->Blocks.clear();
    return false;
  }
  const double* whole = this->Settings.WholeScalarRange;
  if (whole[0] <= whole[1])
  {
    range[0] = whole[0];
    range[1] = whole[1];
  }
  return true;
}

//------------------------------------------------------------------------------
// A second array as the 2-D transfer function's y axis: its rows span the array's range over
// all blocks (one image of the blocks would), unless the whole data's range was given (MPI).
void vtkSpaceSkipMultiBlockVolumeMapper::SecondAxisRange(const std::vector<vtkImageData*>& images)
{
  vtkSpaceSkipSettings& s = this->Settings;
  if (s.Transfer2DYAxisArray.empty() || s.WholeSecondAxisRange[0] <= s.WholeSecondAxisRange[1])
  {
    return;
  }
  double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
  for (vtkImageData* image : images)
  {
    vtkDataArray* y = image->GetPointData()->GetArray(s.Transfer2DYAxisArray.c_str());
    if (!y || y->GetNumberOfTuples() == 0)
    {
      continue;
    }
    double r[2];
    y->GetFiniteRange(r, std::min(std::max(s.Transfer2DYAxisComponent, 0), y->GetNumberOfComponents() - 1));
    if (r[0] <= r[1])
    {
      lo = std::min(lo, r[0]);
      hi = std::max(hi, r[1]);
    }
  }
  if (lo <= hi)
  {
    s.WholeSecondAxisRange[0] = lo;
    s.WholeSecondAxisRange[1] = hi;
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkipMultiBlockVolumeMapper::UpdateLattice(
  const std::vector<vtkImageData*>& images, vtkVolume* vol)
{
  const vtkSpaceSkipSettings& s = this->Settings;
  vtkVolumeProperty* prop = vol->GetProperty();
  // Shading's central differences (and slice mode's sample, up to half a voxel off the plane)
  // read one voxel past a block's own cells.
  const int layers =
    (prop && prop->GetShade(0)) || s.EffectiveBlendMode() == vtkVolumeMapper::SLICE_BLEND ? 1 : 0;
  std::vector<unsigned long long> key{ static_cast<unsigned long long>(layers),
    static_cast<unsigned long long>(s.ScalarMode), static_cast<unsigned long long>(s.ArrayAccessMode),
    static_cast<unsigned long long>(s.ArrayId), std::hash<std::string>()(s.ArrayName) };
  for (int i = 0; i < 6; ++i)
  {
    key.push_back(static_cast<unsigned long long>(static_cast<long long>(s.WholeExtent[i])));
  }
  for (int a = 0; a < 3; ++a)
  {
    unsigned long long bits = 0;
    std::memcpy(&bits, &s.WholeOrigin[a], sizeof(bits));
    key.push_back(bits);
  }
  spaceskip::LatticeRequest request;
  request.layers = layers;
  request.anchored = s.HasWholeExtent();
  std::copy(s.WholeExtent, s.WholeExtent + 6, request.wholeExtent);
  std::copy(s.WholeOrigin, s.WholeOrigin + 3, request.wholeOrigin);
  std::vector<vtkDataArray*> arrays, second;
  for (vtkImageData* image : images)
  {
    vtkDataArray* a = SelectedScalars(s, image);
    arrays.push_back(a);
    key.insert(key.end(),
      { reinterpret_cast<unsigned long long>(image), image->GetMTime(),
        reinterpret_cast<unsigned long long>(a), a ? a->GetMTime() : 0ULL });
    // The 2-D transfer function's y-axis array goes into padded copies too.
    vtkDataArray* y = s.Transfer2DYAxisArray.empty()
      ? nullptr
      : image->GetPointData()->GetArray(s.Transfer2DYAxisArray.c_str());
    second.push_back(y);
    key.insert(key.end(), { reinterpret_cast<unsigned long long>(y), y ? y->GetMTime() : 0ULL });
  }
  if (key != this->PlanKey)
  {
    this->PlanKey = key;
    for (size_t i = 0; i < images.size(); ++i)
    {
      request.blocks.push_back(ToLatticeBlock(images[i], arrays[i]));
    }
    this->ApplyPlan(spaceskip::planLattice(request), arrays, second);
  }
  if (!this->OnLattice)
  {
    this->Warn("composite input: the image blocks are not drawn on one sample lattice (" +
      this->OffLatticeWhy +
      "): each block samples from its own box entry, so its faces may show seams (resample the "
      "blocks to one image, e.g. with Resample To Image, for an exact render)");
  }
}

//------------------------------------------------------------------------------
// Each drawing block as a piece of the whole: its arrays on the lattice, or a padded copy.
void vtkSpaceSkipMultiBlockVolumeMapper::ApplyPlan(const spaceskip::LatticePlan& plan,
  const std::vector<vtkDataArray*>& arrays, const std::vector<vtkDataArray*>& second)
{
  const bool padSecond =
    !second.empty() && std::all_of(second.begin(), second.end(), [](vtkDataArray* y) { return y; });
  this->OnLattice = plan.onLattice;
  this->OffLatticeWhy = plan.why;
  this->Lattice = vtkSmartPointer<vtkImageData>::New();
  this->Lattice->SetOrigin(plan.origin);
  this->Lattice->SetSpacing(plan.spacing);
  this->Lattice->SetDirectionMatrix(plan.direction);
  for (size_t i = 0; i < this->Blocks.size(); ++i)
  {
    Block& b = this->Blocks[i];
    const spaceskip::LatticePiece& p = plan.pieces[i];
    b.Piece = nullptr;
    b.Draws = p.draws;
    if (!plan.onLattice || !p.draws)
    {
      continue;
    }
    auto piece = vtkSmartPointer<vtkImageData>::New();
    b.Padded = p.padded;
    if (p.padded)
    {
      piece->SetExtent(const_cast<int*>(p.need));
      piece->GetPointData()->SetScalars(PaddedScalars(p, plan.pieces, arrays, arrays[i]));
      if (padSecond)
      {
        piece->GetPointData()->AddArray(PaddedScalars(p, plan.pieces, second, second[i]));
      }
    }
    else
    {
      piece->ShallowCopy(b.Image);
      piece->SetExtent(const_cast<int*>(p.points));
    }
    piece->SetOrigin(plan.origin);
    piece->SetSpacing(plan.spacing);
    piece->SetDirectionMatrix(plan.direction);
    b.Piece = piece;
    std::copy(p.owned, p.owned + 6, b.Owned);
  }
  std::copy(plan.wholeExtent, plan.wholeExtent + 6, this->WholeExtent);
}

//------------------------------------------------------------------------------
void vtkSpaceSkipMultiBlockVolumeMapper::ConfigureBlocks(
  const double range[2], vtkRenderer* ren, vtkVolume* vol)
{
  vtkCamera* cam = ren->GetActiveCamera();
  double eye[3], dop[3];
  cam->GetPosition(eye);
  cam->GetDirectionOfProjection(dop);
  const bool parallel = cam->GetParallelProjection() != 0;
  vtkMatrix4x4* matrix = vol->GetMatrix();
  for (Block& b : this->Blocks)
  {
    const bool piece = this->OnLattice && b.Draws;
    b.Mapper->SetInput(piece ? b.Piece.GetPointer() : b.Image);
    b.Mapper->Configure(this->Settings, piece && b.Padded, range,
      piece ? this->WholeExtent : nullptr, piece ? b.Owned : nullptr);
    double bounds[6];
    b.Image->GetBounds(bounds);
    double c[4] = { 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
      0.5 * (bounds[4] + bounds[5]), 1.0 };
    matrix->MultiplyPoint(c, c);
    const double d[3] = { c[0] - eye[0], c[1] - eye[1], c[2] - eye[2] };
    b.Depth = parallel ? vtkMath::Dot(d, dop) : vtkMath::Norm(d);
  }
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipMultiBlockVolumeMapper::ExchangesPieces() const
{
  return this->Pieces && this->OnLattice && this->Settings.HasWholeExtent();
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipMultiBlockVolumeMapper::CarriesOpacity() const
{
  // Composite and isosurface blending accumulate opacity along the ray; the other modes'
  // blocks are blended over one another (not exact across block faces).
  return this->OnLattice && !this->ExchangesPieces() && this->Settings.AccumulatesOpacity();
}

//------------------------------------------------------------------------------
// Every block into its float image, front to back in visibility order, each ray going on with
// the opacity the blocks in front gave it (so early ray termination stops where the single
// image's ray stops), the images summed per pixel in float: the sum goes to the window once (one
// rounding to 8 bits, not one per block). MPI with a piece exchange: each block's image goes to
// the exchange on its own (another rank's blocks may lie between two of ours along a ray),
// without the carried opacity.
bool vtkSpaceSkipMultiBlockVolumeMapper::RenderBlocks(
  vtkRenderer* ren, vtkVolume* vol, int width, int height)
{
  const std::vector<size_t> order = this->VisibilityOrder(ren, vol);
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
  std::vector<vtkSpaceSkipPieceImage>* pieces = this->ExchangesPieces() ? this->Pieces : nullptr;
  const bool carry = this->CarriesOpacity();
  bool drew = false;
  for (size_t i : order)
  {
    int w = 0, h = 0;
    const float* img =
      this->Blocks[i].Mapper->Render(ren, vol, carry && drew ? this->Alpha.data() : nullptr, w, h);
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
  return drew;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipMultiBlockVolumeMapper::ExchangeCamera(
  vtkRenderer* ren, vtkVolume* vol, double eye[3], double dir[3], bool& parallel) const
{
  const int none[3] = { 0, 0, 0 };
  if (this->Lattice && ren && vol && ren->GetActiveCamera())
  {
    vtkSpaceSkipPieceCompositing::CameraInIndexSpace(ren, vol, this->Lattice, none, eye, dir, parallel);
  }
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipMultiBlockVolumeMapper::DrawSum(vtkRenderer* ren, bool eightBit)
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
void vtkSpaceSkipMultiBlockVolumeMapper::AddFollowBias(vtkRenderer* ren, vtkVolume* vol, float bias)
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
std::vector<size_t> vtkSpaceSkipMultiBlockVolumeMapper::VisibilityOrder(vtkRenderer* ren, vtkVolume* vol) const
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
void vtkSpaceSkipMultiBlockVolumeMapper::ReleaseGraphicsResources(vtkWindow* win)
{
  for (Block& b : this->Blocks)
  {
    b.Mapper->ReleaseGraphicsResources(win);
  }
  if (this->Compositor)
  {
    this->Compositor->ReleaseGraphicsResources(win);
  }
  this->Superclass::ReleaseGraphicsResources(win);
}

//------------------------------------------------------------------------------
vtkSpaceSkipStatistics vtkSpaceSkipMultiBlockVolumeMapper::GetStatistics(bool deviceTimes)
{
  std::vector<vtkSpaceSkipStatistics> blocks;
  std::vector<double> voxels;
  for (const Block& b : this->Blocks)
  {
    blocks.push_back(b.Mapper->GetStatistics(deviceTimes));
    voxels.push_back(static_cast<double>(b.Image ? b.Image->GetNumberOfPoints() : 0));
  }
  vtkSpaceSkipStatistics s = vtkSpaceSkipStatistics::Combine(blocks, voxels);
  s.Frames = this->Frames; // one per Render() that drew blocks
  s.CompositePath = this->Compositor ? this->Compositor->GetCompositePath() : "none";
  s.CompositeBlend = "gl"; // the blended blocks are drawn by GL
  return s;
}

//------------------------------------------------------------------------------
vtkImageData* vtkSpaceSkipMultiBlockVolumeMapper::FirstImage(vtkDataObject* input)
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
bool vtkSpaceSkipMultiBlockVolumeMapper::ComputeBounds(vtkDataObject* input, double bounds[6])
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
    auto* image = vtkDataSet::SafeDownCast(it->GetCurrentDataObject());
    if (!image || image->GetNumberOfPoints() == 0 ||
      !(image->IsA("vtkImageData") || image->IsA("vtkRectilinearGrid")))
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
void vtkSpaceSkipMultiBlockVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Blocks: " << this->Blocks.size() << "\n";
  os << indent << "OnLattice: " << (this->OnLattice ? "yes" : "no (" + this->OffLatticeWhy + ")")
     << "\n";
  os << indent << "Frames: " << this->Frames << "\n";
}
