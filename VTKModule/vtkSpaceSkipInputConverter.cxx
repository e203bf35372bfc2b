// vtkSpaceSkipInputConverter: the mapper's vtkImageData and scalar array -> a spaceskip::Volume.
#include "vtkSpaceSkipInputConverter.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDataSetAttributes.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationInformationVectorKey.h"
#include "vtkInformationVector.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkRectilinearGrid.h"
#include "vtkFloatArray.h"
#include "vtkSMPTools.h"
#include "vtkScalarsToColors.h"
#include "vtkStructuredData.h"
#include "vtkUnsignedCharArray.h"

#include "spaceskip/Engine.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

namespace
{
// Core voxel types by VTK type; int/unsigned int/long become float (see ConvertibleToFloat).
bool CoreTypeOf(int vtkType, spaceskip::VoxelType& out)
{
  using VT = spaceskip::VoxelType;
  static const std::pair<int, VT> kTypes[] = { { VTK_UNSIGNED_CHAR, VT::UInt8 },
    { VTK_CHAR, VT::Int8 }, { VTK_SIGNED_CHAR, VT::Int8 }, { VTK_UNSIGNED_SHORT, VT::UInt16 },
    { VTK_SHORT, VT::Int16 }, { VTK_FLOAT, VT::Float32 }, { VTK_DOUBLE, VT::Float64 } };
  for (const auto& t : kTypes)
  {
    if (t.first == vtkType)
    {
      out = t.second;
      return true;
    }
  }
  return false;
}

bool ConvertibleToFloat(int vtkType)
{
  switch (vtkType)
  {
    case VTK_INT:
    case VTK_UNSIGNED_INT:
    case VTK_LONG:
    case VTK_UNSIGNED_LONG:
    case VTK_LONG_LONG:
    case VTK_UNSIGNED_LONG_LONG:
    case VTK_ID_TYPE:
      return true;
    default:
      return false;
  }
}

// The selected component (or the magnitude) of every tuple, as float, in parallel, tuple i at
// out[i * stride]; all components (interleaved) when `component` < 0.
void ConvertToFloat(
  vtkDataArray* scalars, bool magnitude, int component, float* out, vtkIdType stride = 1)
{
  const int ncomp = scalars->GetNumberOfComponents();
  if (component < 0)
  {
    vtkSMPTools::For(0, scalars->GetNumberOfTuples(), [&](vtkIdType begin, vtkIdType end) {
      for (vtkIdType i = begin; i < end; ++i)
      {
        for (int c = 0; c < ncomp; ++c)
        {
          out[i * ncomp + c] = static_cast<float>(scalars->GetComponent(i, c));
        }
      }
    });
    return;
  }
  vtkSMPTools::For(0, scalars->GetNumberOfTuples(), [&](vtkIdType begin, vtkIdType end) {
    std::vector<double> tuple(static_cast<size_t>(ncomp));
    for (vtkIdType i = begin; i < end; ++i)
    {
      if (magnitude)
      {
        scalars->GetTuple(i, tuple.data());
        double m = 0;
        for (double c : tuple)
        {
          m += c * c;
        }
        out[i * stride] = static_cast<float>(std::sqrt(m));
      }
      else
      {
        out[i * stride] = static_cast<float>(scalars->GetComponent(i, component));
      }
    }
  });
}
} // namespace

