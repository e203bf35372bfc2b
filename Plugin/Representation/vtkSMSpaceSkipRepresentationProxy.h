// The server-manager proxy of "Space Skipping Volume": its statistics come from the render server.
/**
 * @class vtkSMSpaceSkipRepresentationProxy
 * @brief vtkSMRepresentationProxy whose statistics properties read the representation that
 * renders.
 *
 * ParaView pulls information properties (vtkSMProxy::UpdatePropertyInformation ->
 * vtkSMSessionClient::PullState) from one location, the client first when the proxy exists
 * there; the client's representation never renders a volume in client/server mode, so its
 * statistics stay "none"/0. After the usual pull, this proxy gathers a
 * vtkSpaceSkipStatisticsInformation from the render server (rank 0) and sets the statistics
 * properties from it. In the built-in session (GUI, pvpython, pvbatch) the render server is the
 * same process and the values are the ones the pull read.
 * It also lets the Properties panel show the stock volume groups for this representation (see
 * CreateVTKObjects).
 * Created for the XML element `<SpaceSkipRepresentationProxy>` (SpaceSkipRepresentation.xml).
 */
#ifndef vtkSMSpaceSkipRepresentationProxy_h
#define vtkSMSpaceSkipRepresentationProxy_h

#include "vtkSMRepresentationProxy.h"
#include "vtkSpaceSkipRepresentationModule.h" // for export macro
#include "vtkWeakPointer.h"                   // for vtkWeakPointer

class VTKSPACESKIPREPRESENTATION_EXPORT vtkSMSpaceSkipRepresentationProxy
  : public vtkSMRepresentationProxy
{
public:
  static vtkSMSpaceSkipRepresentationProxy* New();
  vtkTypeMacro(vtkSMSpaceSkipRepresentationProxy, vtkSMRepresentationProxy);
  void PrintSelf(ostream& os, vtkIndent indent) override;

protected:
  vtkSMSpaceSkipRepresentationProxy();
  ~vtkSMSpaceSkipRepresentationProxy() override;

  /// The usual pull, then the statistics from the render server.
  void UpdatePropertyInformationInternal(vtkSMProperty* prop = nullptr) override;

  /// ParaView 5.11's Properties panel shows the image-data display's stock "Volume Rendering"
  /// and "Cropping Parameters" groups (Blend Mode, Slice Type, Shade, Use Cropping...) only while
  /// Representation is "Volume" or "NVIDIA IndeX": an `or` of GenericDecorators in ParaView's own
  /// XML, which a plugin's XML cannot extend. Those properties are shared with this
  /// representation, so after the usual creation "Space Skipping Volume" is added to that `or`
  /// in the parent display's group hints (once: the hints belong to the shared definition).
  void CreateVTKObjects() override;

  /// After the view updated: follows that view's still renders (see OnRenderEnd).
  void ViewUpdated(vtkSMProxy* view) override;

  /// A colour array when the display switches to "Space Skipping Volume" without one, picked
  /// as vtkSMPVRepresentationProxy::SetRepresentationType does for ParaView's own "Volume" (the
  /// first point array, else the first array; its transfer functions rescaled to the data
  /// range), so the volume draws at once. Not while a state file loads (it sets its own).
  void OnRepresentationModified();

  /// After a still render of the view: the statistics properties read again, so the Properties
  /// panel shows the frame just drawn (ParaView pulls information properties only on request).
  void OnRenderEnd(vtkObject* caller, unsigned long event, void* calldata);

private:
  vtkWeakPointer<vtkSMProperty> RepresentationProperty;
  unsigned long RepresentationObserver = 0;
  vtkWeakPointer<vtkSMProxy> ObservedView;
  unsigned long RenderObserver = 0;
  bool PickingColorArray = false;


  vtkSMSpaceSkipRepresentationProxy(const vtkSMSpaceSkipRepresentationProxy&) = delete;
  void operator=(const vtkSMSpaceSkipRepresentationProxy&) = delete;
};

#endif
