// ParaView's image-data volume representation with vtkSpaceSkippingVolumeMapper installed.
#include "vtkSpaceSkipVolumeRepresentation.h"

#include "vtkColorTransferFunction.h"
#include "vtkCellData.h"
#include "vtkCommunicator.h"
#include "vtkDataArray.h"
#include "vtkDataSet.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMath.h"
#include "vtkMatrix3x3.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOutlineSource.h"
#include "vtkPointData.h"
#include "vtkProcessModule.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkPVLODVolume.h"
#include "vtkPVProgressHandler.h"
#include "vtkPVSession.h"
#include "vtkPVRenderView.h"
#include "vtkPVView.h"
#include "vtkPartitionedDataSet.h"
#include "vtkRectilinearGrid.h"
#include "vtkScalarsToColors.h"
#include "vtkSpaceSkipMPIExchange.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkVolumeProperty.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkSpaceSkipVolumeRepresentation);

namespace
{
// The range of the drawn array over all ranks, per component and then of the magnitude
// ({lo0, hi0, lo1, hi1, ..., loMag, hiMag}), from each rank's `arrays` (maybe none). Collective:
// every rank calls it. Empty when no rank has the array.
std::vector<double> GatherWholeRanges(
  vtkMultiProcessController* controller, const std::vector<vtkDataArray*>& arrays)
{
  int local = 0, k = 0;
  for (vtkDataArray* a : arrays)
  {
    local = std::max(local, a->GetNumberOfComponents());
  }
  controller->AllReduce(&local, &k, 1, vtkCommunicator::MAX_OP);
  if (k < 1)
  {
    return {};
  }
  std::vector<double> lo(static_cast<size_t>(k + 1), VTK_DOUBLE_MAX);
  std::vector<double> hi(static_cast<size_t>(k + 1), VTK_DOUBLE_MIN);
  for (vtkDataArray* array : arrays)
  {
    if (array->GetNumberOfComponents() != k)
    {
      continue;
    }
    // As the mapper reads them: native single-component types as they are, the rest as float.
    const int t = array->GetDataType();
    const bool native = k == 1 &&
      (t == VTK_UNSIGNED_CHAR || t == VTK_CHAR || t == VTK_SIGNED_CHAR || t == VTK_UNSIGNED_SHORT ||
        t == VTK_SHORT || t == VTK_FLOAT || t == VTK_DOUBLE);
    for (int c = 0; c <= k; ++c)
    {
      double r[2];
      array->GetFiniteRange(r, c == k ? -1 : c);
      if (r[0] <= r[1])
      {
        lo[c] = std::min(lo[c], native ? r[0] : static_cast<double>(static_cast<float>(r[0])));
        hi[c] = std::max(hi[c], native ? r[1] : static_cast<double>(static_cast<float>(r[1])));
      }
    }
  }
  std::vector<double> wlo(lo.size()), whi(hi.size());
  controller->AllReduce(lo.data(), wlo.data(), static_cast<vtkIdType>(lo.size()), vtkCommunicator::MIN_OP);
  controller->AllReduce(hi.data(), whi.data(), static_cast<vtkIdType>(hi.size()), vtkCommunicator::MAX_OP);
  std::vector<double> ranges(2 * lo.size());
  for (size_t c = 0; c < lo.size(); ++c)
  {
    ranges[2 * c] = wlo[c];
    ranges[2 * c + 1] = whi[c];
  }
  return ranges;
}

// The image all ranks' image partitions make, when they lie on one axis-aligned lattice of one
// spacing: the world position of its first point (the same bits on every rank) and its extent
// counted from there. Collective: every rank calls it (with its partitions, maybe none). False
// (every rank alike) when there is no image, the spacings differ or an image is rotated: each
// rank then lays its blocks on a lattice of its own.
bool GatherLattice(vtkMultiProcessController* controller, const std::vector<vtkImageData*>& images,
  double origin[3], int extent[6])
{
  // lo[3], -hi[3], spacing[3], -spacing[3], rotated: reduced with MIN.
  double local[13], global[13];
  for (int a = 0; a < 3; ++a)
  {
    local[a] = local[3 + a] = local[6 + a] = local[9 + a] = VTK_DOUBLE_MAX;
  }
  local[12] = 0;
  for (vtkImageData* image : images)
  {
    const double* s = image->GetSpacing();
    const double* o = image->GetOrigin();
    const int* e = image->GetExtent();
    vtkMatrix3x3* d = image->GetDirectionMatrix();
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        if (d->GetElement(r, c) != (r == c ? 1.0 : 0.0))
        {
          local[12] = -1;
        }
      }
    }
    for (int a = 0; a < 3; ++a)
    {
      local[a] = std::min(local[a], o[a] + e[2 * a] * s[a]);
      local[3 + a] = std::min(local[3 + a], -(o[a] + e[2 * a + 1] * s[a]));
      local[6 + a] = std::min(local[6 + a], s[a]);
      local[9 + a] = std::min(local[9 + a], -s[a]);
    }
  }
  controller->AllReduce(local, global, 13, vtkCommunicator::MIN_OP);
  if (global[12] < 0 || global[0] == VTK_DOUBLE_MAX)
  {
    return false;
  }
  for (int a = 0; a < 3; ++a)
  {
    const double s = global[6 + a];
    if (!(s > 0) || std::abs(-global[9 + a] - s) > 1e-6 * s)
    {
      return false;
    }
    origin[a] = global[a];
    extent[2 * a] = 0;
    extent[2 * a + 1] = static_cast<int>(std::lround((-global[3 + a] - global[a]) / s));
  }
  return true;
}