//------------------------------------------------------------------------------
bool vtkSpaceSkipInputConverter::Select(vtkImageData* input, vtkDataArray* scalars, int cellFlag,
  int vectorMode, int vectorComponent, bool independentComponents, bool composite,
  const WarnFunction& warnOnce, std::string& problem, vtkDataArray* yAxis, int yComponent)
{
  this->Input = input;
  this->Scalars = scalars;
  if (!input)
  {
    problem = "no vtkImageData input: nothing drawn";
    return false;
  }
  int ext[6];
  input->GetExtent(ext);
  if (ext[1] < ext[0] || ext[3] < ext[2] || ext[5] < ext[4])
  {
    problem = "input has an empty extent: nothing drawn";
    return false;
  }
  if (!scalars)
  {
    problem = "input has no point scalars (or the selected array does not exist): nothing drawn";
    return false;
  }
  if (cellFlag)
  {
    problem = std::string("scalars '") + (scalars->GetName() ? scalars->GetName() : "") +
      "' are cell data; only point scalars are supported (apply vtkCellDataToPointData): "
      "nothing drawn";
    return false;
  }
  // Several components: the one selected by VectorMode/VectorComponent (ParaView's colour
  // array component, or Magnitude) is rendered, as vtkSmartVolumeMapper does.
  const int ncomp = scalars->GetNumberOfComponents();
  this->NumberOfComponents = ncomp;
  this->Magnitude = ncomp > 1 && vectorMode == vtkScalarsToColors::MAGNITUDE;
  this->Component =
    ncomp > 1 && !this->Magnitude ? std::min(std::max(vectorComponent, 0), ncomp - 1) : 0;
  // Independent components off (ParaView: Multi Components Mapping, or Map Scalars off): 2 or 4
  // components are drawn as vtkGPUVolumeRayCastMapper does; what it does not define is said.
  this->Dependent = (ncomp == 2 || ncomp == 4) && !independentComponents && composite;
  if (ncomp > 1 && !independentComponents && !this->Dependent)
  {
    const std::string drawn = std::string("rendering ") +
      (this->Magnitude ? "the magnitude" : "component " + std::to_string(this->Component)) +
      " through the transfer functions";
    warnOnce(ncomp == 2 || ncomp == 4
        ? "dependent components (Multi Components Mapping) are drawn with composite blending "
          "only; " + drawn
        : "dependent components (Multi Components Mapping) need 2 (value + opacity) or 4 (RGBA) "
          "components, not " + std::to_string(ncomp) + "; " + drawn);
  }
  if (scalars->GetNumberOfTuples() != input->GetNumberOfPoints())
  {
    problem = "scalar array length does not match the number of points: nothing drawn";
    return false;
  }
  spaceskip::VoxelType vtype;
  const int stype = scalars->GetDataType();
  if (!CoreTypeOf(stype, vtype) && !ConvertibleToFloat(stype))
  {
    problem = std::string("scalar type ") + scalars->GetDataTypeAsString() +
      " is not supported (uint8, int8, uint16, int16, float, double; int/long are converted "
      "to float): nothing drawn";
    return false;
  }
  // A second array as the 2-D transfer function's y axis: the drawn value and that array's
  // component become the engine's two components (Update). The 2-D table is composite only.
  this->SecondAxis = false;
  this->YAxis = nullptr;
  if (yAxis && composite)
  {
    const std::string name = yAxis->GetName() ? yAxis->GetName() : "";
    const std::string fallback = "; the gradient magnitude is the y axis";
    const int ytype = yAxis->GetDataType();
    if (ncomp > 1 && !independentComponents)
    {
      warnOnce("a second array ('" + name + "') as the 2-D transfer function's y axis is not "
        "supported with dependent components" + fallback);
    }
    else if (yAxis->GetNumberOfTuples() != input->GetNumberOfPoints())
    {
      warnOnce("the 2-D transfer function's y-axis array '" + name +
        "' does not have one value per point" + fallback);
    }
    else if (!CoreTypeOf(ytype, vtype) && !ConvertibleToFloat(ytype))
    {
      warnOnce("the 2-D transfer function's y-axis array '" + name + "' is of type " +
        yAxis->GetDataTypeAsString() + ", which is not supported" + fallback);
    }
    else
    {
      this->SecondAxis = true;
      this->YAxis = yAxis;
      this->YComponent = std::min(std::max(yComponent, 0), yAxis->GetNumberOfComponents() - 1);
    }
  }
  return true;
}

//------------------------------------------------------------------------------
namespace
{
// The volume's lattice (dims, spacing, origin, direction) of `input`, no voxels yet.
spaceskip::Volume LatticeOf(vtkImageData* input)
{
  spaceskip::Volume v;
  int dims[3], ext[6];
  input->GetDimensions(dims);
  input->GetExtent(ext);
  v.dims = spaceskip::vec3l{ dims[0], dims[1], dims[2] };
  const double* sp = input->GetSpacing();
  std::copy(sp, sp + 3, v.spacing);
  input->TransformIndexToPhysicalPoint(ext[0], ext[2], ext[4], v.origin);
  const double* dir = input->GetDirectionMatrix()->GetData();
  std::copy(dir, dir + 9, v.direction);
  return v;
}
} // namespace

