// The server-manager proxy of "Space Skipping Volume": its statistics come from the render server.
#include "vtkSMSpaceSkipRepresentationProxy.h"

#include "vtkCommand.h"
#include "vtkDataObject.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPVSession.h"
#include "vtkPVXMLElement.h"
#include "vtkSMArrayListDomain.h"
#include "vtkSMPVRepresentationProxy.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyGroup.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMSessionProxyManager.h"
#include "vtkSpaceSkipStatisticsInformation.h"

#include <cstring>

vtkStandardNewMacro(vtkSMSpaceSkipRepresentationProxy);

//------------------------------------------------------------------------------
vtkSMSpaceSkipRepresentationProxy::vtkSMSpaceSkipRepresentationProxy() = default;

//------------------------------------------------------------------------------
vtkSMSpaceSkipRepresentationProxy::~vtkSMSpaceSkipRepresentationProxy()
{
  if (this->RepresentationProperty && this->RepresentationObserver)
  {
    this->RepresentationProperty->RemoveObserver(this->RepresentationObserver);
  }
  if (this->ObservedView && this->RenderObserver)
  {
    this->ObservedView->RemoveObserver(this->RenderObserver);
  }
}

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
namespace
{
constexpr const char* kRepresentationName = "Space Skipping Volume";

bool IsRepresentationDecorator(vtkPVXMLElement* e, const char* value)
{
  const char* name = e->GetName();
  const char* type = e->GetAttribute("type");
  const char* property = e->GetAttribute("property");
  const char* v = e->GetAttribute("value");
  return name && strcmp(name, "PropertyWidgetDecorator") == 0 && type &&
    strcmp(type, "GenericDecorator") == 0 && property && strcmp(property, "Representation") == 0 &&
    v && strcmp(v, value) == 0;
}

// In `element` and below: every <Expression type="or"> that lists Representation == "Volume" gets
// Representation == "Space Skipping Volume" beside it, unless it has it already. Returns how
// many such expressions there are.
int AddRepresentationToOr(vtkPVXMLElement* element)
{
  int found = 0;
  const unsigned int n = element->GetNumberOfNestedElements();
  for (unsigned int i = 0; i < n; ++i)
  {
    found += AddRepresentationToOr(element->GetNestedElement(i));
  }
  const char* name = element->GetName();
  const char* type = element->GetAttribute("type");
  if (!name || strcmp(name, "Expression") != 0 || !type || strcmp(type, "or") != 0)
  {
    return found;
  }
  bool volume = false, ours = false;
  for (unsigned int i = 0; i < n; ++i)
  {
    volume = volume || IsRepresentationDecorator(element->GetNestedElement(i), "Volume");
    ours = ours || IsRepresentationDecorator(element->GetNestedElement(i), kRepresentationName);
  }
  if (volume && !ours)
  {
    vtkNew<vtkPVXMLElement> decorator;
    decorator->SetName("PropertyWidgetDecorator");
    decorator->AddAttribute("type", "GenericDecorator");
    decorator->AddAttribute("mode", "visibility");
    decorator->AddAttribute("property", "Representation");
    decorator->AddAttribute("value", kRepresentationName);
    element->AddNestedElement(decorator);
  }
  return found + (volume ? 1 : 0);
}
}

//------------------------------------------------------------------------------
void vtkSMSpaceSkipRepresentationProxy::CreateVTKObjects()
{
  const bool wasCreated = this->ObjectsCreated != 0;
  this->Superclass::CreateVTKObjects();
  vtkSMProxy* display = this->GetParentProxy();
  if (wasCreated || !this->ObjectsCreated || !display)
  {
    return;
  }
  if (vtkSMProperty* representation = display->GetProperty("Representation"))
  {
    this->RepresentationProperty = representation;
    this->RepresentationObserver = representation->AddObserver(
      vtkCommand::ModifiedEvent, this, &vtkSMSpaceSkipRepresentationProxy::OnRepresentationModified);
  }
  for (size_t i = 0; i < display->GetNumberOfPropertyGroups(); ++i)
  {
    vtkSMPropertyGroup* group = display->GetPropertyGroup(i);
    const char* label = group ? group->GetXMLLabel() : nullptr;
    if (label && group->GetHints() &&
      (strcmp(label, "Volume Rendering") == 0 || strcmp(label, "Cropping Parameters") == 0))
    {
      AddRepresentationToOr(group->GetHints());
    }
  }
}

//------------------------------------------------------------------------------
void vtkSMSpaceSkipRepresentationProxy::OnRepresentationModified()
{
  auto* display = vtkSMPVRepresentationProxy::SafeDownCast(this->GetParentProxy());
  if (!display || this->PickingColorArray || !this->RepresentationProperty)
  {
    return;
  }
  const char* type = vtkSMPropertyHelper(this->RepresentationProperty).GetAsString();
  if (!type || strcmp(type, kRepresentationName) != 0 || display->GetUsingScalarColoring())
  {
    return;
  }
  vtkSMSessionProxyManager* pxm = display->GetSessionProxyManager();
  if (pxm && pxm->GetInLoadXMLState())
  {
    return;
  }
  vtkSMProperty* colorArrayName = display->GetProperty("ColorArrayName");
  auto* arrays = colorArrayName ? colorArrayName->FindDomain<vtkSMArrayListDomain>() : nullptr;
  if (!arrays || arrays->GetNumberOfStrings() == 0)
  {
    return;
  }
  unsigned int index = 0;
  for (unsigned int i = 0; i < arrays->GetNumberOfStrings(); ++i)
  {
    if (arrays->GetFieldAssociation(i) == vtkDataObject::POINT)
    {
      index = i;
      break;
    }
  }
  this->PickingColorArray = true;
  if (display->SetScalarColoring(arrays->GetString(index), arrays->GetFieldAssociation(index)))
  {
    display->RescaleTransferFunctionToDataRange(true);
  }
  this->PickingColorArray = false;
}

//------------------------------------------------------------------------------
void vtkSMSpaceSkipRepresentationProxy::ViewUpdated(vtkSMProxy* view)
{
  this->Superclass::ViewUpdated(view);
  if (!view || view == this->ObservedView)
  {
    return;
  }
  if (this->ObservedView && this->RenderObserver)
  {
    this->ObservedView->RemoveObserver(this->RenderObserver);
  }
  this->ObservedView = view;
  this->RenderObserver =
    view->AddObserver(vtkCommand::EndEvent, this, &vtkSMSpaceSkipRepresentationProxy::OnRenderEnd);
}

//------------------------------------------------------------------------------
void vtkSMSpaceSkipRepresentationProxy::OnRenderEnd(vtkObject*, unsigned long, void* calldata)
{
  // vtkSMViewProxy: calldata points to 0 after StillRender, 1 after InteractiveRender. Only
  // still renders (a gather from the render server each), and only while this one is shown.
  const int interactive = calldata ? *static_cast<int*>(calldata) : 0;
  vtkSMProxy* display = this->GetParentProxy();
  if (interactive || !this->ObjectsCreated || !display || !this->RepresentationProperty)
  {
    return;
  }
  const char* type = vtkSMPropertyHelper(this->RepresentationProperty).GetAsString();
  if (!type || strcmp(type, kRepresentationName) != 0 ||
    !vtkSMPropertyHelper(display, "Visibility").GetAsInt())
  {
    return;
  }
  this->UpdatePropertyInformation();
}

//------------------------------------------------------------------------------
void vtkSMSpaceSkipRepresentationProxy::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