// The array `info` names (FIELD_NAME, FIELD_ASSOCIATION) in `data`: an image or rectilinear grid,
// or the first partition that has it; null if none.
vtkDataArray* FindDrawnArray(vtkDataObject* data, vtkInformation* info)
{
  const char* name = info && info->Has(vtkDataObject::FIELD_NAME())
    ? info->Get(vtkDataObject::FIELD_NAME())
    : nullptr;
  if (!data || !name || !name[0])
  {
    return nullptr;
  }
  const bool cells = info->Has(vtkDataObject::FIELD_ASSOCIATION()) &&
    info->Get(vtkDataObject::FIELD_ASSOCIATION()) == vtkDataObject::FIELD_ASSOCIATION_CELLS;
  auto fromSet = [&](vtkDataSet* ds) -> vtkDataArray* {
    if (!ds)
    {
      return nullptr;
    }
    return cells ? ds->GetCellData()->GetArray(name) : ds->GetPointData()->GetArray(name);
  };
  if (auto* ds = vtkDataSet::SafeDownCast(data))
  {
    return fromSet(ds);
  }
  if (auto* pds = vtkPartitionedDataSet::SafeDownCast(data))
  {
    for (unsigned int i = 0; i < pds->GetNumberOfPartitions(); ++i)
    {
      if (vtkDataArray* a = fromSet(pds->GetPartition(i)))
      {
        return a;
      }
    }
  }
  return nullptr;
}

// One component of 8- or 16-bit integers: what the mapper draws as a label map.
bool IsLabelArray(vtkDataArray* a)
{
  if (!a || a->GetNumberOfComponents() != 1)
  {
    return false;
  }
  const int t = a->GetDataType();
  return t == VTK_UNSIGNED_CHAR || t == VTK_CHAR || t == VTK_SIGNED_CHAR ||
    t == VTK_UNSIGNED_SHORT || t == VTK_SHORT;
}

// The smallest coordinate step per axis of all ranks' pieces of a vtkRectilinearGrid (collective;
// 0 on an axis where no rank has two points, or no rank has a grid).
void GatherSmallestSteps(vtkMultiProcessController* controller, vtkRectilinearGrid* grid, double steps[3])
{
  double local[3] = { VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, VTK_DOUBLE_MAX };
  vtkDataArray* coords[3] = { grid ? grid->GetXCoordinates() : nullptr,
    grid ? grid->GetYCoordinates() : nullptr, grid ? grid->GetZCoordinates() : nullptr };
  for (int a = 0; a < 3; ++a)
  {
    for (vtkIdType i = 1; coords[a] && i < coords[a]->GetNumberOfTuples(); ++i)
    {
      const double step = std::abs(coords[a]->GetComponent(i, 0) - coords[a]->GetComponent(i - 1, 0));
      local[a] = step > 0 ? std::min(local[a], step) : local[a];
    }
  }
  controller->AllReduce(local, steps, 3, vtkCommunicator::MIN_OP);
  for (int a = 0; a < 3; ++a)
  {
    steps[a] = steps[a] == VTK_DOUBLE_MAX ? 0.0 : steps[a];
  }
}

// The bounds of all ranks' data (collective; uninitialized when no rank has data).
void GatherBounds(vtkMultiProcessController* controller, const double local[6], double global[6])
{
  double lo[6], out[6];
  const bool have = vtkMath::AreBoundsInitialized(local);
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = have ? local[2 * a] : VTK_DOUBLE_MAX;
    lo[3 + a] = have ? -local[2 * a + 1] : VTK_DOUBLE_MAX;
  }
  controller->AllReduce(lo, out, 6, vtkCommunicator::MIN_OP);
  vtkMath::UninitializeBounds(global);
  if (out[0] == VTK_DOUBLE_MAX)
  {
    return;
  }
  for (int a = 0; a < 3; ++a)
  {
    global[2 * a] = out[a];
    global[2 * a + 1] = -out[3 + a];
  }
}
} // namespace