double vtkSpaceSkipInputConverter::Update(
  spaceskip::Engine& engine, const WarnFunction& warnOnce, vtkDataArray* next)
{
  vtkImageData* input = this->Input;
  vtkDataArray* scalars = this->Scalars;
  const int selection = this->Dependent ? -2 : (this->Magnitude ? -1 : this->Component);
  vtkDataArray* yAxis = this->SecondAxis ? this->YAxis : nullptr;
  if (this->HaveVolume && this->WarpKey == this->Warp.get() && this->InputKey == input &&
    this->InputMTime == input->GetMTime() &&
    this->ScalarsKey == scalars && this->ScalarsMTime == scalars->GetMTime() &&
    this->Selection == selection && this->YAxisKey == yAxis &&
    (!yAxis || (this->YAxisMTime == yAxis->GetMTime() && this->YAxisComponent == this->YComponent)))
  {
    if (next)
    {
      this->Prefetch(engine, next, warnOnce);
    }
    return 0.0;
  }
  this->Selection = selection;
  spaceskip::Volume v = LatticeOf(input);
  spaceskip::VoxelType vtype = spaceskip::VoxelType::Float32;
  const bool native = CoreTypeOf(scalars->GetDataType(), vtype);
  v.components = this->Dependent ? this->NumberOfComponents : 1;
  if (yAxis)
  {
    // The drawn value and the y axis's value, interleaved as float (the engine's two components).
    v.components = 2;
    this->Converted.resize(static_cast<size_t>(input->GetNumberOfPoints()) * 2);
    ConvertToFloat(scalars, this->Magnitude, this->Component, this->Converted.data(), 2);
    ConvertToFloat(yAxis, false, this->YComponent, this->Converted.data() + 1, 2);
    v.type = spaceskip::VoxelType::Float32;
    v.data = this->Converted.data();
    this->Borrowed = nullptr;
  }
  else if (native && (this->NumberOfComponents == 1 || this->Dependent) &&
    scalars->HasStandardMemoryLayout())
  {
    // Borrowed as it is: dependent components stay interleaved, no copy.
    v.type = vtype;
    v.data = scalars->GetVoidPointer(0);
    this->Borrowed = scalars;
    this->Converted.clear();
    this->Converted.shrink_to_fit();
  }
  else
  {
    if (!native)
    {
      warnOnce(std::string("scalar type ") + scalars->GetDataTypeAsString() +
        " converted to float (values beyond 2^24 lose precision)");
    }
    this->Converted.resize(static_cast<size_t>(input->GetNumberOfPoints()) * v.components);
    ConvertToFloat(
      scalars, this->Magnitude, this->Dependent ? -1 : this->Component, this->Converted.data());
    v.type = spaceskip::VoxelType::Float32;
    v.data = this->Converted.data();
    this->Borrowed = nullptr;
  }
  // A time step, as the engine counts one (a volume of the last one's shape: the engine's other
  // settings, memory budget and brick size among them, are already those of this view).
  if (this->Warp && v.components == 1)
  {
    v.warp = this->Warp; // a rectilinear grid through its coordinates
  }
  else if (this->Warp)
  {
    warnOnce("a rectilinear grid with more than one drawn component is drawn as the uniform image "
             "of its points (its coordinates are not used)");
  }
  this->WarpKey = this->Warp.get();
  const int steps = engine.counters().timeSteps;
  engine.setVolume(v);
  this->Prefetched = nullptr; // taken from the device, or no longer the step that comes
  const bool step = engine.counters().timeSteps > steps;
  if (next)
  {
    // setVolume(t); prefetchVolume(t + 1), before anything waits for step t: when t was itself
    // prefetched, t + 1's copy queues right behind it. In the VTK window on an H200 (512^3 uint8
    // steps in NewTimeStepArray memory) a step took 3.45 ms with t + 1 prefetched after t's value
    // ranges, 2.90 ms here (upload bound 2.43 ms).
    this->Prefetch(engine, next, warnOnce);
  }
  // The table's range: for a time step of one component from the engine's brick ranges, which
  // it computes where the voxels land anyway (on the GPU right after the upload; a step's host
  // pass over its voxels was up to 60 % of the step: 174 ms of 278 ms for 1024^3 float32 on an
  // H200). A first volume takes one parallel pass over the voxels the engine reads, before the
  // upload, so that the view's memory budget and brick size (set after this) decide the upload
  // (vtkDataArray::GetFiniteRange was serial here: 267 s for the first frame of a 2048^3 uint8
  // volume).
  const auto tRange = std::chrono::steady_clock::now();
  // Dependent components: the colour TF spans component 0's range, the opacity function the
  // last component's (vtkVolumeInputHelper, ColorRangeType/ScalarOpacityRangeType SCALAR). A
  // second axis: the 2-D table's rows span its component's range.
  const bool two = this->Dependent || yAxis;
  if (!(two ? v.componentRange(0, this->ScalarRange[0], this->ScalarRange[1])
                        : ((step && engine.valueRange(this->ScalarRange[0], this->ScalarRange[1])) ||
                            v.scalarRange(this->ScalarRange[0], this->ScalarRange[1]))))
  {
    this->ScalarRange[0] = 0; // no finite value at all: an empty table range
    this->ScalarRange[1] = 1;
  }
  if (two &&
    !v.componentRange(v.components - 1, this->OpacityRange[0], this->OpacityRange[1]))
  {
    this->OpacityRange[0] = 0;
    this->OpacityRange[1] = 1;
  }
  const double seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - tRange).count();
  this->InputKey = input;
  this->InputMTime = input->GetMTime();
  this->ScalarsKey = scalars;
  this->ScalarsMTime = scalars->GetMTime();
  this->YAxisKey = yAxis;
  this->YAxisMTime = yAxis ? yAxis->GetMTime() : 0;
  this->YAxisComponent = this->YComponent;
  this->HaveVolume = true;
  return seconds;
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipInputConverter::DrawnInPlace(int vtkType)
{
  spaceskip::VoxelType t;
  return CoreTypeOf(vtkType, t);
}

