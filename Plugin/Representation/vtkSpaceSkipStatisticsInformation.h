// The statistics of a vtkSpaceSkipVolumeRepresentation, gathered where it renders.
/**
 * @class vtkSpaceSkipStatisticsInformation
 * @brief vtkPVInformation carrying the "Space Skipping Statistics" of the render server.
 *
 * In client/server the client's copy of the representation never renders (ParaView renders
 * volumes on the server), and vtkSMSessionClient::PullState reads information properties from
 * the client when the proxy lives there too. vtkSMSpaceSkipRepresentationProxy therefore gathers
 * this object from the render server (vtkSMProxy::GatherInformation, RENDER_SERVER) and copies
 * it into the statistics properties. RootOnly: rank 0's numbers, as the built-in session and
 * pvbatch report them.
 */
#ifndef vtkSpaceSkipStatisticsInformation_h
#define vtkSpaceSkipStatisticsInformation_h

#include "vtkPVInformation.h"
#include "vtkSpaceSkipRepresentationModule.h" // for export macro

#include <array>  // for the values
#include <string> // for the names

class VTKSPACESKIPREPRESENTATION_EXPORT vtkSpaceSkipStatisticsInformation : public vtkPVInformation
{
public:
  static vtkSpaceSkipStatisticsInformation* New();
  vtkTypeMacro(vtkSpaceSkipStatisticsInformation, vtkPVInformation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Reads the statistics of a vtkSpaceSkipVolumeRepresentation (anything else: none).
  void CopyFromObject(vtkObject* object) override;
  /// Keeps the first process's statistics that has drawn frames.
  void AddInformation(vtkPVInformation* other) override;
  void CopyToStream(vtkClientServerStream* stream) override;
  void CopyFromStream(const vtkClientServerStream* stream) override;

  /// Numeric statistics, by the names of their properties (NumberNames).
  static constexpr int NumberCount = 13;
  static const char* GetNumberName(int i);
  double GetNumber(int i) const { return this->Numbers[i]; }
  /// String statistics, by the names of their properties.
  static constexpr int TextCount = 7;
  static const char* GetTextName(int i);
  const char* GetText(int i) const { return this->Texts[i].c_str(); }
  /// Whether a vtkSpaceSkipVolumeRepresentation was read.
  vtkGetMacro(Valid, bool);

protected:
  vtkSpaceSkipStatisticsInformation();
  ~vtkSpaceSkipStatisticsInformation() override;

  bool Valid = false;
  std::array<double, NumberCount> Numbers{};
  std::array<std::string, TextCount> Texts;

private:
  vtkSpaceSkipStatisticsInformation(const vtkSpaceSkipStatisticsInformation&) = delete;
  void operator=(const vtkSpaceSkipStatisticsInformation&) = delete;
};

#endif
