// vtkSpaceSkipPropertyTranslator: vtkVolumeProperty, the mapper's settings (vtkSpaceSkipSettings,
// values), the renderer's lights and camera -> Core's TransferFunction, BuildParams, RenderParams and Camera.
// Internal to the module (not wrapped, not installed).
#ifndef vtkSpaceSkipPropertyTranslator_h
#define vtkSpaceSkipPropertyTranslator_h

#include "vtkType.h" // For vtkMTimeType

#include <functional> // For WarnFunction
#include <map>        // For vtkSpaceSkipLabelEdits
#include <string>     // For the warning texts
#include <vector>     // For the sampled tables

class vtkImageData;
class vtkOpenGLCamera;
class vtkPiecewiseFunction;
class vtkRenderer;
class vtkVolume;
class vtkVolumeProperty;
struct vtkSpaceSkipSettings;
namespace spaceskip
{
class Engine;
struct BuildParams;
struct Camera;
struct RenderParams;
}

/// A label map's mapper-level settings for one label id (vtkSpaceSkippingVolumeMapper's
/// SetLabelColor, SetLabelOpacity, SetLabelVisibility): what was set overrides what the volume
/// property gives that label.
struct vtkSpaceSkipLabelEdit
{
  double Color[3] = { 1, 1, 1 };
  double Opacity = 1;
  bool Visible = true;
  bool HasColor = false, HasOpacity = false, HasVisible = false;
  bool operator==(const vtkSpaceSkipLabelEdit& o) const
  {
    return Color[0] == o.Color[0] && Color[1] == o.Color[1] && Color[2] == o.Color[2] &&
      Opacity == o.Opacity && Visible == o.Visible && HasColor == o.HasColor &&
      HasOpacity == o.HasOpacity && HasVisible == o.HasVisible;
  }
};
using vtkSpaceSkipLabelEdits = std::map<int, vtkSpaceSkipLabelEdit>;

class vtkSpaceSkipPropertyTranslator
{
public:
  using WarnFunction = std::function<void(const std::string&)>;

  /**
   * Resamples the property's colour and scalar-opacity functions over `scalarRange` into the
   * engine's table, each only when it (its object, MTime or range) changed, and tells the engine
   * which part may differ, so that it compares only that part with its table (a colour edit
   * compares no opacity, an opacity edit no colour; another change of the property, e.g. its
   * shading, does nothing here). Dependent components: the opacity function over `opacityRange`
   * instead, with component `opacityComponent`'s unit distance
   * (vtkVolumeInputHelper::UpdateOpacityTransferFunction). One-component volumes also get the
   * property's 2-D transfer function (TF_2D mode) or its gradient opacity (1-D mode, unless
   * disabled), as vtkGPUVolumeRayCastMapper reads them; an edit of either re-classifies.
   * `secondAxis`: the volume's two components are the 2-D table's x and y values (a second
   * array as its y axis, over `opacityRange`), so the 2-D table is given with them.
   */
  void UpdateTransferFunction(spaceskip::Engine& engine, vtkVolumeProperty* prop,
    const double scalarRange[2], const double* opacityRange = nullptr, int opacityComponent = 0,
    bool secondAxis = false);

  /// The property's 2-D transfer function when vtkGPUVolumeRayCastMapper would use it: TF_2D
  /// mode and an image of 4-component scalars, one slice deep (ParaView's
  /// vtkPVTransferFunction2D); else nullptr.
  static vtkImageData* Usable2D(vtkVolumeProperty* prop);

  /// The accumulated opacity at which `settings` stop a ray (early ray termination: 1 - 1/255,
  /// vtkGPUVolumeRayCastMapper's threshold); above 1 when rays never stop early.
  static double EarlyTerminationOpacity(const vtkSpaceSkipSettings& settings);