//------------------------------------------------------------------------------
void vtkSpaceSkipInputConverter::Prefetch(
  spaceskip::Engine& engine, vtkDataArray* next, const WarnFunction& warnOnce)
{
  vtkDataArray* shown = this->Borrowed;
  if (next == shown)
  {
    return; // the step shown: nothing to fetch
  }
  const std::string prefix = "PrefetchTimeStep: not prefetched: ";
  if (!shown || this->SecondAxis)
  {
    warnOnce(prefix + "the volume shown is not drawn in place from its array (a converted type, a "
                   "selected component or the magnitude, a second array as the 2-D transfer "
                   "function's y axis)");
    return;
  }
  if (next->GetDataType() != shown->GetDataType() ||
    next->GetNumberOfComponents() != shown->GetNumberOfComponents() ||
    next->GetNumberOfTuples() != shown->GetNumberOfTuples() || !next->HasStandardMemoryLayout())
  {
    warnOnce(prefix + "the next step's array (" + next->GetDataTypeAsString() + ", " +
      std::to_string(next->GetNumberOfComponents()) + " components, " +
      std::to_string(next->GetNumberOfTuples()) + " tuples) is not of the type, components, "
      "tuple count and layout of the array shown (" + shown->GetDataTypeAsString() + ", " +
      std::to_string(shown->GetNumberOfComponents()) + ", " +
      std::to_string(shown->GetNumberOfTuples()) + ")");
    return;
  }
  spaceskip::Volume v = LatticeOf(this->Input);
  spaceskip::VoxelType vtype = spaceskip::VoxelType::Float32;
  CoreTypeOf(next->GetDataType(), vtype);
  v.type = vtype;
  v.components = this->Dependent ? this->NumberOfComponents : 1;
  v.data = next->GetVoidPointer(0);
  if (engine.prefetchVolume(v)) // else it is uploaded when shown (the CPU reads it in place)
  {
    this->Prefetched = next;
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkipInputConverter::Reset()
{
  this->InputKey = this->ScalarsKey = this->YAxisKey = nullptr;
  this->InputMTime = this->ScalarsMTime = this->YAxisMTime = 0;
  this->HaveVolume = false;
  this->Borrowed = nullptr;
  this->Prefetched = nullptr;
}

//------------------------------------------------------------------------------
namespace
{
// The cells of a structured data set of extent `ext` that its ghost-cell array leaves unmarked,
// [lo, hi) per axis (vtkSpaceSkipInputConverter::UnmarkedCells; `cells` set only when 1).
int UnmarkedCellsOf(vtkDataSet* data, const int ext[6], int cells[6])
{
  vtkUnsignedCharArray* g = data->GetCellData()->GetGhostArray();
  if (!g || g->GetNumberOfTuples() == 0)
  {
    return 2;
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
    return 0;
  }
  if (first == 0 && last == n - 1)
  {
    return 2;
  }
  int ijk[3], ijk1[3];
  vtkStructuredData::ComputeCellStructuredCoordsForExtent(first, ext, ijk);
  vtkStructuredData::ComputeCellStructuredCoordsForExtent(last, ext, ijk1);
  for (int a = 0; a < 3; ++a)
  {
    cells[2 * a] = ijk[a];
    cells[2 * a + 1] = ijk1[a] + 1;
  }
  return 1;
}

} // namespace

bool vtkSpaceSkipInputConverter::FillRangeCaches(vtkDataArray* array)
{
  spaceskip::VoxelType type;
  const int nc = array ? array->GetNumberOfComponents() : 0;
  const vtkIdType n = array ? array->GetNumberOfTuples() : 0;
  if (nc < 1 || nc > 4 || n < 1 || !array->HasStandardMemoryLayout() ||
    !CoreTypeOf(array->GetDataType(), type))
  {
    return false;
  }
  vtkInformation* info = array->GetInformation();
  const bool needAll = !info->Has(vtkAbstractArray::PER_COMPONENT());
  const bool needFinite = !info->Has(vtkAbstractArray::PER_FINITE_COMPONENT());
  if (!needAll && !needFinite)
  {
    return false;
  }
  const auto* base = static_cast<const unsigned char*>(array->GetVoidPointer(0));
  const size_t size = static_cast<size_t>(array->GetDataTypeSize());
  // Ranges of every component (all values but NaN, or the finite ones), or none.
  auto ranges = [&](bool finiteOnly, std::vector<double>& r) {
    r.assign(2 * static_cast<size_t>(nc), 0.0);
    for (int c = 0; c < nc; ++c)
    {
      if (!spaceskip::valueRange(type, base + c * size, n, nc, finiteOnly, r[2 * c], r[2 * c + 1]))
      {
        return false;
      }
    }
    return true;
  };
  auto store = [&](vtkInformationInformationVectorKey* key, const std::vector<double>& r) {
    vtkNew<vtkInformationVector> perComponent;
    perComponent->SetNumberOfInformationObjects(nc);
    for (int c = 0; c < nc; ++c)
    {
      perComponent->GetInformationObject(c)->Set(vtkDataArray::COMPONENT_RANGE(), r.data() + 2 * c, 2);
    }
    info->Set(key, perComponent);
  };
  const bool integral = type != spaceskip::VoxelType::Float32 && type != spaceskip::VoxelType::Float64;
  // Only the missing caches are computed (integers: one pass serves both). A component of NaN
  // only (or of no finite value) leaves the array to VTK.
  std::vector<double> all, finite;
  if ((needAll || integral) && !ranges(false, all))
  {
    return false;
  }
  if (needFinite && !(integral ? (finite = all, true) : ranges(true, finite)))
  {
    return false;
  }
  if (needAll)
  {
    store(vtkAbstractArray::PER_COMPONENT(), all);
  }
  if (needFinite)
  {
    store(vtkAbstractArray::PER_FINITE_COMPONENT(), finite);
  }
  return true;
}

//------------------------------------------------------------------------------
int vtkSpaceSkipInputConverter::UnmarkedCells(vtkImageData* image, int cells[6])
{
  return UnmarkedCellsOf(image, image->GetExtent(), cells);
}

//------------------------------------------------------------------------------
spaceskip::VolumePiece vtkSpaceSkipInputConverter::PieceOf(vtkImageData* input, const int whole[6],
  const int* owned, bool exact, double bias, const WarnFunction& warn)
{
  spaceskip::VolumePiece piece;
  int ext[6], w[6];
  input->GetExtent(ext);
  std::copy(whole, whole + 6, w);
  bool haveWhole = w[0] <= w[1] && w[2] <= w[3] && w[4] <= w[5];
  if (haveWhole &&
    !(w[0] <= ext[0] && ext[1] <= w[1] && w[2] <= ext[2] && ext[3] <= w[3] && w[4] <= ext[4] &&
      ext[5] <= w[5]))
  {
    warn("WholeExtent does not contain the input's extent: ignored (the input is drawn as a "
         "whole image)");
    haveWhole = false;
  }
  if (!haveWhole)
  {
    std::copy(ext, ext + 6, w);
  }
  // The cells of the input, [lo, hi) per axis (an axis of one point has one cell), then those
  // it owns.
  int all[6], own[6];
  for (int a = 0; a < 3; ++a)
  {
    all[2 * a] = ext[2 * a];
    all[2 * a + 1] = std::max(ext[2 * a + 1] - 1, ext[2 * a]) + 1;
  }
  std::copy(all, all + 6, own);
  if (owned)
  {
    std::copy(owned, owned + 6, own);
  }
  else if (UnmarkedCells(input, own) == 0)
  {
    own[1] = own[0]; // all ghost: nothing owned
  }
  bool same = std::equal(own, own + 6, all);
  for (int i = 0; i < 6; ++i)
  {
    same = same && w[i] == ext[i];
  }
  if (same)
  {
    return piece;
  }
  input->TransformIndexToPhysicalPoint(w[0], w[2], w[4], piece.wholeOrigin);
  piece.wholeDims = spaceskip::vec3l{ w[1] - w[0] + 1, w[3] - w[2] + 1, w[5] - w[4] + 1 };
  piece.offset = spaceskip::vec3l{ ext[0] - w[0], ext[2] - w[2], ext[4] - w[4] };
  piece.ownedLo = spaceskip::vec3l{ own[0] - w[0], own[2] - w[2], own[4] - w[4] };
  piece.ownedHi = spaceskip::vec3l{ own[1] - w[0], own[3] - w[2], own[5] - w[4] };
  // The window and IceT hold 8 bits: a piece in front rounds up by half a unit what IceT's
  // blend truncates (docs/paraview.md).
  piece.followBias = exact ? 0.f : static_cast<float>(bias / 255.0);
  return piece;
}

//------------------------------------------------------------------------------
namespace
{
// One coordinate array of a rectilinear grid: its mean step (signed), the largest relative
// deviation of a step from it, and whether it is strictly monotonic.
struct AxisSteps
{
  vtkIdType Count = 0;
  double First = 0, Last = 0, Mean = 1, Deviation = 0;
  bool Monotonic = true;
};

AxisSteps StepsOf(vtkDataArray* coords)
{
  AxisSteps a;
  a.Count = coords ? coords->GetNumberOfTuples() : 0;
  if (a.Count == 0)
  {
    return a;
  }
  a.First = coords->GetComponent(0, 0);
  a.Last = coords->GetComponent(a.Count - 1, 0);
  if (a.Count == 1)
  {
    a.Monotonic = std::isfinite(a.First);
    return a; // one point: any step; the image's spacing 1
  }
  a.Mean = (a.Last - a.First) / static_cast<double>(a.Count - 1);
  if (!std::isfinite(a.Mean) || a.Mean == 0)
  {
    a.Monotonic = false; // a NaN or infinite end, or both ends equal
    return a;
  }
  double previous = a.First;
  for (vtkIdType i = 1; i < a.Count; ++i)
  {
    const double x = coords->GetComponent(i, 0);
    const double step = x - previous;
    if (!(step * a.Mean > 0)) // zero, the other sign, or NaN
    {
      a.Monotonic = false;
      return a;
    }
    a.Deviation = std::max(a.Deviation, std::abs(step - a.Mean) / std::abs(a.Mean));
    previous = x;
  }
  return a;
}
// The grid's arrays (shared, not copied) as an image whose index (i, j, k) of the grid's extent
// `ext` lies at first + (i - ext0) * steps[a] per axis (steps > 0; a descending axis with -1 in
// the direction matrix).
vtkSmartPointer<vtkImageData> PointsOnLattice(
  vtkRectilinearGrid* grid, const int ext[6], const AxisSteps axes[3], const double steps[3])
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetExtent(const_cast<int*>(ext));
  double origin[3];
  double direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
  for (int a = 0; a < 3; ++a)
  {
    const double sign = axes[a].Mean < 0 ? -1.0 : 1.0;
    direction[4 * a] = sign;
    origin[a] = axes[a].First - sign * steps[a] * ext[2 * a];
  }
  image->SetSpacing(steps[0], steps[1], steps[2]);
  image->SetOrigin(origin);
  image->SetDirectionMatrix(direction);
  image->GetPointData()->ShallowCopy(grid->GetPointData());
  image->GetCellData()->ShallowCopy(grid->GetCellData());
  image->GetFieldData()->ShallowCopy(grid->GetFieldData());
  return image;
}

// Where each of the `n` lattice points along an axis (first + i * step) falls in the ascending
// `coords`: the index of its cell's lower point and the weight of the upper one, in [0, 1].
void AxisWeights(vtkDataArray* coords, int n, double first, double step,
  std::vector<vtkIdType>& cell, std::vector<double>& weight)
{
  const vtkIdType count = coords->GetNumberOfTuples();
  cell.assign(static_cast<size_t>(n), 0);
  weight.assign(static_cast<size_t>(n), 0.0);
  if (count < 2)
  {
    return;
  }
  vtkIdType j = 0;
  for (int i = 0; i < n; ++i)
  {
    const double x = first + i * step;
    while (j + 2 < count && coords->GetComponent(j + 1, 0) <= x)
    {
      ++j;
    }
    const double x0 = coords->GetComponent(j, 0), x1 = coords->GetComponent(j + 1, 0);
    cell[i] = j;
    weight[i] = std::min(1.0, std::max(0.0, (x - x0) / (x1 - x0)));
  }
}

// Every point array of `grid` (ghost markers aside) trilinearly interpolated within the grid's
// cells at the points of `image` (on the grid's bounds), as float; the active scalars stay
// active. One pass per array, z slices in parallel.
void ResampleTrilinear(vtkRectilinearGrid* grid, vtkImageData* image)
{
  int dims[3], gdims[3];
  image->GetDimensions(dims);
  grid->GetDimensions(gdims);
  const double* origin = image->GetOrigin();
  const double* spacing = image->GetSpacing();
  const int* ext = image->GetExtent();
  vtkDataArray* coords[3] = { grid->GetXCoordinates(), grid->GetYCoordinates(),
    grid->GetZCoordinates() };
  std::vector<vtkIdType> cell[3];
  std::vector<double> weight[3];
  for (int a = 0; a < 3; ++a)
  {
    AxisWeights(coords[a], dims[a], origin[a] + ext[2 * a] * spacing[a], spacing[a], cell[a], weight[a]);
  }
  // The upper neighbour's offset per axis (0 on an axis of one point).
  const vtkIdType up[3] = { gdims[0] > 1 ? 1 : 0,
    gdims[1] > 1 ? static_cast<vtkIdType>(gdims[0]) : 0,
    gdims[2] > 1 ? static_cast<vtkIdType>(gdims[0]) * gdims[1] : 0 };
  vtkPointData* in = grid->GetPointData();
  vtkDataArray* active = in->GetScalars();
  for (int n = 0; n < in->GetNumberOfArrays(); ++n)
  {
    vtkDataArray* src = in->GetArray(n);
    if (!src || (src->GetName() && std::string(src->GetName()) == vtkDataSetAttributes::GhostArrayName()) ||
      src->GetNumberOfTuples() != grid->GetNumberOfPoints())
    {
      continue;
    }
    const int nc = src->GetNumberOfComponents();
    vtkNew<vtkFloatArray> dst;
    dst->SetName(src->GetName());
    dst->SetNumberOfComponents(nc);
    dst->SetNumberOfTuples(static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2]);
    float* out = dst->GetPointer(0);
    vtkSMPTools::For(0, dims[2], [&](vtkIdType k0, vtkIdType k1) {
      for (vtkIdType k = k0; k < k1; ++k)
      {
        const double wz = weight[2][k];
        for (vtkIdType j = 0; j < dims[1]; ++j)
        {
          const double wy = weight[1][j];
          const vtkIdType row = (cell[2][k] * gdims[1] + cell[1][j]) * gdims[0];
          float* o = out + ((k * dims[1] + j) * dims[0]) * nc;
          for (vtkIdType i = 0; i < dims[0]; ++i)
          {
            const double wx = weight[0][i];
            const vtkIdType p = row + cell[0][i];
            for (int c = 0; c < nc; ++c)
            {
              auto v = [&](vtkIdType q) { return src->GetComponent(q, c); };
              const double x00 = v(p) + wx * (v(p + up[0]) - v(p));
              const double x10 = v(p + up[1]) + wx * (v(p + up[1] + up[0]) - v(p + up[1]));
              const double x01 = v(p + up[2]) + wx * (v(p + up[2] + up[0]) - v(p + up[2]));
              const double x11 = v(p + up[2] + up[1]) +
                wx * (v(p + up[2] + up[1] + up[0]) - v(p + up[2] + up[1]));
              const double y0 = x00 + wy * (x10 - x00), y1 = x01 + wy * (x11 - x01);
              o[i * nc + c] = static_cast<float>(y0 + wz * (y1 - y0));
            }
          }
        }
      }
    });
    if (src == active)
    {
      image->GetPointData()->SetScalars(dst);
    }
    else
    {
      image->GetPointData()->AddArray(dst);
    }
  }
}

// The resampling lattice of a grid spanning [first, last] per axis with `count` points and
// `smallest` its smallest step: the smallest step per axis, coarsened alike on every axis (never
// below the grid's own point count) until the lattice holds at most `cap` points. The serial
// grid and the pieces of one (from the whole grid's figures) get the same lattice.
void ResampleLattice(const double first[3], const double last[3], const double smallest[3],
  const vtkIdType count[3], double cap, int n[3], double spacing[3])
{
  double dims[3];
  for (int a = 0; a < 3; ++a)
  {
    dims[a] = count[a] > 1 ? std::ceil((last[a] - first[a]) / smallest[a] - 1e-9) + 1 : 1;
  }
  for (int pass = 0; pass < 8 && dims[0] * dims[1] * dims[2] > cap; ++pass)
  {
    const double f = std::cbrt(dims[0] * dims[1] * dims[2] / cap);
    for (int a = 0; a < 3; ++a)
    {
      dims[a] = std::max(static_cast<double>(count[a]), std::floor((dims[a] - 1) / f) + 1);
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    n[a] = static_cast<int>(dims[a]);
    spacing[a] = n[a] > 1 ? (last[a] - first[a]) / (n[a] - 1) : 1.0;
  }
}

// Marks the cells of `image` outside the lattice cells [owned[2a], owned[2a+1]) per axis as
// duplicates (a ghost-cell array), so that UnmarkedCells finds `owned`.
void MarkOwnedCells(vtkImageData* image, const int owned[6])
{
  const int* ext = image->GetExtent();
  int cells[3], lo[3];
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = ext[2 * a];
    cells[a] = std::max(ext[2 * a + 1] - ext[2 * a], 1);
  }
  vtkNew<vtkUnsignedCharArray> ghosts;
  ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
  ghosts->SetNumberOfTuples(static_cast<vtkIdType>(cells[0]) * cells[1] * cells[2]);
  unsigned char* g = ghosts->GetPointer(0);
  for (int k = 0; k < cells[2]; ++k)
  {
    for (int j = 0; j < cells[1]; ++j)
    {
      for (int i = 0; i < cells[0]; ++i)
      {
        const int c[3] = { lo[0] + i, lo[1] + j, lo[2] + k };
        bool mine = true;
        for (int a = 0; a < 3; ++a)
        {
          mine = mine && c[a] >= owned[2 * a] && c[a] < owned[2 * a + 1];
        }
        *g++ = mine ? 0 : vtkDataSetAttributes::DUPLICATECELL;
      }
    }
  }
  image->GetCellData()->AddArray(ghosts);
}
} // namespace

