// vtkSpaceSkipBlockRenderer: one vtkSpaceSkippingVolumeMapper per image block of a composite
// input, drawn back to front (vtkMultiBlockVolumeMapper's scheme).
#include "vtkSpaceSkipBlockRenderer.h"

#include "vtkCamera.h"
#include "vtkCompositeDataIterator.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkScalarsToColors.h"
#include "vtkVolume.h"

#include <cmath>
#include <limits>
#include <set>

namespace
{
// Above this many image blocks the per-block engines and frame buffers are said to be costly.
constexpr size_t kManyBlocks = 64;

// The parent's settings, as vtkMultiBlockVolumeMapper hands its own to each block's mapper.
void CopySettings(vtkSpaceSkippingVolumeMapper* from, vtkSpaceSkippingVolumeMapper* to)
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
  to->SetVectorMode(from->GetVectorMode());
  to->SetVectorComponent(from->GetVectorComponent());
  to->SetBlendModeOverride(from->GetBlendModeOverride());
  to->SetBlendMode(from->GetBlendMode());
  to->SetAverageIPScalarRange(from->GetAverageIPScalarRange());
  to->SetScalarMode(from->GetScalarMode());
  if (from->GetArrayAccessMode() == VTK_GET_ARRAY_BY_ID)
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
} // namespace

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
  if (images.empty() || !anyScalars)
  {
    problem = images.empty()
      ? "composite input without a vtkImageData block: nothing drawn"
      : "no block of the composite input has the selected point scalars: nothing drawn";
    this->Blocks.clear();
    return false;
  }

  // Visibility order: back to front by the distance of each block's centre from the camera
  // (along the view direction for a parallel projection), as vtkMultiBlockVolumeMapper sorts.
  vtkCamera* cam = ren->GetActiveCamera();
  double eye[3], dop[3];
  cam->GetPosition(eye);
  cam->GetDirectionOfProjection(dop);
  const bool parallel = cam->GetParallelProjection() != 0;
  vtkMatrix4x4* matrix = vol->GetMatrix();
  for (size_t i = 0; i < images.size(); ++i)
  {
    Block& b = this->Blocks[i];
    if (!b.Mapper)
    {
      b.Mapper = vtkSmartPointer<vtkSpaceSkippingVolumeMapper>::New();
    }
    if (b.Image != images[i] || b.Mapper->GetInputDataObject(0, 0) != images[i])
    {
      b.Mapper->SetInputData(images[i]);
      b.Image = images[i];
    }
    CopySettings(parent, b.Mapper);
    b.Mapper->SetTableRange(range);
    double bounds[6];
    images[i]->GetBounds(bounds);
    double c[4] = { 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
      0.5 * (bounds[4] + bounds[5]), 1.0 };
    matrix->MultiplyPoint(c, c);
    const double d[3] = { c[0] - eye[0], c[1] - eye[1], c[2] - eye[2] };
    b.Depth = parallel ? vtkMath::Dot(d, dop) : vtkMath::Norm(d);
  }
  std::vector<Block*> order;
  for (Block& b : this->Blocks)
  {
    order.push_back(&b);
  }
  std::stable_sort(
    order.begin(), order.end(), [](const Block* a, const Block* b) { return a->Depth > b->Depth; });
  for (Block* b : order)
  {
    b->Mapper->Render(ren, vol);
  }
  ++this->Frames;
  return true;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipBlockRenderer::ReleaseGraphicsResources(vtkWindow* win)
{
  for (Block& b : this->Blocks)
  {
    b.Mapper->ReleaseGraphicsResources(win);
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkipBlockRenderer::Clear()
{
  this->Blocks.clear();
  this->Active = false;
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
