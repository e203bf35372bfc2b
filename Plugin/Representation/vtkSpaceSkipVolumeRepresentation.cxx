// ParaView's image-data volume representation with vtkSpaceSkippingVolumeMapper installed.
#include "vtkSpaceSkipVolumeRepresentation.h"

#include "vtkColorTransferFunction.h"
#include "vtkImageData.h"
#include "vtkInformationVector.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOutlineSource.h"
#include "vtkPVLODVolume.h"
#include "vtkPartitionedDataSet.h"
#include "vtkScalarsToColors.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkVolumeProperty.h"

vtkStandardNewMacro(vtkSpaceSkipVolumeRepresentation);

//------------------------------------------------------------------------------
vtkSpaceSkipVolumeRepresentation::vtkSpaceSkipVolumeRepresentation()
{
  // Replace the base class's vtkMultiBlockVolumeMapper; UpdateMapperParameters() (run on every
  // REQUEST_RENDER) connects the delivered piece and sets it on the actor.
  auto mapper = vtkSmartPointer<vtkSpaceSkippingVolumeMapper>::New();
  this->SpaceSkipMapper = mapper;
  this->VolumeMapper = mapper;
  this->Actor->SetMapper(mapper);
}

//------------------------------------------------------------------------------
vtkSpaceSkipVolumeRepresentation::~vtkSpaceSkipVolumeRepresentation() = default;

//------------------------------------------------------------------------------
void vtkSpaceSkipVolumeRepresentation::UpdateMapperParameters()
{
  this->Superclass::UpdateMapperParameters();
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
}

