// vtkSpaceSkipImageRenderer: one vtkImageData drawn by a spaceskip::Engine into the window (what
// vtkVolumeInputHelper is to vtkOpenGLGPUVolumeRayCastMapper: the per-input state kept out of the
// mapper). Takes the mapper's settings as values; owns the engine, the input converter, the
// property translator and the compositor, and the statistics of the last frame.
// Internal to the module (not wrapped, not installed).
#ifndef vtkSpaceSkipImageRenderer_h
#define vtkSpaceSkipImageRenderer_h

#include "vtkSpaceSkipCompositor.h"         // For the compositor
#include "vtkSpaceSkipInputConverter.h"     // For the input converter
#include "vtkSpaceSkipPropertyTranslator.h" // For the property translator
#include "vtkSpaceSkipStatistics.h"         // For the statistics

#include "spaceskip/Engine.h" // For the engine, Image, VolumePiece

#include <functional> // For the callbacks
#include <memory>     // For the engine
#include <string>     // For the messages

class vtkDataArray;
class vtkImageData;
class vtkOpenGLCamera;
class vtkOpenGLRenderWindow;
class vtkRenderer;
class vtkVolume;
class vtkWindow;
struct vtkSpaceSkipSettings;

class vtkSpaceSkipImageRenderer
{
public:
  using MessageFunction = std::function<void(const std::string&)>;
  using ProgressFunction = std::function<void(double, const char*)>;

  /// `warnOnce`: warnings, once per cause; `fail`: why nothing was drawn (the mapper's error);
  /// `progress`: the engine's steps (Engine::setProgress).
  vtkSpaceSkipImageRenderer(MessageFunction warnOnce, MessageFunction fail, ProgressFunction progress);

  /// How this frame is drawn besides the settings: a block of composite input or a piece for
  /// the exchange keeps its float image (Defer), with the table range of all blocks, its own
  /// cells on the whole lattice (Owned, else its ghost array) and the incoming opacity.
  struct FrameMode
  {
    const double* TableRange = nullptr; // null: WholeScalarRange or the input's
    const int* Owned = nullptr;
    bool Defer = false;
    bool Exact = false; // no 8-bit rounding bias (composited in float)
    bool OnDevice = false; // a deferred CUDA frame stays in device memory (DeferredDeviceImage)
    const float* IncomingAlpha = nullptr;
    vtkDataArray* Prefetch = nullptr; // the next time step's scalars (PrefetchTimeStep)
  };

  /**
   * Draws `input` (`scalars`: vtkAbstractMapper::GetScalars of it): the engine is (re)made for
   * the settings' backend, only what changed reaches it, the frame is rendered and, unless
   * deferred, blended into the window. True when it drew (or kept) a frame; false after saying
   * why through `fail` or `warnOnce`.
   */
  bool Render(vtkRenderer* ren, vtkVolume* vol, vtkOpenGLRenderWindow* renWin, vtkOpenGLCamera* cam,
    vtkImageData* input, vtkDataArray* scalars, int cellFlag, const vtkSpaceSkipSettings& settings,
    const FrameMode& mode);

  /// The last deferred frame's premultiplied RGBA floats (row 0 at the bottom), or null.
  const float* DeferredImage(int& width, int& height) const;
  /// The last deferred frame left in device memory (FrameMode::OnDevice, the CUDA backend):
  /// `width` x `height` float4, premultiplied RGBA, row 0 at the bottom, written on `stream` (a
  /// cudaStream_t), valid until the next frame; or null (it went to host memory).
  const void* DeferredDeviceImage(int& width, int& height, void*& stream) const;
  /// The last frame (the window's copy when it was drawn through host memory).
  const spaceskip::Image& GetImage() const { return this->Image; }
  /// The piece the last frame drew (inactive: the whole input).
  const spaceskip::VolumePiece& LastPiece() const { return this->Piece; }
  /// The statistics of the last frame; `deviceTimes`: with its render and kernel times (with
  /// the image kept on the GPU, asking waits for the frame).
  vtkSpaceSkipStatistics Statistics(bool deviceTimes) const;
  /// Starts the mapper's Render(): the last frame's times are reset.
  void ResetFrameTimes();
  void SetMapperSeconds(double seconds) { this->Frame.MapperSeconds = seconds; }

  void SetTuning(const spaceskip::Tuning& tuning);
  /// SPACESKIP_REPORT: print what ran whenever it changes.
  void SetReport(bool report) { this->Report = report; }
  vtkSpaceSkipCompositor& GetCompositor() { return this->Compositor; }
  void ReleaseGraphicsResources(vtkWindow* win) { this->Compositor.ReleaseGraphicsResources(win); }
  /// The next Render's input is a rectilinear grid's points drawn through its coordinates
  /// (vtkSpaceSkipRectilinearImage path 4), or an image (nullptr).
  void SetWarp(std::shared_ptr<const spaceskip::AxisWarp> warp) { this->Input.SetWarp(std::move(warp)); }

private:
  bool UpdateEngine(int backend);
  class WindowState;
  void RenderFrame(vtkOpenGLRenderWindow* renWin, WindowState& window, bool sceneHasDepth,
    const spaceskip::Camera& camera,
    int x0, int y0, int width, int height, const vtkSpaceSkipSettings& s, const FrameMode& mode);
  bool Composite(vtkOpenGLRenderWindow* renWin, vtkImageData* input,
    const spaceskip::Camera& camera, int width, int height, bool eightBit);
  void ReportPaths();
  spaceskip::Counters Counts() const;

  // Call-outs to the application so far (messages, progress): see WindowState.
  unsigned long Callouts = 0;
  MessageFunction Warn;
  MessageFunction Fail;
  ProgressFunction Progress;
  // Before the engine, so that it goes after it: the arrays it holds (the volume the engine
  // borrows, a time step whose copy the engine may still be making) outlive the engine's use.
  vtkSpaceSkipInputConverter Input;
  std::unique_ptr<spaceskip::Engine> Engine;
  int EngineBackend = -1;
  spaceskip::Counters CountOffset; // stages run by engines replaced after a backend change
  spaceskip::Tuning Tuning;
  vtkSpaceSkipPropertyTranslator Properties;
  vtkSpaceSkipStatistics Frame; // the last frame's times and what ran
  spaceskip::Image Image;
  bool Deferred = false;                 // Image holds the last deferred frame
  spaceskip::VolumePiece Piece;
  const float* FrameDepth = nullptr; // this frame's depth (the compositor's buffer), or null
  // SPACESKIP_REPORT: one stdout line whenever backend, builder or composite path change.
  bool Report = false;
  std::string Reported;
  // Last, so that it goes (with its CUDA-GL interop registration) before the engine.
  vtkSpaceSkipCompositor Compositor;
};

#endif
