// The server-manager proxy of "Space Skipping Volume": its statistics come from the render server.
#include "vtkSMSpaceSkipRepresentationProxy.h"

#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPVSession.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSpaceSkipStatisticsInformation.h"

#include <cstring>

vtkStandardNewMacro(vtkSMSpaceSkipRepresentationProxy);

//------------------------------------------------------------------------------
vtkSMSpaceSkipRepresentationProxy::vtkSMSpaceSkipRepresentationProxy() = default;

//------------------------------------------------------------------------------
vtkSMSpaceSkipRepresentationProxy::~vtkSMSpaceSkipRepresentationProxy() = default;

//------------------------------------------------------------------------------
void vtkSMSpaceSkipRepresentationProxy::UpdatePropertyInformationInternal(vtkSMProperty* prop)
{
  this->Superclass::UpdatePropertyInformationInternal(prop);
  if (!this->ObjectsCreated || (this->GetLocation() & vtkPVSession::RENDER_SERVER) == 0)
  {
    return;
  }
  // Only when a statistic is asked for (all properties, or one of them).
  bool wanted = prop == nullptr;
  for (int i = 0; !wanted && i < vtkSpaceSkipStatisticsInformation::NumberCount; ++i)
  {
    wanted = prop == this->GetProperty(vtkSpaceSkipStatisticsInformation::GetNumberName(i));
  }
  for (int i = 0; !wanted && i < vtkSpaceSkipStatisticsInformation::TextCount; ++i)
  {
    wanted = prop == this->GetProperty(vtkSpaceSkipStatisticsInformation::GetTextName(i));
  }
  if (!wanted)
  {
    return;
  }
  vtkNew<vtkSpaceSkipStatisticsInformation> info;
  // Not the return value: vtkSMSessionClient::GatherInformation returns false even when the
  // server answered; Valid says whether a representation was read.
  this->GatherInformation(info, vtkPVSession::RENDER_SERVER);
  if (!info->GetValid())
  {
    return;
  }
  for (int i = 0; i < vtkSpaceSkipStatisticsInformation::NumberCount; ++i)
  {
    if (this->GetProperty(vtkSpaceSkipStatisticsInformation::GetNumberName(i)))
    {
      vtkSMPropertyHelper(this, vtkSpaceSkipStatisticsInformation::GetNumberName(i))
        .Set(info->GetNumber(i));
    }
  }
  for (int i = 0; i < vtkSpaceSkipStatisticsInformation::TextCount; ++i)
  {
    if (this->GetProperty(vtkSpaceSkipStatisticsInformation::GetTextName(i)))
    {
      vtkSMPropertyHelper(this, vtkSpaceSkipStatisticsInformation::GetTextName(i))
        .Set(info->GetText(i));
    }
  }
}

//------------------------------------------------------------------------------
void vtkSMSpaceSkipRepresentationProxy::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