//------------------------------------------------------------------------------
int vtkSpaceSkipVolumeRepresentation::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPartitionedDataSet* input = inputVector[0]->GetNumberOfInformationObjects() == 1
    ? vtkPartitionedDataSet::GetData(inputVector[0], 0)
    : nullptr;
  if (!input)
  {
    return this->Superclass::RequestData(request, inputVector, outputVector);
  }
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
  cache->GetBounds(this->DataBounds);
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
void vtkSpaceSkipVolumeRepresentation::SetBuilder(int v)
{
  this->SpaceSkipMapper->SetBuilder(v);
}
int vtkSpaceSkipVolumeRepresentation::GetBuilder()
{
  return this->SpaceSkipMapper->GetBuilder();
}
void vtkSpaceSkipVolumeRepresentation::SetLeafCriterion(int v)
{
  this->SpaceSkipMapper->SetLeafCriterion(v);
}
int vtkSpaceSkipVolumeRepresentation::GetLeafCriterion()
{
  return this->SpaceSkipMapper->GetLeafCriterion();
}
void vtkSpaceSkipVolumeRepresentation::SetMaxLeafSize(int v)
{
  this->SpaceSkipMapper->SetMaxLeafSize(v);
}
int vtkSpaceSkipVolumeRepresentation::GetMaxLeafSize()
{
  return this->SpaceSkipMapper->GetMaxLeafSize();
}
void vtkSpaceSkipVolumeRepresentation::SetBinCount(int v)
{
  this->SpaceSkipMapper->SetBinCount(v);
}
int vtkSpaceSkipVolumeRepresentation::GetBinCount()
{
  return this->SpaceSkipMapper->GetBinCount();
}
void vtkSpaceSkipVolumeRepresentation::SetMacroCellSize(int v)
{
  this->SpaceSkipMapper->SetMacroCellSize(v);
}
int vtkSpaceSkipVolumeRepresentation::GetMacroCellSize()
{
  return this->SpaceSkipMapper->GetMacroCellSize();
}
void vtkSpaceSkipVolumeRepresentation::SetSampleDistance(double v)
{
  this->SpaceSkipMapper->SetSampleDistance(v);
}
double vtkSpaceSkipVolumeRepresentation::GetSampleDistance()
{
  return this->SpaceSkipMapper->GetSampleDistance();
}
void vtkSpaceSkipVolumeRepresentation::SetBackend(int v)
{
  this->SpaceSkipMapper->SetBackend(v);
}
int vtkSpaceSkipVolumeRepresentation::GetBackend()
{
  return this->SpaceSkipMapper->GetBackend();
}
void vtkSpaceSkipVolumeRepresentation::SetEarlyRayTermination(int v)
{
  this->SpaceSkipMapper->SetEarlyRayTermination(v != 0);
}
int vtkSpaceSkipVolumeRepresentation::GetEarlyRayTermination()
{
  return this->SpaceSkipMapper->GetEarlyRayTermination() ? 1 : 0;
}
void vtkSpaceSkipVolumeRepresentation::SetUseJittering(int v)
{
  this->SpaceSkipMapper->SetUseJittering(v != 0);
}
int vtkSpaceSkipVolumeRepresentation::GetUseJittering()
{
  return this->SpaceSkipMapper->GetUseJittering() ? 1 : 0;
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
double vtkSpaceSkipVolumeRepresentation::GetLastBuildSeconds()
{
  return this->SpaceSkipMapper->GetLastBuildSeconds();
}
double vtkSpaceSkipVolumeRepresentation::GetLastClassifySeconds()
{
  return this->SpaceSkipMapper->GetLastClassifySeconds();
}
double vtkSpaceSkipVolumeRepresentation::GetLastRenderSeconds()
{
  return this->SpaceSkipMapper->GetLastRenderSeconds();
}
double vtkSpaceSkipVolumeRepresentation::GetSampleDistanceUsed()
{
  return this->SpaceSkipMapper->GetSampleDistanceUsed();
}
double vtkSpaceSkipVolumeRepresentation::GetNodeCount()
{
  return static_cast<double>(this->SpaceSkipMapper->GetNodeCount());
}
int vtkSpaceSkipVolumeRepresentation::GetTreeHeight()
{
  return static_cast<int>(this->SpaceSkipMapper->GetTreeHeight());
}
double vtkSpaceSkipVolumeRepresentation::GetLeafCount()
{
  return static_cast<double>(this->SpaceSkipMapper->GetLeafCount());
}
double vtkSpaceSkipVolumeRepresentation::GetOccupancy()
{
  return this->SpaceSkipMapper->GetOccupancy();
}
// The string getters copy: the wrapped caller reads the value after the mapper may change it.
const char* vtkSpaceSkipVolumeRepresentation::GetBuilderChoice()
{
  const char* text = this->SpaceSkipMapper->GetBuilderChoice();
  this->BuilderChoiceText = text ? text : "";
  return this->BuilderChoiceText.c_str();
}
const char* vtkSpaceSkipVolumeRepresentation::GetBuilderUsed()
{
  const char* name = this->SpaceSkipMapper->GetBuilderUsed();
  this->BuilderUsedName = name ? name : "";
  return this->BuilderUsedName.c_str();
}
const char* vtkSpaceSkipVolumeRepresentation::GetBackendUsed()
{
  const char* name = this->SpaceSkipMapper->GetBackendUsed();
  this->BackendUsedName = name ? name : "";
  return this->BackendUsedName.c_str();
}
int vtkSpaceSkipVolumeRepresentation::GetBuildCount()
{
  return static_cast<int>(this->SpaceSkipMapper->GetBuildCount());
}
int vtkSpaceSkipVolumeRepresentation::GetClassifyCount()
{
  return static_cast<int>(this->SpaceSkipMapper->GetClassifyCount());
}
int vtkSpaceSkipVolumeRepresentation::GetColorUpdateCount()
{
  return static_cast<int>(this->SpaceSkipMapper->GetColorUpdateCount());
}
int vtkSpaceSkipVolumeRepresentation::GetFrameCount()
{
  return static_cast<int>(this->SpaceSkipMapper->GetFrameCount());
}

//------------------------------------------------------------------------------
void vtkSpaceSkipVolumeRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SpaceSkipMapper: " << this->SpaceSkipMapper << "\n";
}