  /**
   * Gives the engine the build parameters and the render parameters of `settings` (its
   * effective blend mode, iso values, shading and lights, cropping, clipping planes, jitter, early ray
   * termination, the slice plane). What it lacks or cuts (nearest interpolation, more than
   * spaceskip::kMaxLights lights, a slice function that is not a vtkPlane) is said once each
   * through `warnOnce`.
   */
  void UpdateParameters(spaceskip::Engine& engine, const vtkSpaceSkipSettings& settings,
    vtkRenderer* ren, vtkVolume* vol, const double scalarRange[2], const WarnFunction& warnOnce);

  /**
   * Label map (vtkSpaceSkippingVolumeMapper::LabelMap): the labels are the ids of `edits` and,
   * when the property's colour function has IndexedLookup on, its annotated values (ParaView's
   * categorical colour map); with neither, every integer of `scalarRange`. A label's colour is
   * its indexed colour (IndexedLookup) or the colour function at its id, its opacity the scalar
   * opacity function at its id, visible; `edits` override each part they set. Values without a
   * label are transparent. Sets RenderParams::labelMap and labelSampling too.
   */
  static void UpdateLabels(spaceskip::Engine& engine, bool labelMap, int labelSampling,
    const vtkSpaceSkipLabelEdits& edits, vtkVolumeProperty* prop, const double scalarRange[2]);

  /**
   * The engine's camera: the volume's matrix is folded into the view, so the engine marches in
   * the image's physical space and the projected depth matches what OpenGL drew.
   */
  static spaceskip::Camera ToCamera(vtkRenderer* ren, vtkOpenGLCamera* cam, vtkVolume* vol);

  /// Forgets the table the engine was given (a new engine): the next update resamples it.
  void Reset();

  /// How often the colour (opacity) function was sampled into the table: on its own edits only.
  int GetColorTableSamples() const { return this->ColorSamples; }
  int GetOpacityTableSamples() const { return this->OpacitySamples; }

private:
  void SetBlendAndShading(spaceskip::RenderParams& rp, const vtkSpaceSkipSettings& settings,
    vtkRenderer* ren, vtkVolume* vol, const double scalarRange[2],
    const WarnFunction& warnOnce);
  void SetSlicePlane(spaceskip::RenderParams& rp, const vtkSpaceSkipSettings& settings,
    vtkVolume* vol, const WarnFunction& warnOnce);

  // What the engine was last given; compared by identity and MTime to redo only what changed.
  // The colour part: its function, the range it was sampled over, grey or RGB; the opacity part:
  // its function, range, component and unit distance. Each part's samples are kept.
  const void* ColorKey = nullptr;
  const void* OpacityKey = nullptr;
  vtkMTimeType ColorMTime = 0;
  vtkMTimeType OpacityMTime = 0;
  double TableRange[2] = { 0, 0 };
  bool Gray = false;
  double OpacityTableRange[2] = { 0, 0 }; // dependent components; {0, 0}: none
  double OpacitySampleRange[2] = { 0, 0 };
  int OpacityComponent = 0;
  double UnitDistance = 1;
  bool HaveTF = false;
  std::vector<float> RGB, Alpha;
  // The 2-D table (RGBA per entry, Width2D x Height2D) or the gradient-opacity table, with the
  // function, MTime and scalar range they were read with.
  const vtkImageData* Table2DKey = nullptr;
  vtkMTimeType Table2DMTime = 0;
  std::vector<float> Table2D;
  int Width2D = 0, Height2D = 0;
  const vtkPiecewiseFunction* GradientKey = nullptr;
  vtkMTimeType GradientMTime = 0;
  double GradientRange[2] = { 0, 0 };
  std::vector<float> GradientOpacity;
  int ColorSamples = 0, OpacitySamples = 0;

  // Unsupported features already said (the lights say their first cause only).
  bool WarnedNearest = false;
  bool WarnedBlend = false;
  bool Warned2D = false;
  bool WarnedLight = false;
  bool WarnedSlice = false;
};

#endif