//------------------------------------------------------------------------------
bool vtkSpaceSkipRectilinearImage::WholeGrid::Valid() const
{
  for (int a = 0; a < 3; ++a)
  {
    // An axis of one point has no step.
    if (!(this->Bounds[2 * a] <= this->Bounds[2 * a + 1]) || this->Extent[2 * a] > this->Extent[2 * a + 1] ||
      (!(this->SmallestStep[a] > 0) && this->Extent[2 * a] < this->Extent[2 * a + 1]))
    {
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
vtkImageData* vtkSpaceSkipRectilinearImage::From(vtkRectilinearGrid* grid,
  const WarnFunction& warn, std::string& problem, const WholeGrid* wholeGrid, bool throughCoordinates)
{
  const WholeGrid whole = wholeGrid && wholeGrid->Valid() ? *wholeGrid : WholeGrid();
  vtkDataArray* coords[3] = { grid->GetXCoordinates(), grid->GetYCoordinates(),
    grid->GetZCoordinates() };
  vtkMTimeType mtime = grid->GetMTime();
  for (vtkDataArray* c : coords)
  {
    mtime = std::max(mtime, c ? c->GetMTime() : 0);
  }
  auto sameWhole = [&](const WholeGrid& w) {
    return std::equal(w.Bounds, w.Bounds + 6, whole.Bounds) &&
      std::equal(w.SmallestStep, w.SmallestStep + 3, whole.SmallestStep) &&
      std::equal(w.Extent, w.Extent + 6, whole.Extent);
  };
  if (this->Key == grid && this->MTime == mtime && sameWhole(this->KeyWhole) &&
    this->KeyThrough == throughCoordinates)
  {
    problem = this->Problem;
    return this->Image;
  }
  this->Key = grid;
  this->MTime = mtime;
  this->KeyWhole = whole;
  this->KeyThrough = throughCoordinates;
  this->Image = nullptr;
  this->Warp = nullptr;
  this->Path = 0;
  this->Problem.clear();
  int ext[6];
  grid->GetExtent(ext);
  AxisSteps axes[3];
  double deviation = 0;
  int worst = 0;
  bool descending = false;
  static const char* kAxis = "xyz";
  for (int a = 0; a < 3; ++a)
  {
    axes[a] = StepsOf(coords[a]);
    if (axes[a].Count != ext[2 * a + 1] - ext[2 * a] + 1)
    {
      this->Problem = std::string("vtkRectilinearGrid: its ") + kAxis[a] +
        " coordinates do not match its extent: nothing drawn";
      problem = this->Problem;
      return nullptr;
    }
    if (!axes[a].Monotonic)
    {
      this->Problem = std::string("vtkRectilinearGrid: its ") + kAxis[a] +
        " coordinates are not finite and strictly monotonic: nothing drawn";
      problem = this->Problem;
      return nullptr;
    }
    descending = descending || axes[a].Mean < 0;
    if (axes[a].Deviation > deviation)
    {
      deviation = axes[a].Deviation;
      worst = a;
    }
  }
  const std::string name = grid->GetObjectName().empty()
    ? std::string("vtkRectilinearGrid")
    : "vtkRectilinearGrid '" + grid->GetObjectName() + "'";
  constexpr double kUniform = 1e-6;
  if (deviation <= kUniform)
  {
    // The same points as an image: index (i, j, k) at first + (i - ext0) * mean step per axis.
    const double steps[3] = { std::abs(axes[0].Mean), std::abs(axes[1].Mean), std::abs(axes[2].Mean) };
    this->Image = PointsOnLattice(grid, ext, axes, steps);
    this->Path = 1;
    return this->Image;
  }
  // The whole grid (serially ParaView gives its own extent as the whole one): drawn through its
  // coordinates where the mapper allows it.
  const bool alone = !whole.Valid() || std::equal(whole.Extent, whole.Extent + 6, ext);
  if (throughCoordinates && alone)
  {
    std::vector<double> axis[3];
    const double* at[3];
    int64_t count[3];
    for (int a = 0; a < 3; ++a)
    {
      axis[a].resize(static_cast<size_t>(axes[a].Count));
      for (vtkIdType i = 0; i < axes[a].Count; ++i)
      {
        axis[a][static_cast<size_t>(i)] = coords[a]->GetComponent(i, 0);
      }
      at[a] = axis[a].data();
      count[a] = axes[a].Count;
    }
    try
    {
      auto warp = spaceskip::AxisWarp::fromCoordinates(at, count);
      // The virtual lattice: the grid's points at the warp's steps, as for a uniform grid.
      const double steps[3] = { warp->spacing(0), warp->spacing(1), warp->spacing(2) };
      this->Image = PointsOnLattice(grid, ext, axes, steps);
      this->Warp = std::move(warp);
      this->Path = 4;
      return this->Image;
    }
    catch (const std::exception& e)
    {
      warn(name + ": " + e.what() + "; resampled instead");
    }
  }
  if (descending)
  {
    this->Problem = name + " has non-uniform descending coordinates: not drawn (only ascending "
                           "non-uniform coordinates are resampled to an image)";
    problem = this->Problem;
    return nullptr;
  }
  // The smallest step per axis over the grid's bounds (the whole grid's, for a piece of one),
  // coarsened until the lattice holds at most kMaxResampleFactor times the grid's points.
  const bool piece = whole.Valid();
  double first[3], last[3], smallest[3];
  vtkIdType count[3];
  for (int a = 0; a < 3; ++a)
  {
    first[a] = piece ? whole.Bounds[2 * a] : axes[a].First;
    last[a] = piece ? whole.Bounds[2 * a + 1] : axes[a].Last;
    count[a] = piece ? whole.Extent[2 * a + 1] - whole.Extent[2 * a] + 1 : axes[a].Count;
    smallest[a] = piece ? whole.SmallestStep[a] : std::abs(axes[a].Mean);
    for (vtkIdType i = 1; !piece && i < axes[a].Count; ++i)
    {
      smallest[a] =
        std::min(smallest[a], coords[a]->GetComponent(i, 0) - coords[a]->GetComponent(i - 1, 0));
    }
  }
  int n[3];
  double spacing[3];
  ResampleLattice(first, last, smallest, count,
    kMaxResampleFactor * static_cast<double>(count[0]) * count[1] * count[2], n, spacing);
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetOrigin(first);
  image->SetSpacing(spacing);
  std::string seams;
  if (!piece)
  {
    image->SetExtent(0, n[0] - 1, 0, n[1] - 1, 0, n[2] - 1);
  }
  else
  {
    // The lattice points the piece's coordinates span, and the lattice cells it owns: from the
    // first lattice point at or after the world position of its first owned grid point to the
    // one at or after its last (the same bits of the shared coordinate on both neighbours: no
    // cell is owned twice or not at all).
    int cells[6];
    for (int a = 0; a < 3; ++a)
    {
      cells[2 * a] = ext[2 * a];
      cells[2 * a + 1] = std::max(ext[2 * a + 1] - 1, ext[2 * a]) + 1;
    }
    const bool ownsNothing = UnmarkedCellsOf(grid, ext, cells) == 0; // all ghost
    int pext[6], owned[6];
    for (int a = 0; a < 3; ++a)
    {
      auto at = [&](double x, double round) {
        const double u = (x - first[a]) / spacing[a];
        return std::clamp(static_cast<int>(round > 0 ? std::ceil(u - 1e-9) : std::floor(u + 1e-9)), 0, n[a] - 1);
      };
      auto coordinate = [&](int p) { return coords[a]->GetComponent(p - ext[2 * a], 0); };
      pext[2 * a] = at(axes[a].First, 1);
      pext[2 * a + 1] = at(axes[a].Last, -1);
      owned[2 * a] = cells[2 * a] <= whole.Extent[2 * a] ? 0 : at(coordinate(cells[2 * a]), 1);
      owned[2 * a + 1] = cells[2 * a + 1] >= whole.Extent[2 * a + 1]
        ? std::max(n[a] - 1, 1)
        : at(coordinate(std::min(cells[2 * a + 1], ext[2 * a + 1])), 1);
      // Shading's central differences read one lattice point beyond the owned ones.
      if (std::max(owned[2 * a] - 1, 0) < pext[2 * a] || std::min(owned[2 * a + 1] + 1, n[a] - 1) > pext[2 * a + 1])
      {
        seams += kAxis[a];
      }
      // The owned points must be in the image (beyond the piece's coordinates, its edge values).
      pext[2 * a] = std::min(pext[2 * a], owned[2 * a]);
      pext[2 * a + 1] = std::max(pext[2 * a + 1], std::min(owned[2 * a + 1], n[a] - 1));
    }
    if (ownsNothing)
    {
      owned[1] = owned[0];
    }
    image->SetExtent(pext);
    MarkOwnedCells(image, owned);
    for (int a = 0; a < 3; ++a)
    {
      this->LatticeWhole[2 * a] = 0;
      this->LatticeWhole[2 * a + 1] = n[a] - 1;
    }
  }
  ResampleTrilinear(grid, image);
  this->Image = image;
  this->Path = piece ? 3 : 2;
  char dev[32];
  std::snprintf(dev, sizeof(dev), "%.3g", deviation);
  warn(name + " (" + std::to_string(axes[0].Count) + " x " + std::to_string(axes[1].Count) +
    " x " + std::to_string(axes[2].Count) + " points" + (piece ? ", a piece of a larger grid" : "") +
    ") has non-uniform coordinates (largest relative step deviation " + dev + ", on " +
    kAxis[worst] + "): drawn resampled by trilinear interpolation on a uniform " +
    std::to_string(n[0]) + " x " + std::to_string(n[1]) + " x " + std::to_string(n[2]) +
    " lattice (the smallest step per axis, at most " +
    std::to_string(static_cast<int>(kMaxResampleFactor)) + "x the " + (piece ? "whole " : "") +
    "grid's points); a whole grid drawn alone, linear interpolation and one drawn component are "
    "drawn through the coordinates instead");
  if (!seams.empty())
  {
    warn(name + ": the piece's ghost layers do not reach the lattice points next to the cells it "
      "owns (along " + seams + "; steps at the piece's boundary are smaller than the lattice's): "
      "those points take the piece's edge values, so the image (its shading first) may differ "
      "from the serial one at that seam");
  }
  return this->Image;
}