//------------------------------------------------------------------------------
vtkSpaceSkipVolumeRepresentation::vtkSpaceSkipVolumeRepresentation()
{
  // Replace the base class's vtkMultiBlockVolumeMapper; UpdateMapperParameters() (run on every
  // REQUEST_RENDER) connects the delivered piece and sets it on the actor.
  auto mapper = vtkSmartPointer<vtkSpaceSkippingVolumeMapper>::New();
  this->SpaceSkipMapper = mapper;
  this->VolumeMapper = mapper;
  this->Actor->SetMapper(mapper);
  // The mapper's progress (value ranges, classification, build, Auto's measuring, long CPU
  // frames) to ParaView's progress bar: the session's handler listens to algorithms it is told
  // of, and the mapper lives inside this representation, out of its sight.
  vtkProcessModule* pm = vtkProcessModule::GetProcessModule();
  vtkPVSession* session = pm ? vtkPVSession::SafeDownCast(pm->GetActiveSession()) : nullptr;
  if (session && session->GetProgressHandler())
  {
    session->GetProgressHandler()->RegisterProgressEvent(mapper, 0);
  }
}

//------------------------------------------------------------------------------
vtkSpaceSkipVolumeRepresentation::~vtkSpaceSkipVolumeRepresentation() = default;

//------------------------------------------------------------------------------
void vtkSpaceSkipVolumeRepresentation::UpdateMapperParameters()
{
  this->Superclass::UpdateMapperParameters();
  // The base class sets the property's 2-D transfer-function mode (Use Transfer 2D) and function;
  // its y axis is the gradient magnitude, or with Use Gradient For Transfer 2D off the second
  // array (Color Array 2, as the base class gives vtkMultiBlockVolumeMapper's
  // Transfer2DYAxisArray), which the mapper reads from the delivered piece.
  const bool secondArray = this->UseTransfer2D && !this->UseGradientForTransfer2D && !this->ColorArray2Name.empty();
  this->SpaceSkipMapper->SetTransfer2DYAxisArray(secondArray ? this->ColorArray2Name.c_str() : nullptr);
  this->SpaceSkipMapper->SetTransfer2DYAxisComponent(std::max(this->ColorArray2Component, 0));
  // Under MPI its range over all ranks (RequestData gathers it): every rank's rows span it.
  const int k2 = static_cast<int>(this->SecondWholeRanges.size() / 2) - 1; // its components
  double yRange[2] = { 1, 0 };                                             // none: the piece's own
  if (secondArray && k2 >= 1)
  {
    const int c = std::min(std::max(this->ColorArray2Component, 0), k2 - 1);
    yRange[0] = this->SecondWholeRanges[2 * c];
    yRange[1] = this->SecondWholeRanges[2 * c + 1];
  }
  this->SpaceSkipMapper->SetWholeSecondAxisRange(yRange);
  this->UpdateLabelMap();
  // Same rule as the base class for vtkSmartVolumeMapper: with independent components the
  // colour map's vector mode and component, else component 0.
  vtkVolumeProperty* prop = this->Property;
  vtkColorTransferFunction* ctf = prop ? prop->GetRGBTransferFunction(0) : nullptr;
  if (!ctf)
  {
    return;
  }
  const bool indep = prop->GetIndependentComponents() != 0;
  this->SpaceSkipMapper->SetVectorMode(indep ? ctf->GetVectorMode() : vtkScalarsToColors::COMPONENT);
  this->SpaceSkipMapper->SetVectorComponent(indep ? ctf->GetVectorComponent() : 0);
  // In pieces: the whole data's range of what the mapper draws (its transfer-function table
  // spans the data's range; each piece's own range would give each rank another table).
  const int k = static_cast<int>(this->WholeRanges.size() / 2) - 1; // components
  double range[2] = { 1, 0 };                                         // none: the piece's own
  if (k >= 1)
  {
    const int mode = this->SpaceSkipMapper->GetVectorMode();
    const int c = k > 1 && mode == vtkScalarsToColors::MAGNITUDE
      ? k
      : std::min(std::max(this->SpaceSkipMapper->GetVectorComponent(), 0), k - 1);
    range[0] = this->WholeRanges[2 * c];
    range[1] = this->WholeRanges[2 * c + 1];
  }
  this->SpaceSkipMapper->SetWholeScalarRange(range);
}

//------------------------------------------------------------------------------
void vtkSpaceSkipVolumeRepresentation::UpdateLabelMap()
{
  bool on = this->LabelMapMode == LabelMapOn;
  if (this->LabelMapMode == LabelMapAuto)
  {
    // Auto: a categorical colour map ("Interpret Values As Categories") on an integer array the
    // mapper can draw as labels. Other types stay ordinary volumes, without the mapper's warning.
    vtkVolumeProperty* prop = this->Property;
    vtkColorTransferFunction* ctf = prop ? prop->GetRGBTransferFunction(0) : nullptr;
    on = ctf && ctf->GetIndexedLookup() &&
      IsLabelArray(FindDrawnArray(this->Cache, this->GetInputArrayInformation(0)));
  }
  this->SpaceSkipMapper->SetLabelMap(on);
}

