// vtkSpaceSkipImageRenderer: one vtkImageData through the engine into the window.
#include "vtkSpaceSkipImageRenderer.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkLogger.h"
#include "vtkOpenGLCamera.h"
#include "vtkPointData.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkipOpenGL.h"
#include "vtkSpaceSkipSettings.h"
#include "vtkVolume.h"
#include "vtkVolumeMapper.h"
#include "vtkVolumeProperty.h"

#include "spaceskip/Backend.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <vector>

namespace
{
double SecondsSince(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
// vtkSpaceSkippingVolumeMapper::BackendTypes.
constexpr int kBackendCPU = 1;
constexpr int kBackendCUDA = 2;
}

//------------------------------------------------------------------------------
// Every message and progress step calls out to the application, which may run its event loop
// there (ParaView's progress bar: Qt paints its widgets): counted, so that the frame puts the
// window's GL state back before it touches the framebuffer again (WindowState).
vtkSpaceSkipImageRenderer::vtkSpaceSkipImageRenderer(
  MessageFunction warnOnce, MessageFunction fail, ProgressFunction progress)
  : Warn([this, f = std::move(warnOnce)](const std::string& m) {
    ++this->Callouts;
    f(m);
  })
  , Fail([this, f = std::move(fail)](const std::string& m) {
    ++this->Callouts;
    f(m);
  })
  , Progress([this, f = std::move(progress)](double fraction, const char* step) {
    ++this->Callouts;
    if (f)
    {
      f(fraction, step);
    }
  })
{
}

//------------------------------------------------------------------------------
// The window's GL state as VTK's state cache had it when the frame began: the framebuffer
// bindings, viewport, scissor box, blending, depth and colour masks, clear colour, active
// texture unit. Restore() puts it back after call-outs: an application that painted in this
// context (Qt's QOpenGLWidget) or made another one current left GL out of step with the cache,
// and the frame would draw into its framebuffer, or nowhere (a view without the volume).
class vtkSpaceSkipImageRenderer::WindowState
{
public:
  WindowState(vtkOpenGLRenderWindow* w, const unsigned long& callouts)
    : Window(w)
    , Callouts(callouts)
    , Seen(callouts)
  {
    this->Capture();
  }
  ~WindowState()
  {
    this->Restore();
    this->Release();
  }
  WindowState(const WindowState&) = delete;
  WindowState& operator=(const WindowState&) = delete;

  /// After call-outs (none: nothing to do): the window's context current again, the cache read
  /// back from GL, then the captured state applied through it.
  void Restore()
  {
    if (this->Callouts == this->Seen || !this->Window)
    {
      return;
    }
    this->Seen = this->Callouts;
    this->Window->MakeCurrent();
    vtkOpenGLState* ostate = this->Window->GetState();
    ostate->Reset();
    // The shader cache's current program may no longer be the bound one: bind on next use.
    this->Window->GetShaderCache()->ReleaseCurrentShader();
    this->Release();
    this->Capture();
  }

private:
  void Capture()
  {
    vtkOpenGLState* s = this->Window ? this->Window->GetState() : nullptr;
    if (!s)
    {
      return;
    }
    s->PushFramebufferBindings();
    this->Pushed = true;
    this->Savers.emplace_back(new Saver<vtkOpenGLState::ScopedglViewport>(s));
    this->Savers.emplace_back(new Saver<vtkOpenGLState::ScopedglScissor>(s));
    this->Savers.emplace_back(new Saver<vtkOpenGLState::ScopedglBlendFuncSeparate>(s));
    this->Savers.emplace_back(new Saver<vtkOpenGLState::ScopedglDepthMask>(s));
    this->Savers.emplace_back(new Saver<vtkOpenGLState::ScopedglDepthFunc>(s));
    this->Savers.emplace_back(new Saver<vtkOpenGLState::ScopedglColorMask>(s));
    this->Savers.emplace_back(new Saver<vtkOpenGLState::ScopedglClearColor>(s));
    this->Savers.emplace_back(new Saver<vtkOpenGLState::ScopedglActiveTexture>(s));
    for (unsigned int cap : { GL_BLEND, GL_DEPTH_TEST, GL_SCISSOR_TEST, GL_CULL_FACE, GL_STENCIL_TEST })
    {
      this->Savers.emplace_back(new EnableSaver(s, cap));
    }
  }
  // Applies the captured state: each saver sets its value back (through the cache) as it goes,
  // in reverse order of capture as nested scopes would; the framebuffer bindings last.
  void Release()
  {
    while (!this->Savers.empty())
    {
      this->Savers.pop_back();
    }
    if (this->Pushed)
    {
      this->Window->GetState()->PopFramebufferBindings();
      this->Pushed = false;
    }
  }

