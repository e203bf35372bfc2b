// vtkSpaceSkipPropertyTranslator: vtkVolumeProperty, the mapper's settings, the renderer's
// lights and camera -> Core's TransferFunction, BuildParams, RenderParams and Camera.
// Internal to the module (not wrapped, not installed).
#ifndef vtkSpaceSkipPropertyTranslator_h
#define vtkSpaceSkipPropertyTranslator_h

#include "vtkType.h" // For vtkMTimeType

#include <functional> // For WarnFunction
#include <string>     // For the warning texts

class vtkOpenGLCamera;
class vtkRenderer;
class vtkSpaceSkippingVolumeMapper;
class vtkVolume;
class vtkVolumeProperty;
namespace spaceskip
{
class Engine;
struct BuildParams;
struct Camera;
struct RenderParams;
}

class vtkSpaceSkipPropertyTranslator
{
public:
  using WarnFunction = std::function<void(const std::string&)>;

  /**
   * Resamples the property's colour and scalar-opacity functions over `scalarRange` into the
   * engine's table, only when the property, one of its functions or the range changed (the
   * engine itself tells a colour-only edit from an opacity edit). Dependent components: the
   * opacity function over `opacityRange` instead, with component `opacityComponent`'s unit
   * distance (vtkVolumeInputHelper::UpdateOpacityTransferFunction).
   */
  void UpdateTransferFunction(spaceskip::Engine& engine, vtkVolumeProperty* prop,
    const double scalarRange[2], const double* opacityRange = nullptr, int opacityComponent = 0);

  /**
   * Gives the engine the mapper's build parameters and its render parameters (blend mode
   * `blendMode`, iso values, shading and lights, cropping, clipping planes, jitter, early ray
   * termination, the slice plane). What it lacks or cuts (nearest interpolation, more than
   * spaceskip::kMaxLights lights, a slice function that is not a vtkPlane) is said once each
   * through `warnOnce`.
   */
  void UpdateParameters(spaceskip::Engine& engine, vtkSpaceSkippingVolumeMapper* mapper,
    int blendMode, vtkRenderer* ren, vtkVolume* vol, const double scalarRange[2],
    const WarnFunction& warnOnce);

  /**
   * The engine's camera: the volume's matrix is folded into the view, so the engine marches in
   * the image's physical space and the projected depth matches what OpenGL drew.
   */
  static spaceskip::Camera ToCamera(vtkRenderer* ren, vtkOpenGLCamera* cam, vtkVolume* vol);

  /// Forgets the table the engine was given (a new engine): the next update resamples it.
  void Reset();

private:
  void SetBlendAndShading(spaceskip::RenderParams& rp, vtkSpaceSkippingVolumeMapper* mapper,
    int mode, vtkRenderer* ren, vtkVolume* vol, const double scalarRange[2],
    const WarnFunction& warnOnce);
  void SetSlicePlane(spaceskip::RenderParams& rp, vtkSpaceSkippingVolumeMapper* mapper,
    vtkVolume* vol, const WarnFunction& warnOnce);

  // What the engine was last given; compared by identity and MTime to redo only what changed.
  const void* PropertyKey = nullptr;
  const void* ColorKey = nullptr;
  const void* OpacityKey = nullptr;
  vtkMTimeType PropertyMTime = 0;
  vtkMTimeType ColorMTime = 0;
  vtkMTimeType OpacityMTime = 0;
  double TableRange[2] = { 0, 0 };
  double OpacityTableRange[2] = { 0, 0 }; // dependent components; {0, 0}: none
  int OpacityComponent = 0;
  bool HaveTF = false;

  // Unsupported features already said (the lights say their first cause only).
  bool WarnedNearest = false;
  bool WarnedBlend = false;
  bool WarnedLight = false;
  bool WarnedSlice = false;
};

#endif