//------------------------------------------------------------------------------
void vtkSpaceSkipVolumeRepresentation::SetLabelMapMode(int mode)
{
  mode = std::min(std::max(mode, 0), 2);
  if (this->LabelMapMode != mode)
  {
    this->LabelMapMode = mode;
    this->UpdateLabelMap();
    this->Modified();
  }
}

//------------------------------------------------------------------------------
int vtkSpaceSkipVolumeRepresentation::GetLabelMapUsed()
{
  return this->SpaceSkipMapper->GetLabelMap() ? 1 : 0;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipVolumeRepresentation::SetLabelSampling(int sampling)
{
  this->SpaceSkipMapper->SetLabelSampling(sampling);
}

//------------------------------------------------------------------------------
int vtkSpaceSkipVolumeRepresentation::GetLabelSampling()
{
  return this->SpaceSkipMapper->GetLabelSampling();
}

//------------------------------------------------------------------------------
void vtkSpaceSkipVolumeRepresentation::HideLabel(int id)
{
  if (std::find(this->HiddenLabels.begin(), this->HiddenLabels.end(), id) == this->HiddenLabels.end())
  {
    this->HiddenLabels.push_back(id);
    this->SpaceSkipMapper->SetLabelVisibility(id, 0);
    this->Modified();
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkipVolumeRepresentation::ShowAllLabels()
{
  for (int id : this->HiddenLabels)
  {
    this->SpaceSkipMapper->RemoveLabelVisibility(id);
  }
  if (!this->HiddenLabels.empty())
  {
    this->HiddenLabels.clear();
    this->Modified();
  }
}

//------------------------------------------------------------------------------
int vtkSpaceSkipVolumeRepresentation::RequestUpdateExtent(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!this->Superclass::RequestUpdateExtent(request, inputVector, outputVector))
  {
    return 0;
  }
  // Pieces share their face points, so a trilinear sample in a piece's own cells reads its own
  // voxels: no ghost layer (ParaView asks none of an image by default). A gradient's central
  // differences read one voxel further: one layer, only while a sample reads one. A
  // rectilinear grid's piece, if non-uniform, is resampled on the whole grid's lattice, whose
  // points next to the owned cells (and one further, for shading) can lie more than one grid
  // step beyond them: three layers (vtkSpaceSkipRectilinearImage warns where even that is short).
  using SDDP = vtkStreamingDemandDrivenPipeline;
  for (int i = 0; i < inputVector[0]->GetNumberOfInformationObjects(); ++i)
  {
    vtkInformation* info = inputVector[0]->GetInformationObject(i);
    const int pieces = info->Has(SDDP::UPDATE_NUMBER_OF_PIECES())
      ? info->Get(SDDP::UPDATE_NUMBER_OF_PIECES())
      : 1;
    if (pieces > 1)
    {
      const int levels = info->Has(SDDP::UPDATE_NUMBER_OF_GHOST_LEVELS())
        ? info->Get(SDDP::UPDATE_NUMBER_OF_GHOST_LEVELS())
        : 0;
      const bool grid = vtkRectilinearGrid::SafeDownCast(info->Get(vtkDataObject::DATA_OBJECT())) != nullptr;
      const int needed = grid ? 3 : (this->NeedsNeighbourPoints() ? 1 : 0);
      info->Set(SDDP::UPDATE_NUMBER_OF_GHOST_LEVELS(), std::max(levels, needed));
    }
  }
  return 1;
}

//------------------------------------------------------------------------------
int vtkSpaceSkipVolumeRepresentation::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (inputVector[0]->GetNumberOfInformationObjects() == 1 && vtkPartitionedDataSet::GetData(inputVector[0], 0))
  {
    return this->RequestPartitionedData(request, inputVector, outputVector);
  }
  vtkImageData* input = inputVector[0]->GetNumberOfInformationObjects() == 1
    ? vtkImageData::GetData(inputVector[0], 0)
    : nullptr;
  const int ok = input && input->HasAnyGhostCells() && !this->UseSeparateOpacityArray
    ? this->RequestPieceWithGhosts(input, request, inputVector, outputVector)
    : this->Superclass::RequestData(request, inputVector, outputVector);
  this->SpaceSkipMapper->SetWholeExtent(this->WholeExtent);
  // The ranges of the drawn piece's arrays, in one parallel pass each, where VTK has none yet:
  // ParaView takes them of every array of the piece for its array lists (and the whole range
  // below takes the colour array's), one value at a time. A piece with a ghost layer is new
  // data after the reader ran again for it (a shaded 2-rank first frame at 512^3 on the 2-core
  // machine: 11.2 s without this, 0.67 s with it).
  if (auto* piece = vtkDataSet::SafeDownCast(this->Cache))
  {
    for (vtkDataSetAttributes* attributes :
      { static_cast<vtkDataSetAttributes*>(piece->GetPointData()), static_cast<vtkDataSetAttributes*>(piece->GetCellData()) })
    {
      for (int i = 0; i < attributes->GetNumberOfArrays(); ++i)
      {
        vtkSpaceSkippingVolumeMapper::FillRangeCaches(attributes->GetArray(i));
      }
    }
  }

  // The colour array's range over all ranks (collective: every rank runs RequestData).
  this->WholeRanges.clear();
  this->SecondWholeRanges.clear();
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  this->UpdateExchange(controller);
  if (controller && controller->GetNumberOfProcesses() > 1)
  {
    // A rectilinear grid's pieces: its smallest step per axis over all ranks, so that the mapper
    // resamples a non-uniform piece on the lattice the serial grid gets (collective).
    double steps[3];
    GatherSmallestSteps(controller,
      inputVector[0]->GetNumberOfInformationObjects() == 1 ? vtkRectilinearGrid::GetData(inputVector[0], 0) : nullptr,
      steps);
    this->SpaceSkipMapper->SetWholeGridSteps(steps);
  }
  vtkInformation* arrayInfo = this->GetInputArrayInformation(0);
  const char* name = arrayInfo && arrayInfo->Has(vtkDataObject::FIELD_NAME())
    ? arrayInfo->Get(vtkDataObject::FIELD_NAME())
    : nullptr;
  if (!controller || controller->GetNumberOfProcesses() < 2 || !name || !name[0])
  {
    return ok;
  }
  std::vector<vtkDataArray*> arrays;
  if (vtkDataArray* array = input ? input->GetPointData()->GetArray(name) : nullptr)
  {
    arrays.push_back(array);
  }
  this->WholeRanges = GatherWholeRanges(controller, arrays);
  // Color Array 2 (the 2-D transfer function's y axis): its whole range too.
  std::vector<vtkDataArray*> second;
  if (vtkDataArray* array = input && !this->ColorArray2Name.empty()
        ? input->GetPointData()->GetArray(this->ColorArray2Name.c_str())
        : nullptr)
  {
    second.push_back(array);
  }
  this->SecondWholeRanges = this->ColorArray2Name.empty() ? std::vector<double>()
                                                          : GatherWholeRanges(controller, second);
  return ok;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipVolumeRepresentation::UpdateExchange(vtkMultiProcessController* controller)
{
  const bool parallel = controller && controller->GetNumberOfProcesses() > 1;
  if (parallel)
  {
    // The bounds of all ranks' data: the volume reports them while the exchange is on.
    double whole[6];
    GatherBounds(controller, this->DataBounds, whole);
    this->SpaceSkipMapper->SetWholeBounds(whole);
  }
  if (parallel && this->NodeRank < 0)
  {
    // One rank per GPU: each rank's CUDA backend on the device of its node-local rank
    // (modulo the node's devices). Collective, once.
    int local = 0, onNode = 1;
    this->NodeRank = vtkSpaceSkipMPIExchange::NodeLocalRank(controller, local, onNode) ? local : 0;
    this->RanksOnNode = onNode;
    this->SpaceSkipMapper->SetCudaDevice(this->NodeRank);
  }
  const bool want = this->FloatCompositing && parallel;
  if (want && !this->Exchange)
  {
    // Collective (a communicator of its own): every rank runs RequestData. One that gave up
    // stays off until the property is turned off and on (the same on every rank).
    this->Exchange = vtkSpaceSkipMPIExchange::New(controller,
      [](const std::string& m) { vtkGenericWarningMacro(<< "SpaceSkip: " << m); },
      this->RanksOnNode == controller->GetNumberOfProcesses());
  }
  else if (!want)
  {
    this->Exchange.reset();
  }
  this->SpaceSkipMapper->SetPieceExchange(this->Exchange);
}

//------------------------------------------------------------------------------
void vtkSpaceSkipVolumeRepresentation::SetFloatCompositing(int on)
{
  if (this->FloatCompositing != on)
  {
    this->FloatCompositing = on;
    this->MarkModified(); // RequestData (on every rank) makes or drops the exchange
  }
}

//------------------------------------------------------------------------------
int vtkSpaceSkipVolumeRepresentation::ProcessViewRequest(
  vtkInformationRequestKey* request_type, vtkInformation* inInfo, vtkInformation* outInfo)
{
  if (!this->Superclass::ProcessViewRequest(request_type, inInfo, outInfo))
  {
    return 0;
  }
  if (request_type == vtkPVView::REQUEST_UPDATE() && this->SpaceSkipMapper->GetPieceExchange())
  {
    // The exchange waits for every rank's piece: IceT must draw every rank in every frame, even
    // one whose piece is out of the tile.
    outInfo->Set(vtkPVRenderView::RENDER_EMPTY_IMAGES(), 1);
  }
  if ((request_type == vtkPVView::REQUEST_UPDATE() || request_type == vtkPVView::REQUEST_RENDER()) &&
    this->SpaceSkipMapper->GetPieceExchange() && this->GetVisibility())
  {
    this->KeepFXAAOffVolumes(this->GetView());
  }
  return 1;
}

//------------------------------------------------------------------------------
// The view's settings reach every rank alike (the proxy pushes them to all), and so does this
// request: every rank turns FXAA off together.
void vtkSpaceSkipVolumeRepresentation::KeepFXAAOffVolumes(vtkView* view)
{
  auto* rv = vtkPVRenderView::SafeDownCast(view);
  if (!rv || !rv->GetUseFXAA())
  {
    return;
  }
  rv->SetUseFXAA(false);
  this->TurnedFXAAOff = true;
  if (!this->WarnedFXAA)
  {
    vtkMultiProcessController* c = vtkMultiProcessController::GetGlobalController();
    if (!c || c->GetLocalProcessId() == 0)
    {
      vtkWarningMacro(<< "FXAA is off in this view while the Space Skipping Volume is composited "
                         "across processes: ParaView applies FXAA to the composited frame, "
                         "volumes included (serially it smooths no volume), which drew up to "
                         "121/255 away from the serial image");
    }
  }
  this->WarnedFXAA = true;
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipVolumeRepresentation::RemoveFromView(vtkView* view)
{
  auto* rv = vtkPVRenderView::SafeDownCast(view);
  if (rv && this->TurnedFXAAOff)
  {
    rv->SetUseFXAA(true); // the user's setting, as it was before this representation
  }
  this->TurnedFXAAOff = false;
  return this->Superclass::RemoveFromView(view);
}

//------------------------------------------------------------------------------
int vtkSpaceSkipVolumeRepresentation::RequestPieceWithGhosts(vtkImageData* input,
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // What vtkImageVolumeRepresentation::RequestData does for an image piece with ghost layers,
  // less its vtkImageData::Crop of the ghost cells: the mapper draws the piece with them (its
  // own cells only), and the crop copied the piece tuple by tuple (24 of the 50 s of a 2-rank
  // pvbatch run of a 512^3 volume on the 2-core machine). The bounds of the cells without ghosts,
  // which the base class took from the cropped piece, still go to the ordered compositing and the
  // outline.
  auto cache = vtkSmartPointer<vtkImageData>::New();
  cache->ShallowCopy(input);
  int own[6];
  vtkSpaceSkippingVolumeMapper::GetOwnedExtent(input, own);
  vtkNew<vtkImageData> shape; // the piece's lattice without its ghost layers, no arrays
  shape->SetExtent(own);
  shape->SetOrigin(input->GetOrigin());
  shape->SetSpacing(input->GetSpacing());
  shape->SetDirectionMatrix(input->GetDirectionMatrix());
  this->Actor->SetEnableLOD(0);
  this->VolumeMapper->SetInputData(cache);
  this->OutlineSource->SetBounds(shape->GetBounds());
  this->OutlineSource->GetBounds(this->DataBounds);
  this->OutlineSource->Update();
  this->DataSize = cache->GetActualMemorySize();
  vtkStreamingDemandDrivenPipeline::GetWholeExtent(
    inputVector[0]->GetInformationObject(0), this->WholeExtent);
  this->Cache = cache;
  return this->vtkVolumeRepresentation::RequestData(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------
int vtkSpaceSkipVolumeRepresentation::RequestPartitionedData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPartitionedDataSet* input = vtkPartitionedDataSet::GetData(inputVector[0], 0);
  // What vtkImageVolumeRepresentation::RequestData does for partitioned input with
  // vtkMultiBlockVolumeMapper, plus the outline (drawn where the data is not) and the data size.
  vtkMath::UninitializeBounds(this->DataBounds);
  this->DataSize = 0;
  this->WholeExtent[0] = this->WholeExtent[2] = this->WholeExtent[4] = 0;
  this->WholeExtent[1] = this->WholeExtent[3] = this->WholeExtent[5] = -1;
  vtkNew<vtkPartitionedDataSet> cache;
  unsigned int n = 0;
  for (unsigned int i = 0; i < input->GetNumberOfPartitions(); ++i)
  {
    vtkDataSet* partition = input->GetPartition(i);
    if (!partition)
    {
      continue;
    }
    if (this->UseSeparateOpacityArray)
    {
      this->AppendOpacityComponent(partition);
    }
    // Other types stay in: the mapper says once that it skips them.
    cache->SetPartition(n++, partition);
  }
  // Under MPI the blocks of all ranks make one image: its lattice (every rank's blocks sample
  // it) and the range of the drawn array (every rank's table spans it). Collective.
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  this->WholeRanges.clear();
  this->SecondWholeRanges.clear();
  double wholeOrigin[3] = { 0, 0, 0 };
  int wholeExtent[6] = { 0, -1, 0, -1, 0, -1 };
  if (controller && controller->GetNumberOfProcesses() > 1)
  {
    std::vector<vtkImageData*> images;
    std::vector<vtkDataArray*> arrays, second;
    vtkInformation* arrayInfo = this->GetInputArrayInformation(0);
    const char* name = arrayInfo && arrayInfo->Has(vtkDataObject::FIELD_NAME())
      ? arrayInfo->Get(vtkDataObject::FIELD_NAME())
      : nullptr;
    for (unsigned int i = 0; i < cache->GetNumberOfPartitions(); ++i)
    {
      auto* image = vtkImageData::SafeDownCast(cache->GetPartition(i));
      if (image && image->GetNumberOfPoints() > 0)
      {
        images.push_back(image);
        if (vtkDataArray* a = name && name[0] ? image->GetPointData()->GetArray(name) : nullptr)
        {
          arrays.push_back(a);
        }
        if (vtkDataArray* a = this->ColorArray2Name.empty()
              ? nullptr
              : image->GetPointData()->GetArray(this->ColorArray2Name.c_str()))
        {
          second.push_back(a);
        }
      }
    }
    if (!GatherLattice(controller, images, wholeOrigin, wholeExtent))
    {
      wholeExtent[1] = -1;
    }
    if (name && name[0])
    {
      this->WholeRanges = GatherWholeRanges(controller, arrays);
    }
    if (!this->ColorArray2Name.empty())
    {
      this->SecondWholeRanges = GatherWholeRanges(controller, second);
    }
  }
  this->SpaceSkipMapper->SetWholeOrigin(wholeOrigin);
  this->SpaceSkipMapper->SetWholeExtent(wholeExtent);

  cache->GetBounds(this->DataBounds);
  this->UpdateExchange(controller);
  if (vtkMath::AreBoundsInitialized(this->DataBounds))
  {
    this->OutlineSource->SetBounds(this->DataBounds);
    this->OutlineSource->Update();
  }
  this->DataSize = cache->GetActualMemorySize();
  this->Actor->SetEnableLOD(0);
  this->Cache = cache;
  // Skips vtkImageVolumeRepresentation::RequestData (it would refuse the partitions).
  return this->vtkVolumeRepresentation::RequestData(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------
// Setters: the mapper's own Modified() makes the next render rebuild what the change needs.
// Settings and statistics passed to and from the mapper as they are (the getters cast the
// mapper's type to the representation's).
#define vtkSpaceSkipForwardSet(name, type)                                                        \
  void vtkSpaceSkipVolumeRepresentation::Set##name(type v)                                         \
  {                                                                                                \
    this->SpaceSkipMapper->Set##name(v);                                                           \
  }
#define vtkSpaceSkipForwardGet(name, type)                                                        \
  type vtkSpaceSkipVolumeRepresentation::Get##name()                                               \
  {                                                                                                \
    return static_cast<type>(this->SpaceSkipMapper->Get##name());                                  \
  }
#define vtkSpaceSkipForward(name, type)                                                           \
  vtkSpaceSkipForwardSet(name, type) vtkSpaceSkipForwardGet(name, type)
// An on/off setting: the mapper's bool as the representation's 0/1 int.
#define vtkSpaceSkipForwardBool(name)                                                             \
  void vtkSpaceSkipVolumeRepresentation::Set##name(int v)                                          \
  {                                                                                                \
    this->SpaceSkipMapper->Set##name(v != 0);                                                      \
  }                                                                                                \
  int vtkSpaceSkipVolumeRepresentation::Get##name()                                                \
  {                                                                                                \
    return this->SpaceSkipMapper->Get##name() ? 1 : 0;                                             \
  }

vtkSpaceSkipForward(Builder, int)
vtkSpaceSkipForward(LeafCriterion, int)
vtkSpaceSkipForward(MaxLeafSize, int)
vtkSpaceSkipForward(BinCount, int)
vtkSpaceSkipForward(MacroCellSize, int)
vtkSpaceSkipForward(SampleDistance, double)
vtkSpaceSkipForward(Backend, int)
vtkSpaceSkipForward(FilterMode, int)
vtkSpaceSkipForwardGet(LastBuildSeconds, double)
vtkSpaceSkipForwardGet(LastClassifySeconds, double)
vtkSpaceSkipForwardGet(LastRenderSeconds, double)
vtkSpaceSkipForwardGet(SampleDistanceUsed, double)
vtkSpaceSkipForwardGet(NodeCount, double)
vtkSpaceSkipForwardGet(TreeHeight, int)
vtkSpaceSkipForwardGet(LeafCount, double)
vtkSpaceSkipForwardGet(Occupancy, double)
vtkSpaceSkipForwardGet(BuildCount, int)
vtkSpaceSkipForwardGet(ClassifyCount, int)
vtkSpaceSkipForwardGet(ColorUpdateCount, int)
vtkSpaceSkipForwardGet(FrameCount, int)

vtkSpaceSkipForwardBool(EarlyRayTermination)
vtkSpaceSkipForwardBool(UseJittering)
vtkSpaceSkipForwardBool(GPUComposite)
vtkSpaceSkipForwardBool(InteractiveAdjustSampleDistances)

bool vtkSpaceSkipVolumeRepresentation::NeedsNeighbourPoints()
{
  return this->Property->GetShade() != 0 || (this->UseTransfer2D && this->UseGradientForTransfer2D);
}

void vtkSpaceSkipVolumeRepresentation::NeighbourNeedMayHaveChanged(bool before)
{
  // Serially no ghost layer is ever asked for, and a new request would only hand the mapper a
  // new copy of the same volume to upload.
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  if (before != this->NeedsNeighbourPoints() && controller && controller->GetNumberOfProcesses() > 1)
  {
    this->MarkModified();
  }
}

void vtkSpaceSkipVolumeRepresentation::SetShade(bool shade)
{
  const bool before = this->NeedsNeighbourPoints();
  this->Superclass::SetShade(shade);
  this->NeighbourNeedMayHaveChanged(before);
}

void vtkSpaceSkipVolumeRepresentation::SetUseTransfer2D(bool use)
{
  const bool before = this->NeedsNeighbourPoints();
  this->Superclass::SetUseTransfer2D(use);
  this->NeighbourNeedMayHaveChanged(before);
}

void vtkSpaceSkipVolumeRepresentation::SetUseGradientForTransfer2D(bool use)
{
  const bool before = this->NeedsNeighbourPoints();
  this->Superclass::SetUseGradientForTransfer2D(use);
  this->NeighbourNeedMayHaveChanged(before);
}

void vtkSpaceSkipVolumeRepresentation::SetGlobalIlluminationReach(float reach)
{
  this->Superclass::SetGlobalIlluminationReach(reach);
  this->SpaceSkipMapper->SetGlobalIlluminationReach(reach);
}
void vtkSpaceSkipVolumeRepresentation::SetVolumetricScatteringBlending(float blending)
{
  this->Superclass::SetVolumetricScatteringBlending(blending);
  this->SpaceSkipMapper->SetVolumetricScatteringBlending(blending);
}
void vtkSpaceSkipVolumeRepresentation::SetDeviceMemoryBudget(int mib)
{
  this->SpaceSkipMapper->SetDeviceMemoryBudget(mib);
}

void vtkSpaceSkipVolumeRepresentation::SetExtraBlendMode(int mode)
{
  this->SpaceSkipMapper->SetBlendModeOverride(mode);
}

int vtkSpaceSkipVolumeRepresentation::GetExtraBlendMode()
{
  return this->SpaceSkipMapper->GetBlendModeOverride();
}

//------------------------------------------------------------------------------
// The string getters copy: the wrapped caller reads the value after the mapper may change it.
namespace
{
const char* CopyText(const char* text, std::string& copy)
{
  copy = text ? text : "";
  return copy.c_str();
}
} // namespace

const char* vtkSpaceSkipVolumeRepresentation::GetResidency()
{
  return CopyText(this->SpaceSkipMapper->GetResidency(), this->ResidencyText);
}
const char* vtkSpaceSkipVolumeRepresentation::GetBuilderChoice()
{
  return CopyText(this->SpaceSkipMapper->GetBuilderChoice(), this->BuilderChoiceText);
}
const char* vtkSpaceSkipVolumeRepresentation::GetBuilderUsed()
{
  return CopyText(this->SpaceSkipMapper->GetBuilderUsed(), this->BuilderUsedName);
}
const char* vtkSpaceSkipVolumeRepresentation::GetBackendUsed()
{
  return CopyText(this->SpaceSkipMapper->GetBackendUsed(), this->BackendUsedName);
}

//------------------------------------------------------------------------------
const char* vtkSpaceSkipVolumeRepresentation::GetCudaDeviceUsed()
{
  std::string text = this->SpaceSkipMapper->GetCudaDeviceUsed();
  if (text != "none" && this->NodeRank >= 0)
  {
    text += " (node rank " + std::to_string(this->NodeRank) + " of " + std::to_string(this->RanksOnNode) + ")";
  }
  this->CudaDeviceUsedName = text;
  return this->CudaDeviceUsedName.c_str();
}

//------------------------------------------------------------------------------
const char* vtkSpaceSkipVolumeRepresentation::GetCompositePathUsed()
{
  std::string path = this->SpaceSkipMapper->GetCompositePathUsed();
  if (path != "none")
  {
    path += std::string(" (blend ") + this->SpaceSkipMapper->GetCompositeBlendUsed() + ")";
  }
  return CopyText(path.c_str(), this->CompositePathText);
}

//------------------------------------------------------------------------------
const char* vtkSpaceSkipVolumeRepresentation::GetPieceCompositingUsed()
{
  return CopyText(this->SpaceSkipMapper->GetPieceCompositingUsed(), this->PieceCompositingText);
}

//------------------------------------------------------------------------------
void vtkSpaceSkipVolumeRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SpaceSkipMapper: " << this->SpaceSkipMapper << "\n";
}