  struct AnySaver
  {
    virtual ~AnySaver() = default;
  };
  template <class T>
  struct Saver : AnySaver
  {
    explicit Saver(vtkOpenGLState* s)
      : Value(s)
    {
    }
    T Value;
  };
  struct EnableSaver : AnySaver
  {
    EnableSaver(vtkOpenGLState* s, unsigned int cap)
      : Value(s, cap)
    {
    }
    vtkOpenGLState::ScopedglEnableDisable Value;
  };

  vtkOpenGLRenderWindow* Window;
  const unsigned long& Callouts;
  unsigned long Seen;
  bool Pushed = false;
  std::vector<std::unique_ptr<AnySaver>> Savers;
};

//------------------------------------------------------------------------------
spaceskip::Counters vtkSpaceSkipImageRenderer::Counts() const
{
  spaceskip::Counters c = this->CountOffset;
  if (this->Engine)
  {
    const spaceskip::Counters& e = this->Engine->counters();
    c.rangeGrids += e.rangeGrids;
    c.classifications += e.classifications;
    c.builds += e.builds;
    c.colorUpdates += e.colorUpdates;
    c.frames += e.frames;
    c.colorCompares += e.colorCompares;
    c.opacityCompares += e.opacityCompares;
    c.timeSteps += e.timeSteps;
    c.prefetchedSteps += e.prefetchedSteps;
  }
  return c;
}

//------------------------------------------------------------------------------
// (Re)creates the engine when the backend changes (counts are carried over); false (said) when
// it cannot be created.
bool vtkSpaceSkipImageRenderer::UpdateEngine(int backend)
{
  if (this->Engine && this->EngineBackend == backend)
  {
    return true;
  }
  this->CountOffset = this->Counts();
  this->Engine.reset();
  try
  {
    // Auto, not CUDA: a missing device is said below in the mapper's words (Engine(CUDA)
    // would say it in the engine's); Auto makes the same choice silently.
    const spaceskip::BackendKind kind =
      backend == kBackendCPU ? spaceskip::BackendKind::CPU : spaceskip::BackendKind::Auto;
    this->Engine.reset(new spaceskip::Engine(kind, this->Warn));
    this->Engine->setTuning(this->Tuning);
    this->Engine->setProgress(this->Progress);
  }
  catch (const std::exception& e)
  {
    this->Fail(std::string("cannot create the SpaceSkip engine: ") + e.what());
    return false;
  }
  this->EngineBackend = backend;
  if (backend == kBackendCUDA && this->Engine->backendKind() != spaceskip::BackendKind::CUDA)
  {
    this->Warn("CUDA backend unavailable (no usable CUDA device, or SpaceSkip built "
               "without CUDA); using the CPU backend");
  }
  this->Input.Reset();
  this->Properties.Reset();
  return true;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipImageRenderer::ResetFrameTimes()
{
  vtkSpaceSkipStatistics& f = this->Frame;
  f.ScalarRangeSeconds = f.UpdateSeconds = f.DepthReadSeconds = f.EngineRenderSeconds = 0;
  f.CompositeSeconds = 0;
  this->Deferred = false;
}

//------------------------------------------------------------------------------
// Only what changed reaches the engine (the volume and its scalar range, the transfer
// function, the build and render parameters), then the frame and its compositing.
bool vtkSpaceSkipImageRenderer::Render(vtkRenderer* ren, vtkVolume* vol,
  vtkOpenGLRenderWindow* renWin, vtkOpenGLCamera* cam, vtkImageData* input, vtkDataArray* scalars,
  int cellFlag, const vtkSpaceSkipSettings& s, const FrameMode& mode)
{
  WindowState window(renWin, this->Callouts);
  // Input conversion, first half: what to draw, or why nothing.
  std::string problem;
  // A second array as the 2-D transfer function's y axis, where one is used (TF_2D with a
  // table): a point array of the input, as vtkGPUVolumeRayCastMapper reads its
  // Transfer2DYAxisArray.
  vtkDataArray* yAxis = nullptr;
  if (!s.Transfer2DYAxisArray.empty() && input &&
    vtkSpaceSkipPropertyTranslator::Usable2D(vol->GetProperty()))
  {
    yAxis = input->GetPointData()->GetArray(s.Transfer2DYAxisArray.c_str());
    if (!yAxis)
    {
      this->Warn("the 2-D transfer function's y-axis array '" + s.Transfer2DYAxisArray +
        "' is not a point array of the input; the gradient magnitude is the y axis");
    }
  }
  if (!this->Input.Select(input, scalars, cellFlag, s.VectorMode, s.VectorComponent,
        vol->GetProperty()->GetIndependentComponents() != 0,
        s.EffectiveBlendMode() == vtkVolumeMapper::COMPOSITE_BLEND, this->Warn, problem, yAxis,
        s.Transfer2DYAxisComponent))
  {
    this->Fail(problem);
    return false;
  }
  if (!this->UpdateEngine(s.Backend))
  {
    return false;
  }
  try
  {
    spaceskip::Engine& engine = *this->Engine;
    // With the next time step's upload started behind this one's (PrefetchTimeStep).
    this->Frame.ScalarRangeSeconds = this->Input.Update(engine, this->Warn, mode.Prefetch);
    // A piece of a larger image (MPI): the whole image's lattice and scalar range. A block of a
    // composite input uses the range of all blocks.
    this->Piece = vtkSpaceSkipInputConverter::PieceOf(input, s.WholeExtent, mode.Owned,
      mode.Owned || mode.Exact, this->Tuning.pieceBias, this->Warn);
    engine.setPiece(this->Piece);
    const double* range = mode.TableRange ? mode.TableRange
      : s.WholeScalarRange[0] <= s.WholeScalarRange[1] ? s.WholeScalarRange
                                                         : this->Input.GetScalarRange();
    // A second array as the y axis: the rows span the whole data's range of it where given
    // (MPI, blocks), rounded to float as the converter's own range is.
    const double* yWhole = s.WholeSecondAxisRange;
    const double secondRange[2] = { static_cast<float>(yWhole[0]), static_cast<float>(yWhole[1]) };
    const double* opacityRange = this->Input.GetSecondAxis() && yWhole[0] <= yWhole[1]
      ? secondRange
      : this->Input.GetOpacityRange();
    this->Properties.UpdateTransferFunction(engine, vol->GetProperty(), range, opacityRange,
      this->Input.GetOpacityComponent(), this->Input.GetSecondAxis());
    this->Properties.UpdateParameters(engine, s, ren, vol, range, this->Warn);
    const spaceskip::Camera camera = vtkSpaceSkipPropertyTranslator::ToCamera(ren, cam, vol);
    int width, height, x0, y0;
    ren->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
    if (width <= 0 || height <= 0)
    {
      return false;
    }
    this->RenderFrame(renWin, window, vtkSpaceSkipCompositor::SceneHasDepth(ren), camera, x0, y0,
      width, height, s, mode);
    this->Deferred = mode.Defer;
    window.Restore();
    return mode.Defer || this->Composite(renWin, input, camera, width, height, s.EightBitComposite);
  }
  catch (const std::exception& e)
  {
    this->Fail(std::string("SpaceSkip engine error: ") + e.what() + ": nothing drawn");
  }
  return false;
}

//------------------------------------------------------------------------------
// The engine's work: whatever the changes left to do (ranges, upload, classification, build),
// the depth of what is drawn, the frame; then what ran.
void vtkSpaceSkipImageRenderer::RenderFrame(vtkOpenGLRenderWindow* renWin, WindowState& window,
  bool sceneHasDepth, const spaceskip::Camera& camera, int x0, int y0, int width, int height,
  const vtkSpaceSkipSettings& s, const FrameMode& mode)
{
  spaceskip::Engine& engine = *this->Engine;
  vtkSpaceSkipStatistics& f = this->Frame;
  auto t0 = std::chrono::steady_clock::now();
  if (engine.backendKind() == spaceskip::BackendKind::CUDA) // the CPU keeps the volume in host memory
  {
    engine.setMemoryBudget(static_cast<int64_t>(s.DeviceMemoryBudget) << 20);
  }
  engine.update();
  f.UpdateSeconds = SecondsSince(t0);

  // Depth of the opaque geometry already drawn, read from the framebuffer being rendered (not
  // when the scene has nothing but volumes: the buffer holds the far plane only).
  t0 = std::chrono::steady_clock::now();
  window.Restore(); // the depth is read from the frame's framebuffer
  f.DepthRead = sceneHasDepth;
  this->FrameDepth = sceneHasDepth ? this->Compositor.ReadDepth(renWin, x0, y0, width, height) : nullptr;
  if (sceneHasDepth && !this->FrameDepth)
  {
    this->Warn("could not read the depth buffer: the volume ignores opaque geometry");
  }
  f.DepthReadSeconds = SecondsSince(t0);

  const int buildsBefore = engine.counters().builds;
  // GPUComposite: the CUDA backend leaves the image on the device for the interop copy.
  // A deferred frame stays there too where the exchange takes device pieces (OnDevice).
  engine.setImageOnDevice((!mode.Defer || mode.OnDevice) && this->Compositor.CanUseDeviceImage(s.GPUComposite) &&
    engine.backendKind() == spaceskip::BackendKind::CUDA);
  t0 = std::chrono::steady_clock::now();
  engine.render(camera, width, height, this->Image, this->FrameDepth,
    mode.Defer ? mode.IncomingAlpha : nullptr);
  f.EngineRenderSeconds = SecondsSince(t0);
  const spaceskip::BuildStats& bs = engine.buildStats();
  if (engine.counters().builds != buildsBefore)
  {
    vtkVLogF(vtkLogger::VERBOSITY_TRACE,
      "vtkSpaceSkippingVolumeMapper: built %s on %s in %.6f s (classify %.6f s): %lld nodes, "
      "height %d, %lld leaves, occupancy %.4f",
      spaceskip::builderName(bs.builder), bs.builtOn.c_str(), bs.seconds, bs.classifySeconds,
      static_cast<long long>(bs.nodes), bs.height, static_cast<long long>(bs.leaves),
      bs.occupancy);
  }
  // frameStats(false): a frame left on the device is not waited for (its kernel time is read
  // when asked for, GetLastKernelSeconds).
  const spaceskip::FrameStats& fs = engine.frameStats(false);
  vtkVLogF(vtkLogger::VERBOSITY_TRACE, "vtkSpaceSkippingVolumeMapper: %dx%d frame in %.6f s on %s",
    width, height, fs.seconds, fs.backend.c_str());
  f.BackendUsed = fs.backend;
  f.BuilderUsed = spaceskip::builderName(bs.builder);
  f.SampleDistanceUsed = engine.sampleDistance();
  f.BuilderChoice = bs.choice;
  const spaceskip::ResidencyStats& rs = fs.residency;
  f.ResidentBricks = rs.sparse ? static_cast<vtkIdType>(rs.resident) : 0;
  char text[160];
  std::snprintf(text, sizeof text, "sparse: %lld of %lld bricks resident (%.0f MiB pool)",
    static_cast<long long>(rs.resident), static_cast<long long>(rs.bricks), double(rs.poolBytes) / 1048576.0);
  f.Residency = rs.sparse ? text : "in core";
}

//------------------------------------------------------------------------------
// The image into the window: through CUDA-GL interop when it stayed on the device (else this
// frame again through host memory), blended over what is drawn; false (said) when it cannot.
bool vtkSpaceSkipImageRenderer::Composite(vtkOpenGLRenderWindow* renWin, vtkImageData* input,
  const spaceskip::Camera& camera, int width, int height, bool eightBit)
{
  const auto t0 = std::chrono::steady_clock::now();
  spaceskip::Engine& engine = *this->Engine;
  // The pixels the rays can colour: the box grown by a sample step and two voxels (a ray's last
  // sample may lie up to a step past the box, clamped onto it).
  int* rect = this->Frame.CompositeRect;
  const double* spacing = input ? input->GetSpacing() : nullptr;
  const double minSpacing = spacing
    ? std::min({ std::fabs(spacing[0]), std::fabs(spacing[1]), std::fabs(spacing[2]) })
    : 0.0;
  vtkSpaceSkipCompositor::VisibleRect(camera,
    minSpacing > 0 && !this->Tuning.compositeFull ? input : nullptr,
    2.0 + engine.sampleDistance() / std::max(minSpacing, 1e-300), width, height, rect);
  const spaceskip::DeviceImageView deviceImage = engine.deviceImageView();
  // The flat image only if the CUDA blend cannot read the layers (the texture path).
  if (deviceImage.image &&
    !this->Compositor.CopyDeviceImage(renWin, deviceImage, [&engine]() { return engine.deviceImage(); },
      engine.deviceImageStream(), width, height, rect, eightBit))
  {
    engine.setImageOnDevice(false);
    engine.render(camera, width, height, this->Image, this->FrameDepth);
  }
  this->ReportPaths();
  if (!this->Compositor.Draw(renWin, this->Image, width, height, eightBit, rect))
  {
    this->Fail("could not compile the compositing shader: nothing drawn");
    return false;
  }
  this->Frame.CompositeSeconds = SecondsSince(t0);
  return true;
}

//------------------------------------------------------------------------------
// SPACESKIP_REPORT: what actually ran, for logs of test and benchmark runs on other machines.
void vtkSpaceSkipImageRenderer::ReportPaths()
{
  const vtkSpaceSkipCompositor& c = this->Compositor;
  if (!this->Report ||
    this->Reported == this->Frame.BackendUsed + this->Frame.BuilderUsed + c.GetCompositePath() + c.GetBlendPath())
  {
    return;
  }
  const GLubyte* glRenderer = glGetString(GL_RENDERER);
  const GLubyte* glVendor = glGetString(GL_VENDOR);
  std::cout << "SpaceSkip: backend " << this->Frame.BackendUsed << ", builder " << this->Frame.BuilderUsed
            << ", GL_RENDERER " << (glRenderer ? reinterpret_cast<const char*>(glRenderer) : "?")
            << ", GL_VENDOR " << (glVendor ? reinterpret_cast<const char*>(glVendor) : "?")
            << ", image "
            << (c.HasDeviceImage() ? "on the GPU (CUDA-GL interop, blended by " + c.GetBlendPath() + ")"
                                   : std::string("through host memory"))
            << (c.GetInteropFailed() ? " (interop: " + c.GetInteropProblem() + ")" : std::string())
            << std::endl;
  this->Reported = this->Frame.BackendUsed + this->Frame.BuilderUsed + c.GetCompositePath() + c.GetBlendPath();
}

//------------------------------------------------------------------------------
vtkSpaceSkipStatistics vtkSpaceSkipImageRenderer::Statistics(bool deviceTimes) const
{
  vtkSpaceSkipStatistics s = this->Frame;
  const spaceskip::Counters c = this->Counts();
  s.Builds = c.builds;
  s.Classifications = c.classifications;
  s.ColorUpdates = c.colorUpdates;
  s.Frames = c.frames;
  s.TimeSteps = c.timeSteps;
  s.PrefetchedTimeSteps = c.prefetchedSteps;
  s.ColorTableSamples = this->Properties.GetColorTableSamples();
  s.OpacityTableSamples = this->Properties.GetOpacityTableSamples();
  s.CompositePath = this->Compositor.GetCompositePath();
  s.CompositeBlend = this->Compositor.GetBlendPath();
  spaceskip::Engine* engine = this->Engine.get();
  if (!engine)
  {
    return s;
  }
  const spaceskip::BuildStats& bs = engine->buildStats();
  s.BuildSeconds = bs.seconds;
  s.ClassifySeconds = bs.classifySeconds;
  s.Nodes = bs.nodes;
  s.TreeHeight = bs.height;
  s.Leaves = bs.leaves;
  s.Occupancy = bs.occupancy;
  if (deviceTimes)
  {
    // With the image kept on the GPU the engine returns once the kernel is launched: the pass is
    // the kernel's time (this waits for it).
    if (engine->deviceImageStream())
    {
      const spaceskip::FrameStats& f = engine->frameStats();
      s.RenderSeconds = f.deviceSeconds > 0 ? f.deviceSeconds : f.seconds;
    }
    else
    {
      s.RenderSeconds = engine->frameStats(false).seconds;
    }
    const spaceskip::FrameStats& f = engine->frameStats();
    s.KernelSeconds = f.deviceSeconds >= 0 ? f.deviceSeconds : f.seconds;
  }
  return s;
}

//------------------------------------------------------------------------------
const void* vtkSpaceSkipImageRenderer::DeferredDeviceImage(int& width, int& height, void*& stream) const
{
  const void* image = this->Deferred && this->Engine ? this->Engine->deviceImage() : nullptr;
  if (!image)
  {
    return nullptr;
  }
  width = this->Image.width;
  height = this->Image.height;
  stream = this->Engine->deviceImageStream();
  return image;
}

//------------------------------------------------------------------------------
const float* vtkSpaceSkipImageRenderer::DeferredImage(int& width, int& height) const
{
  if (!this->Deferred || this->Image.rgba.empty())
  {
    return nullptr;
  }
  width = this->Image.width;
  height = this->Image.height;
  return &this->Image.rgba[0].x;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipImageRenderer::SetTuning(const spaceskip::Tuning& tuning)
{
  this->Tuning = tuning;
  this->Compositor.SetCudaBlend(tuning.cudaBlend);
  if (this->Engine)
  {
    this->Engine->setTuning(tuning);
  }
}
