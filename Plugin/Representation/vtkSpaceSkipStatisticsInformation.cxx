// The statistics of a vtkSpaceSkipVolumeRepresentation, gathered where it renders.
#include "vtkSpaceSkipStatisticsInformation.h"

#include "vtkClientServerStream.h"
#include "vtkObjectFactory.h"
#include "vtkSpaceSkipVolumeRepresentation.h"

vtkStandardNewMacro(vtkSpaceSkipStatisticsInformation);

namespace
{
// The information properties of SpaceSkipRepresentation.xml, in stream order.
const char* const kNumberNames[vtkSpaceSkipStatisticsInformation::NumberCount] = {
  "LastBuildSeconds", "LastClassifySeconds", "LastRenderSeconds", "SampleDistanceUsed",
  "NodeCount", "LeafCount", "Occupancy", "TreeHeight", "BuildCount", "ClassifyCount",
  "ColorUpdateCount", "FrameCount", "LabelMapUsed"
};
const char* const kTextNames[vtkSpaceSkipStatisticsInformation::TextCount] = { "BackendUsed",
  "BuilderUsed", "BuilderChoice", "Residency", "CudaDeviceUsed", "CompositePathUsed", "PieceCompositingUsed" };
constexpr int kFrameCount = 11; // index of FrameCount in kNumberNames
}

//------------------------------------------------------------------------------
vtkSpaceSkipStatisticsInformation::vtkSpaceSkipStatisticsInformation()
{
  this->RootOnly = 1;
}

//------------------------------------------------------------------------------
vtkSpaceSkipStatisticsInformation::~vtkSpaceSkipStatisticsInformation() = default;

//------------------------------------------------------------------------------
const char* vtkSpaceSkipStatisticsInformation::GetNumberName(int i)
{
  return (i >= 0 && i < NumberCount) ? kNumberNames[i] : nullptr;
}

//------------------------------------------------------------------------------
const char* vtkSpaceSkipStatisticsInformation::GetTextName(int i)
{
  return (i >= 0 && i < TextCount) ? kTextNames[i] : nullptr;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipStatisticsInformation::CopyFromObject(vtkObject* object)
{
  auto* rep = vtkSpaceSkipVolumeRepresentation::SafeDownCast(object);
  this->Valid = rep != nullptr;
  if (!rep)
  {
    this->Numbers.fill(0);
    this->Texts.fill("");
    return;
  }
  this->Numbers = { rep->GetLastBuildSeconds(), rep->GetLastClassifySeconds(),
    rep->GetLastRenderSeconds(), rep->GetSampleDistanceUsed(), rep->GetNodeCount(),
    rep->GetLeafCount(), rep->GetOccupancy(), static_cast<double>(rep->GetTreeHeight()),
    static_cast<double>(rep->GetBuildCount()), static_cast<double>(rep->GetClassifyCount()),
    static_cast<double>(rep->GetColorUpdateCount()), static_cast<double>(rep->GetFrameCount()),
    static_cast<double>(rep->GetLabelMapUsed()) };
  this->Texts = { rep->GetBackendUsed(), rep->GetBuilderUsed(), rep->GetBuilderChoice(),
    rep->GetResidency(), rep->GetCudaDeviceUsed(), rep->GetCompositePathUsed(),
    rep->GetPieceCompositingUsed() };
}

//------------------------------------------------------------------------------
void vtkSpaceSkipStatisticsInformation::AddInformation(vtkPVInformation* other)
{
  auto* o = vtkSpaceSkipStatisticsInformation::SafeDownCast(other);
  if (o && o->Valid &&
    (!this->Valid || (this->Numbers[kFrameCount] == 0 && o->Numbers[kFrameCount] > 0)))
  {
    this->Valid = true;
    this->Numbers = o->Numbers;
    this->Texts = o->Texts;
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkipStatisticsInformation::CopyToStream(vtkClientServerStream* css)
{
  css->Reset();
  *css << vtkClientServerStream::Reply << (this->Valid ? 1 : 0);
  for (double v : this->Numbers)
  {
    *css << v;
  }
  for (const std::string& t : this->Texts)
  {
    *css << t.c_str();
  }
  *css << vtkClientServerStream::End;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipStatisticsInformation::CopyFromStream(const vtkClientServerStream* css)
{
  int valid = 0;
  int arg = 0;
  if (!css->GetArgument(0, arg++, &valid))
  {
    vtkErrorMacro("Error parsing the SpaceSkip statistics from the message.");
    this->Valid = false;
    return;
  }
  this->Valid = valid != 0;
  for (double& v : this->Numbers)
  {
    if (!css->GetArgument(0, arg++, &v))
    {
      vtkErrorMacro("Error parsing the SpaceSkip statistics from the message.");
      this->Valid = false;
      return;
    }
  }
  for (std::string& t : this->Texts)
  {
    const char* text = nullptr;
    if (!css->GetArgument(0, arg++, &text))
    {
      vtkErrorMacro("Error parsing the SpaceSkip statistics from the message.");
      this->Valid = false;
      return;
    }
    t = text ? text : "";
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkipStatisticsInformation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Valid: " << this->Valid << "\n";
  for (int i = 0; i < NumberCount; ++i)
  {
    os << indent << kNumberNames[i] << ": " << this->Numbers[i] << "\n";
  }
  for (int i = 0; i < TextCount; ++i)
  {
    os << indent << kTextNames[i] << ": " << this->Texts[i] << "\n";
  }
}
