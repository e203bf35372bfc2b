// vtkSpaceSkippingVolumeMapper: VTK types -> spaceskip::Engine, and the engine's image -> the
// window. Render() is the sequence of steps; the work is in vtkSpaceSkipInputConverter (the
// input -> a Core Volume), vtkSpaceSkipPropertyTranslator (property, settings, lights, camera ->
// Core parameters) and vtkSpaceSkipCompositor (depth readback, upload or interop, blending).
#include "vtkSpaceSkippingVolumeMapper.h"

#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkFloatArray.h"
#include "vtkPointData.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkStructuredData.h"
#include "vtkCamera.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkUnsignedCharArray.h"
#include "vtkLogger.h"
#include "vtkMath.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLCamera.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkipBlockRenderer.h"
#include "vtkSpaceSkipCompositor.h"
#include "vtkSpaceSkipInputConverter.h"
#include "vtkSpaceSkipPieceCompositing.h"
#include "vtkSpaceSkipPropertyTranslator.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtk_glew.h"

#include "spaceskip/Backend.h"
#include "spaceskip/Engine.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <set>
#include <string>

namespace
{
// The library's only environment variables, read once per process (docs/tuning.md):
// SPACESKIP_BACKEND=cpu|cuda|auto forces the backend of every mapper in the process, whatever
// its Backend property says (to run the VTK tests on a GPU machine: bench/device/run-vtk.sh),
// said once as a warning; SPACESKIP_REPORT (any value) makes each mapper print what ran.
struct EnvironmentOverrides
{
  int Backend = -1; // -1: none
  bool Report = false;
};

const EnvironmentOverrides& Overrides()
{
  static const EnvironmentOverrides o = []
  {
    EnvironmentOverrides r;
    const char* e = std::getenv("SPACESKIP_BACKEND");
    const std::string v = e ? e : "";
    if (v == "cpu" || v == "CPU")
    {
      r.Backend = vtkSpaceSkippingVolumeMapper::CPU;
    }
    else if (v == "cuda" || v == "CUDA")
    {
      r.Backend = vtkSpaceSkippingVolumeMapper::CUDA;
    }
    else if (v == "auto" || v == "Auto")
    {
      r.Backend = vtkSpaceSkippingVolumeMapper::Auto;
    }
    if (r.Backend >= 0)
    {
      vtkGenericWarningMacro("SPACESKIP_BACKEND=" << v << " in the environment overrides the "
                                                  << "Backend property of every SpaceSkip mapper");
    }
    r.Report = std::getenv("SPACESKIP_REPORT") != nullptr;
    return r;
  }();
  return o;
}

// The input as a piece of the image of extent `whole` (an empty `whole`: its own extent), and
// the cells it draws: those its vtkGhostType cell array does not mark as duplicates of another
// piece's, or `owned` ([lo, hi) cells per axis, whole-extent indices) when given (a block of a
// composite input: drawn exactly, composited in float). Inactive (the serial path, untouched)
// when the input is the whole image without ghosts.
spaceskip::VolumePiece PieceOf(vtkImageData* input, const int whole[6], const int* owned,
  bool exact, double bias, const std::function<void(const std::string&)>& warn)
{
  spaceskip::VolumePiece piece;
  int ext[6], w[6];
  input->GetExtent(ext);
  std::copy(whole, whole + 6, w);
  bool haveWhole = w[0] <= w[1] && w[2] <= w[3] && w[4] <= w[5];
  if (haveWhole &&
    !(w[0] <= ext[0] && ext[1] <= w[1] && w[2] <= ext[2] && ext[3] <= w[3] && w[4] <= ext[4] &&
      ext[5] <= w[5]))
  {
    warn("WholeExtent does not contain the input's extent: ignored (the input is drawn as a "
         "whole image)");
    haveWhole = false;
  }
  if (!haveWhole)
  {
    std::copy(ext, ext + 6, w);
  }
  // Owned cells, [lo, hi] inclusive in cell indices (an axis of one point has one cell).
  int own[6];
  for (int a = 0; a < 3; ++a)
  {
    own[2 * a] = ext[2 * a];
    own[2 * a + 1] = std::max(ext[2 * a + 1] - 1, ext[2 * a]);
  }
  bool ghosts = false;
  if (owned)
  {
    for (int a = 0; a < 3; ++a)
    {
      own[2 * a] = owned[2 * a];
      own[2 * a + 1] = owned[2 * a + 1] - 1;
      ghosts = ghosts || own[2 * a] != ext[2 * a] || own[2 * a + 1] != std::max(ext[2 * a + 1] - 1, ext[2 * a]);
    }
  }
  else if (vtkUnsignedCharArray* g = input->GetCellData()->GetGhostArray())
  {
    // The first and the last cell that is not a duplicate bound the owned cells (an image
    // piece's ghost cells are layers on its faces), as ParaView's volume representation does.
    const vtkIdType n = g->GetNumberOfTuples();
    const unsigned char* v = g->GetPointer(0);
    const unsigned char dup = vtkDataSetAttributes::DUPLICATECELL;
    vtkIdType first = 0, last = n - 1;
    while (first < n && (v[first] & dup))
    {
      ++first;
    }
    while (last >= 0 && (v[last] & dup))
    {
      --last;
    }
    ghosts = first > 0 || last < n - 1;
    if (first > last)
    {
      own[1] = own[0] - 1; // all ghost: nothing owned
    }
    else if (ghosts)
    {
      int ijk[3], ijk1[3];
      vtkStructuredData::ComputeCellStructuredCoordsForExtent(first, ext, ijk);
      vtkStructuredData::ComputeCellStructuredCoordsForExtent(last, ext, ijk1);
      for (int a = 0; a < 3; ++a)
      {
        own[2 * a] = ijk[a];
        own[2 * a + 1] = ijk1[a];
      }
    }
  }
  bool same = !ghosts;
  for (int i = 0; i < 6; ++i)
  {
    same = same && w[i] == ext[i];
  }
  if (same)
  {
    return piece;
  }
  input->TransformIndexToPhysicalPoint(w[0], w[2], w[4], piece.wholeOrigin);
  piece.wholeDims = spaceskip::vec3l{ w[1] - w[0] + 1, w[3] - w[2] + 1, w[5] - w[4] + 1 };
  piece.offset = spaceskip::vec3l{ ext[0] - w[0], ext[2] - w[2], ext[4] - w[4] };
  piece.ownedLo = spaceskip::vec3l{ own[0] - w[0], own[2] - w[2], own[4] - w[4] };
  piece.ownedHi = spaceskip::vec3l{ own[1] + 1 - w[0], own[3] + 1 - w[2], own[5] + 1 - w[4] };
  // The window and IceT hold 8 bits: a piece in front rounds up by half a unit what IceT's
  // blend truncates (README, Parallel). `bias`: Tuning::pieceBias (in 1/255).
  piece.followBias = exact ? 0.f : static_cast<float>(bias / 255.0);
  return piece;
}

double SecondsSince(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
} // namespace

struct vtkSpaceSkippingVolumeMapper::vtkInternals
{
  explicit vtkInternals(vtkSpaceSkippingVolumeMapper* self)
    : Self(self)
    , Warn([self](const std::string& m) { self->WarnOnce(m); })
  {
  }

  vtkSpaceSkippingVolumeMapper* Self;
  // The mapper's WarnOnce, for the engine and the helpers below.
  const std::function<void(const std::string&)> Warn;

  std::unique_ptr<spaceskip::Engine> Engine;
  int EngineBackend = -1;
  spaceskip::Counters CountOffset; // stages run by engines replaced after a Backend change

  vtkSpaceSkipInputConverter Input;
  vtkSpaceSkipPropertyTranslator Properties;

  // One message per distinct problem, not one per frame.
  std::string LastProblem;
  // Warnings (engine fallbacks, clamps) already said by this mapper: each cause once, also
  // across the engines that backend switches create.
  std::set<std::string> Said;
  double SampleDistanceUsed = 0;
  std::string BuilderChoice;
  std::string Residency = "none";
  vtkIdType ResidentBricks = 0;

  std::string BackendUsed = "none";
  std::string BuilderUsed = "none";
  // SPACESKIP_REPORT set: one stdout line per mapper whenever backend or builder changes.
  bool Report = Overrides().Report;
  spaceskip::Tuning Tuning; // SetTuning
  std::string Reported;

  // Where the last Render() spent its time (seconds; see the getters).
  double RangeSeconds = 0;
  double UpdateSeconds = 0;
  double DepthSeconds = 0;
  bool DepthRead = false; // the last frame read the window's depth (SceneHasDepth)
  double EngineSeconds = 0;
  double CompositeSeconds = 0;
  double MapperSeconds = 0;
  int CompositeRect[4] = { 0, 0, 0, 0 }; // the viewport rectangle the last frame blended

  spaceskip::Image Image;
  bool DeferredReady = false; // DeferDraw: Image holds this Render()'s frame
  spaceskip::VolumePiece LastPiece; // the piece the last frame drew (inactive: the whole input)
  // Float compositing across processes (SetPieceExchange), and the image it hands back.
  std::shared_ptr<vtkSpaceSkippingVolumeMapper::PieceExchange> Exchange;
  double WholeBounds[6] = { 1, -1, 1, -1, 1, -1 };
  // GetInput() of a process with an empty piece (see there), and the array name it carries.
  vtkSmartPointer<vtkImageData> EmptyPiece;
  std::string EmptyPieceArray;
  spaceskip::Image Exchanged;
  const float* FrameDepth = nullptr; // this frame's depth (the compositor's buffer), or null
  // Last, so that it goes (with its CUDA-GL interop registration) before the engine.
  vtkSpaceSkipCompositor Compositor;
  // Composite input: one mapper per image block (each with its engine and compositor).
  vtkSpaceSkipBlockRenderer Blocks;

  // Reports a problem once (until the next different one); the caller then draws nothing.
  void Fail(const std::string& msg)
  {
    if (msg != this->LastProblem)
    {
      vtkErrorWithObjectMacro(this->Self, << msg);
      this->LastProblem = msg;
    }
  }

  bool SelectInput(vtkVolume* vol);
  bool UpdateEngine();
  void RenderFrame(vtkOpenGLRenderWindow* renWin, bool sceneHasDepth, const spaceskip::Camera& camera, int x0, int y0,
    int width, int height);
  bool Composite(vtkOpenGLRenderWindow* renWin, vtkImageData* input,
    const spaceskip::Camera& camera, int width, int height);
  void ReportPaths();

  spaceskip::Counters Counts() const
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
    }
    return c;
  }
};

//------------------------------------------------------------------------------
// Input conversion, first half: updates the input and picks its scalars; false (said) when
// nothing can be drawn.
bool vtkSpaceSkippingVolumeMapper::vtkInternals::SelectInput(vtkVolume* vol)
{
  vtkSpaceSkippingVolumeMapper* self = this->Self;
  if (self->GetNumberOfInputConnections(0) > 0 && self->GetInputAlgorithm())
  {
    self->GetInputAlgorithm()->Update();
  }
  vtkImageData* input = vtkImageData::SafeDownCast(self->GetInput());
  int cellFlag = 0;
  vtkDataArray* scalars = input ? vtkAbstractMapper::GetScalars(input, self->ScalarMode,
                                    self->ArrayAccessMode, self->ArrayId, self->ArrayName, cellFlag)
                                : nullptr;
  std::string problem;
  if (!this->Input.Select(input, scalars, cellFlag, self->VectorMode, self->VectorComponent,
        vol->GetProperty()->GetIndependentComponents() != 0,
        self->EffectiveBlendMode() == vtkVolumeMapper::COMPOSITE_BLEND, this->Warn, problem))
  {
    this->Fail(problem);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
// (Re)creates the engine when the backend changes (counts are carried over); false (said) when
// it cannot be created.
bool vtkSpaceSkippingVolumeMapper::vtkInternals::UpdateEngine()
{
  const int forced = Overrides().Backend;
  const int backend = forced >= 0 ? forced : this->Self->Backend;
  if (this->Engine && this->EngineBackend == backend)
  {
    return true;
  }
  this->CountOffset = this->Counts();
  this->Engine.reset();
  try
  {
    // Auto, not CUDA: the mapper says a missing device below in its own words (Engine(CUDA)
    // would say it in the engine's); Auto makes the same choice silently.
    const spaceskip::BackendKind kind =
      backend == CPU ? spaceskip::BackendKind::CPU : spaceskip::BackendKind::Auto;
    this->Engine.reset(new spaceskip::Engine(kind, this->Warn));
    this->Engine->setTuning(this->Tuning);
    // The engine's steps as the algorithm's progress (ParaView's progress bar): the text names
    // the step, the fraction runs over the update and frame together.
    vtkSpaceSkippingVolumeMapper* self = this->Self;
    this->Engine->setProgress([self](double fraction, const char* step) {
      const std::string text = std::string("Space Skipping Volume: ") + step;
      if (!self->GetProgressText() || text != self->GetProgressText())
      {
        self->SetProgressText(text.c_str());
      }
      self->UpdateProgress(fraction);
    });
  }
  catch (const std::exception& e)
  {
    this->Fail(std::string("cannot create the SpaceSkip engine: ") + e.what());
    return false;
  }
  this->EngineBackend = backend;
  if (backend == CUDA && this->Engine->backendKind() != spaceskip::BackendKind::CUDA)
  {
    this->Warn("CUDA backend unavailable (no usable CUDA device, or SpaceSkip built "
               "without CUDA); using the CPU backend");
  }
  this->Input.Reset();
  this->Properties.Reset();
  return true;
}

//------------------------------------------------------------------------------
// The engine's work: whatever the changes left to do (ranges, upload, classification, build),
// the depth of what is drawn, the frame; then the statistics of the frame.
void vtkSpaceSkippingVolumeMapper::vtkInternals::RenderFrame(vtkOpenGLRenderWindow* renWin,
  bool sceneHasDepth, const spaceskip::Camera& camera, int x0, int y0, int width, int height)
{
  spaceskip::Engine& engine = *this->Engine;
  auto t0 = std::chrono::steady_clock::now();
  if (engine.backendKind() == spaceskip::BackendKind::CUDA)  // the CPU backend keeps the volume in host memory
  {
    engine.setMemoryBudget(static_cast<int64_t>(this->Self->DeviceMemoryBudget) << 20);
  }
  engine.update();
  this->UpdateSeconds = SecondsSince(t0);

  // Depth of the opaque geometry already drawn, read from the framebuffer being rendered (not
  // when the scene has nothing but volumes: the buffer holds the far plane only).
  t0 = std::chrono::steady_clock::now();
  this->DepthRead = sceneHasDepth;
  this->FrameDepth = sceneHasDepth ? this->Compositor.ReadDepth(renWin, x0, y0, width, height) : nullptr;
  if (sceneHasDepth && !this->FrameDepth)
  {
    this->Warn("could not read the depth buffer: the volume ignores opaque geometry");
  }
  this->DepthSeconds = SecondsSince(t0);

  const int buildsBefore = engine.counters().builds;
  // GPUComposite: the CUDA backend leaves the image on the device for the interop copy.
  engine.setImageOnDevice(!this->Self->DeferDraw &&
    this->Compositor.CanUseDeviceImage(this->Self->GPUComposite != 0) &&
    engine.backendKind() == spaceskip::BackendKind::CUDA);
  t0 = std::chrono::steady_clock::now();
  engine.render(camera, width, height, this->Image, this->FrameDepth,
    this->Self->DeferDraw ? this->Self->IncomingAlpha : nullptr);
  this->EngineSeconds = SecondsSince(t0);
  if (engine.counters().builds != buildsBefore)
  {
    const spaceskip::BuildStats& bs = engine.buildStats();
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
  this->BackendUsed = fs.backend;
  this->BuilderUsed = spaceskip::builderName(engine.buildStats().builder);
  this->SampleDistanceUsed = engine.sampleDistance();
  this->BuilderChoice = engine.buildStats().choice;
  const spaceskip::ResidencyStats& rs = fs.residency;
  this->ResidentBricks = rs.sparse ? static_cast<vtkIdType>(rs.resident) : 0;
  char text[160];
  std::snprintf(text, sizeof text, "sparse: %lld of %lld bricks resident (%.0f MiB pool)",
    static_cast<long long>(rs.resident), static_cast<long long>(rs.bricks), double(rs.poolBytes) / 1048576.0);
  this->Residency = rs.sparse ? text : "in core";
}

//------------------------------------------------------------------------------
// The image into the window: through CUDA-GL interop when it stayed on the device (else this
// frame again through host memory), blended over what is drawn; false (said) when it cannot.
bool vtkSpaceSkippingVolumeMapper::vtkInternals::Composite(vtkOpenGLRenderWindow* renWin,
  vtkImageData* input, const spaceskip::Camera& camera, int width, int height)
{
  const auto t0 = std::chrono::steady_clock::now();
  spaceskip::Engine& engine = *this->Engine;
  // The pixels the rays can colour: the box grown by a sample step and two voxels (a ray's last
  // sample may lie up to a step past the box, clamped onto it).
  int rect[4];
  const double* spacing = input ? input->GetSpacing() : nullptr;
  const double minSpacing = spacing
    ? std::min({ std::fabs(spacing[0]), std::fabs(spacing[1]), std::fabs(spacing[2]) })
    : 0.0;
  vtkSpaceSkipCompositor::VisibleRect(camera,
    minSpacing > 0 && !this->Tuning.compositeFull ? input : nullptr,
    2.0 + engine.sampleDistance() / std::max(minSpacing, 1e-300), width, height, rect);
  std::copy(rect, rect + 4, this->CompositeRect);
  const bool eightBit = this->Self->EightBitComposite != 0;
  const spaceskip::DeviceImageView deviceImage = engine.deviceImageView();
  if (deviceImage.image)
  {
    // The flat image only if the CUDA blend cannot read the layers (the texture path).
    if (!this->Compositor.CopyDeviceImage(renWin, deviceImage,
          [&engine]() { return engine.deviceImage(); }, engine.deviceImageStream(), width, height,
          rect, eightBit))
    {
      engine.setImageOnDevice(false);
      engine.render(camera, width, height, this->Image, this->FrameDepth);
    }
  }
  this->ReportPaths();
  if (!this->Compositor.Draw(renWin, this->Image, width, height, eightBit, rect))
  {
    this->Fail("could not compile the compositing shader: nothing drawn");
    return false;
  }
  this->CompositeSeconds = SecondsSince(t0);
  return true;
}

//------------------------------------------------------------------------------
// SPACESKIP_REPORT: what actually ran, for logs of test and benchmark runs on other machines.
void vtkSpaceSkippingVolumeMapper::vtkInternals::ReportPaths()
{
  const vtkSpaceSkipCompositor& c = this->Compositor;
  if (!this->Report ||
    this->Reported == this->BackendUsed + this->BuilderUsed + c.GetCompositePath() + c.GetBlendPath())
  {
    return;
  }
  const GLubyte* glRenderer = glGetString(GL_RENDERER);
  const GLubyte* glVendor = glGetString(GL_VENDOR);
  std::cout << "SpaceSkip: backend " << this->BackendUsed << ", builder " << this->BuilderUsed
            << ", GL_RENDERER " << (glRenderer ? reinterpret_cast<const char*>(glRenderer) : "?")
            << ", GL_VENDOR " << (glVendor ? reinterpret_cast<const char*>(glVendor) : "?")
            << ", image "
            << (c.HasDeviceImage() ? "on the GPU (CUDA-GL interop, blended by " + c.GetBlendPath() + ")"
                                   : std::string("through host memory"))
            << (c.GetInteropFailed() ? " (interop: " + c.GetInteropProblem() + ")" : std::string())
            << std::endl;
  this->Reported = this->BackendUsed + this->BuilderUsed + c.GetCompositePath() + c.GetBlendPath();
}

vtkStandardNewMacro(vtkSpaceSkippingVolumeMapper);

//------------------------------------------------------------------------------
vtkSpaceSkippingVolumeMapper::vtkSpaceSkippingVolumeMapper()
  : Internals(new vtkInternals(this))
{
}

//------------------------------------------------------------------------------
vtkSpaceSkippingVolumeMapper::~vtkSpaceSkippingVolumeMapper() = default;

//------------------------------------------------------------------------------
const char* vtkSpaceSkippingVolumeMapper::GetBuilderAsString()
{
  return spaceskip::builderName(static_cast<spaceskip::BuilderKind>(this->Builder));
}

//------------------------------------------------------------------------------
const char* vtkSpaceSkippingVolumeMapper::GetFilterModeAsString()
{
  return this->FilterMode == HardwareFilter ? "Hardware" : "Exact";
}

//------------------------------------------------------------------------------
double vtkSpaceSkippingVolumeMapper::GetLastBuildSeconds()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetLastBuildSeconds);
  }
  return this->Internals->Engine ? this->Internals->Engine->buildStats().seconds : 0.0;
}
double vtkSpaceSkippingVolumeMapper::GetLastClassifySeconds()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetLastClassifySeconds);
  }
  return this->Internals->Engine ? this->Internals->Engine->buildStats().classifySeconds : 0.0;
}
double vtkSpaceSkippingVolumeMapper::GetLastRenderSeconds()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetLastRenderSeconds);
  }
  spaceskip::Engine* engine = this->Internals->Engine.get();
  if (!engine)
  {
    return 0.0;
  }
  // With the image kept on the GPU the engine returns once the kernel is launched: the pass is
  // the kernel's time (this waits for it).
  if (engine->deviceImageStream())
  {
    const spaceskip::FrameStats& f = engine->frameStats();
    return f.deviceSeconds > 0 ? f.deviceSeconds : f.seconds;
  }
  return engine->frameStats(false).seconds;
}
double vtkSpaceSkippingVolumeMapper::GetLastKernelSeconds()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetLastKernelSeconds);
  }
  if (!this->Internals->Engine)
  {
    return 0.0;
  }
  const spaceskip::FrameStats& f = this->Internals->Engine->frameStats();
  return f.deviceSeconds >= 0 ? f.deviceSeconds : f.seconds;
}
double vtkSpaceSkippingVolumeMapper::GetLastScalarRangeSeconds()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetLastScalarRangeSeconds);
  }
  return this->Internals->RangeSeconds;
}
double vtkSpaceSkippingVolumeMapper::GetLastUpdateSeconds()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetLastUpdateSeconds);
  }
  return this->Internals->UpdateSeconds;
}
double vtkSpaceSkippingVolumeMapper::GetLastDepthReadSeconds()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetLastDepthReadSeconds);
  }
  return this->Internals->DepthSeconds;
}
bool vtkSpaceSkippingVolumeMapper::GetLastFrameReadDepth()
{
  return this->Internals->DepthRead;
}
double vtkSpaceSkippingVolumeMapper::GetLastEngineRenderSeconds()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetLastEngineRenderSeconds);
  }
  return this->Internals->EngineSeconds;
}
double vtkSpaceSkippingVolumeMapper::GetLastCompositeSeconds()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetLastCompositeSeconds);
  }
  return this->Internals->CompositeSeconds;
}
double vtkSpaceSkippingVolumeMapper::GetLastMapperSeconds()
{
  return this->Internals->MapperSeconds;
}
vtkIdType vtkSpaceSkippingVolumeMapper::GetNodeCount()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetNodeCount);
  }
  return this->Internals->Engine ? this->Internals->Engine->buildStats().nodes : 0;
}
int vtkSpaceSkippingVolumeMapper::GetTreeHeight()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Max(&vtkSpaceSkippingVolumeMapper::GetTreeHeight);
  }
  return this->Internals->Engine ? this->Internals->Engine->buildStats().height : 0;
}
vtkIdType vtkSpaceSkippingVolumeMapper::GetLeafCount()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetLeafCount);
  }
  return this->Internals->Engine ? this->Internals->Engine->buildStats().leaves : 0;
}
double vtkSpaceSkippingVolumeMapper::GetOccupancy()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Occupancy();
  }
  return this->Internals->Engine ? this->Internals->Engine->buildStats().occupancy : 0.0;
}
const char* vtkSpaceSkippingVolumeMapper::GetBackendUsed()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Names(&vtkSpaceSkippingVolumeMapper::GetBackendUsed);
  }
  return this->Internals->BackendUsed.c_str();
}
const char* vtkSpaceSkippingVolumeMapper::GetBuilderUsed()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Names(&vtkSpaceSkippingVolumeMapper::GetBuilderUsed);
  }
  return this->Internals->BuilderUsed.c_str();
}
const char* vtkSpaceSkippingVolumeMapper::GetCompositePathUsed()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.GetCompositePath(); // the blended blocks' way to the window
  }
  return this->Internals->Compositor.GetCompositePath().c_str();
}
const char* vtkSpaceSkippingVolumeMapper::GetCompositeBlendUsed()
{
  if (this->Internals->Blocks.IsActive())
  {
    return "gl"; // the blocks' images are drawn by GL
  }
  return this->Internals->Compositor.GetBlendPath().c_str();
}
void vtkSpaceSkippingVolumeMapper::GetLastCompositeRect(int rect[4])
{
  std::copy(this->Internals->CompositeRect, this->Internals->CompositeRect + 4, rect);
}
const char* vtkSpaceSkippingVolumeMapper::GetBuilderChoice()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Names(&vtkSpaceSkippingVolumeMapper::GetBuilderChoice);
  }
  return this->Internals->BuilderChoice.c_str();
}
double vtkSpaceSkippingVolumeMapper::GetSampleDistanceUsed()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.MinSampleDistance();
  }
  return this->Internals->SampleDistanceUsed;
}
const char* vtkSpaceSkippingVolumeMapper::GetResidency()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Names(&vtkSpaceSkippingVolumeMapper::GetResidency);
  }
  return this->Internals->Residency.c_str();
}
vtkIdType vtkSpaceSkippingVolumeMapper::GetResidentBricks()
{
  return this->Internals->ResidentBricks;
}
vtkIdType vtkSpaceSkippingVolumeMapper::GetDeviceBytesInUse()
{
  return static_cast<vtkIdType>(spaceskip::cudaDeviceBytesInUse());
}
void vtkSpaceSkippingVolumeMapper::WarnOnce(const std::string& message)
{
  if (this->Internals->Said.insert(message).second)
  {
    vtkWarningMacro(<< message);
  }
}
int vtkSpaceSkippingVolumeMapper::GetBuildCount()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetBuildCount);
  }
  return this->Internals->Counts().builds;
}
int vtkSpaceSkippingVolumeMapper::GetClassifyCount()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetClassifyCount);
  }
  return this->Internals->Counts().classifications;
}
int vtkSpaceSkippingVolumeMapper::GetColorUpdateCount()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetColorUpdateCount);
  }
  return this->Internals->Counts().colorUpdates;
}
int vtkSpaceSkippingVolumeMapper::GetColorTableSampleCount()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetColorTableSampleCount);
  }
  return this->Internals->Properties.GetColorTableSamples();
}
int vtkSpaceSkippingVolumeMapper::GetOpacityTableSampleCount()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.Sum(&vtkSpaceSkippingVolumeMapper::GetOpacityTableSampleCount);
  }
  return this->Internals->Properties.GetOpacityTableSamples();
}
int vtkSpaceSkippingVolumeMapper::GetFrameCount()
{
  if (this->Internals->Blocks.IsActive())
  {
    return this->Internals->Blocks.GetFrameCount();
  }
  return this->Internals->Counts().frames;
}

//------------------------------------------------------------------------------
const float* vtkSpaceSkippingVolumeMapper::GetDeferredImage(int& width, int& height)
{
  vtkInternals& d = *this->Internals;
  if (!d.DeferredReady || d.Image.rgba.empty())
  {
    return nullptr;
  }
  width = d.Image.width;
  height = d.Image.height;
  return &d.Image.rgba[0].x;
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::ReleaseGraphicsResources(vtkWindow* win)
{
  this->Internals->Blocks.ReleaseGraphicsResources(win);
  this->Internals->Compositor.ReleaseGraphicsResources(win);
  this->Superclass::ReleaseGraphicsResources(win);
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::SetTuning(const spaceskip::Tuning& tuning)
{
  vtkInternals& d = *this->Internals;
  d.Tuning = tuning;
  d.Compositor.SetCudaBlend(tuning.cudaBlend);
  if (d.Engine)
  {
    d.Engine->setTuning(tuning);
  }
}
const spaceskip::Tuning& vtkSpaceSkippingVolumeMapper::GetTuning() const
{
  return this->Internals->Tuning;
}

void vtkSpaceSkippingVolumeMapper::SetPieceExchange(const std::shared_ptr<PieceExchange>& exchange)
{
  if (this->Internals->Exchange != exchange)
  {
    this->Internals->Exchange = exchange;
    this->Modified();
  }
}
void vtkSpaceSkippingVolumeMapper::SetWholeBounds(const double bounds[6])
{
  if (!std::equal(bounds, bounds + 6, this->Internals->WholeBounds))
  {
    std::copy(bounds, bounds + 6, this->Internals->WholeBounds);
    this->Modified();
  }
}
const std::shared_ptr<vtkSpaceSkippingVolumeMapper::PieceExchange>&
vtkSpaceSkippingVolumeMapper::GetPieceExchange() const
{
  return this->Internals->Exchange;
}

namespace
{
// Whether the mapper draws a piece of a larger image (WholeExtent given): a vtkImageData piece
// (`blocks` false) or composite input whose blocks lie on its lattice (`blocks` true).
bool IsPiece(vtkSpaceSkippingVolumeMapper* self, const int whole[6], bool& blocks)
{
  vtkDataObject* input =
    self->GetNumberOfInputConnections(0) > 0 ? self->GetInputDataObject(0, 0) : nullptr;
  blocks = vtkSpaceSkipBlockRenderer::IsComposite(input);
  return whole[0] <= whole[1] && whole[2] <= whole[3] && whole[4] <= whole[5];
}
}

//------------------------------------------------------------------------------
// With a piece exchange (MPI): every process draws its piece (or each of its blocks) exactly
// into a float image, the exchange composites them all in float on one process, which draws the
// sum; the others draw nothing. Every call reaches Finish(), whatever the piece drew (the
// others wait for it).
void vtkSpaceSkippingVolumeMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  vtkInternals& d = *this->Internals;
  const std::shared_ptr<PieceExchange> exchange = d.Exchange;
  bool blocks = false;
  if (!exchange || !ren || !IsPiece(this, this->WholeExtent, blocks))
  {
    this->RenderLocal(ren, vol);
    return;
  }
  namespace pc = vtkSpaceSkipPieceCompositing;
  exchange->Begin();
  std::vector<PieceImage> mine;
  double eye[3] = { 0, 0, 0 }, dir[3] = { 0, 0, 1 };
  bool parallel = false;
  const float* image = nullptr; // an image piece's own frame (drawn if the exchange is off)
  if (blocks)
  {
    // The block renderer leaves its blocks' images (on the whole image's lattice) to us.
    d.Blocks.SetExchangePieces(&mine);
    this->RenderLocal(ren, vol);
    d.Blocks.SetExchangePieces(nullptr);
    d.Blocks.ExchangeCamera(ren, vol, eye, dir, parallel);
  }
  else
  {
    const bool defer = this->DeferDraw;
    this->DeferDraw = true;
    this->ExactPiece = true;
    d.LastPiece = spaceskip::VolumePiece();
    d.DeferredReady = false;
    auto* data = vtkDataSet::SafeDownCast(this->GetInputDataObject(0, 0));
    if (data && data->GetNumberOfPoints() > 0)
    {
      this->RenderLocal(ren, vol); // an empty piece draws nothing (and says nothing)
    }
    this->DeferDraw = defer;
    this->ExactPiece = false;
    int w = 0, h = 0;
    image = this->GetDeferredImage(w, h);
    auto* input = vtkImageData::SafeDownCast(this->GetInput());
    if (image && input && vol && ren->GetActiveCamera())
    {
      // The cells drawn and the camera, in the whole extent's index space (less its first index).
      const spaceskip::VolumePiece& p = d.LastPiece;
      int ext[6], owned[6];
      input->GetExtent(ext);
      const int shift[3] = { this->WholeExtent[0], this->WholeExtent[2], this->WholeExtent[4] };
      for (int a = 0; a < 3; ++a)
      {
        owned[2 * a] = p.active() ? static_cast<int>(p.ownedLo[a]) : ext[2 * a] - shift[a];
        owned[2 * a + 1] = p.active() ? static_cast<int>(p.ownedHi[a])
                                      : std::max(ext[2 * a + 1], ext[2 * a] + 1) - shift[a];
      }
      mine.push_back(pc::Crop(image, w, h, owned));
      pc::CameraInIndexSpace(ren, vol, input, shift, eye, dir, parallel);
    }
    else
    {
      image = nullptr;
    }
  }
  int width = 0, height = 0, x0 = 0, y0 = 0;
  ren->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
  std::vector<PieceImage> others;
  const int draw = exchange->Finish(width, height, mine, others);
  auto* renWin = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  if (draw == 0 || !renWin || width <= 0 || height <= 0)
  {
    return;
  }
  const bool eightBit = this->EightBitComposite != 0;
  bool drawn = true;
  if (draw == -1 && blocks)
  {
    drawn = d.Blocks.DrawSum(ren, eightBit); // the exchange is off: this process's own blocks
  }
  else if (draw == -1)
  {
    // The exchange is off: this process's own frame (d.Image, kept by DeferDraw), as without it.
    drawn = !image || d.Compositor.Draw(renWin, d.Image, width, height, eightBit);
  }
  else
  {
    // Every piece front to back in the order the rays meet them, blended in float: one
    // rounding to 8 bits, as the serial image.
    for (PieceImage& p : mine)
    {
      others.push_back(std::move(p));
    }
    pc::Blend(others, eye, dir, parallel, width, height, d.Exchanged);
    drawn = d.Compositor.Draw(renWin, d.Exchanged, width, height, eightBit);
  }
  if (!drawn)
  {
    d.Fail("could not compile the compositing shader: nothing drawn");
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::RenderLocal(vtkRenderer* ren, vtkVolume* vol)
{
  vtkInternals& d = *this->Internals;
  d.DeferredReady = false;
  vtkOpenGLRenderWindow* renWin = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  vtkOpenGLCamera* cam = vtkOpenGLCamera::SafeDownCast(ren->GetActiveCamera());
  if (!renWin || !cam || !vol || !vol->GetProperty())
  {
    d.Fail("needs an OpenGL render window, an OpenGL camera and a volume with a property");
    return;
  }
  // Composite input: every image block through a mapper of its own (vtkSpaceSkipBlockRenderer).
  if (this->GetNumberOfInputConnections(0) > 0 && this->GetInputAlgorithm())
  {
    this->GetInputAlgorithm()->Update();
  }
  vtkDataObject* input = this->GetInputDataObject(0, 0);
  if (vtkSpaceSkipBlockRenderer::IsComposite(input))
  {
    std::string problem;
    if (d.Blocks.Render(this, input, ren, vol, d.Warn, problem))
    {
      d.LastProblem.clear();
    }
    else
    {
      d.Fail(problem);
    }
    return;
  }
  if (d.Blocks.IsActive())
  {
    d.Blocks.ReleaseGraphicsResources(renWin);
    d.Blocks.Clear();
  }
  if (input && input->IsA("vtkRectilinearGrid"))
  {
    d.Fail("vtkRectilinearGrid input is not drawn: vtkSpaceSkippingVolumeMapper draws "
           "vtkImageData (resample the grid to an image first, e.g. vtkResampleToImage)");
    return;
  }
  // Input conversion, first half: what to draw, or why nothing.
  if (!d.SelectInput(vol))
  {
    return;
  }
  const auto tRender = std::chrono::steady_clock::now();
  d.RangeSeconds = d.UpdateSeconds = d.DepthSeconds = d.EngineSeconds = d.CompositeSeconds = 0;
  if (!d.UpdateEngine())
  {
    return;
  }
  try
  {
    // Only what changed reaches the engine: the volume (and its scalar range), the transfer
    // function, the build and render parameters.
    spaceskip::Engine& engine = *d.Engine;
    d.RangeSeconds = d.Input.Update(engine, d.Warn);
    // A piece of a larger image (MPI): the whole image's lattice and scalar range. A block of a
    // composite input uses the range of all blocks (vtkSpaceSkipBlockRenderer).
    d.LastPiece = PieceOf(vtkImageData::SafeDownCast(this->GetInput()), this->WholeExtent,
      this->UseBlockOwned ? this->BlockOwned : nullptr, this->UseBlockOwned || this->ExactPiece,
      d.Tuning.pieceBias, d.Warn);
    engine.setPiece(d.LastPiece);
    const double* range = this->UseTableRange ? this->TableRange
      : this->WholeScalarRange[0] <= this->WholeScalarRange[1] ? this->WholeScalarRange
                                                               : d.Input.GetScalarRange();
    d.Properties.UpdateTransferFunction(engine, vol->GetProperty(), range,
      d.Input.GetOpacityRange(), d.Input.GetOpacityComponent());
    d.Properties.UpdateParameters(
      engine, this, this->EffectiveBlendMode(), ren, vol, range, d.Warn);
    const spaceskip::Camera camera = vtkSpaceSkipPropertyTranslator::ToCamera(ren, cam, vol);

    int width, height, x0, y0;
    ren->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
    if (width <= 0 || height <= 0)
    {
      return;
    }
    d.RenderFrame(renWin, vtkSpaceSkipCompositor::SceneHasDepth(ren), camera, x0, y0, width, height);
    if (this->DeferDraw)
    {
      // A block of a composite input: the block renderer composites the float images.
      d.DeferredReady = true;
      d.MapperSeconds = SecondsSince(tRender);
      d.LastProblem.clear();
      return;
    }
    if (!d.Composite(renWin, vtkImageData::SafeDownCast(this->GetInput()), camera, width, height))
    {
      return;
    }
    d.MapperSeconds = SecondsSince(tRender);
    d.LastProblem.clear();
  }
  catch (const std::exception& e)
  {
    d.Fail(std::string("SpaceSkip engine error: ") + e.what() + ": nothing drawn");
  }
}

//------------------------------------------------------------------------------
int vtkSpaceSkippingVolumeMapper::FillInputPortInformation(int port, vtkInformation* info)
{
  this->Superclass::FillInputPortInformation(port, info);
  // vtkMultiBlockDataSet, vtkPartitionedDataSet, vtkPartitionedDataSetCollection.
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataObjectTree");
  return 1;
}

//------------------------------------------------------------------------------
double* vtkSpaceSkippingVolumeMapper::GetBounds()
{
  // Exchanging pieces, every process must draw every frame: its volume reports the whole
  // image's bounds, so that no renderer culls a piece that is out of view (or empty) while the
  // others wait for it.
  bool blocks = false;
  if (this->Internals->Exchange && IsPiece(this, this->WholeExtent, blocks) &&
    vtkMath::AreBoundsInitialized(this->Internals->WholeBounds))
  {
    std::copy(this->Internals->WholeBounds, this->Internals->WholeBounds + 6, this->Bounds);
    return this->Bounds;
  }
  if (this->GetNumberOfInputConnections(0) == 0 ||
    !vtkSpaceSkipBlockRenderer::IsComposite(this->GetInputDataObject(0, 0)))
  {
    return this->Superclass::GetBounds();
  }
  this->Update();
  vtkSpaceSkipBlockRenderer::ComputeBounds(this->GetInputDataObject(0, 0), this->Bounds);
  return this->Bounds;
}

//------------------------------------------------------------------------------
vtkDataSet* vtkSpaceSkippingVolumeMapper::GetInput()
{
  vtkDataObject* input =
    this->GetNumberOfInputConnections(0) > 0 ? this->GetInputDataObject(0, 0) : nullptr;
  vtkDataSet* data = vtkSpaceSkipBlockRenderer::IsComposite(input)
    ? vtkSpaceSkipBlockRenderer::FirstImage(input)
    : this->Superclass::GetInput();
  bool blocks = false;
  if (!this->Internals->Exchange || !IsPiece(this, this->WholeExtent, blocks))
  {
    return data;
  }
  // Exchanging pieces, a process with an empty piece must still draw every frame (the others
  // wait for it), and ParaView's vtkPVLODVolume draws a mapper only when GetInput() has the
  // selected scalars: an empty image with an empty array of that name stands in.
  int unused = 0;
  if (data && vtkAbstractMapper::GetScalars(data, this->ScalarMode, this->ArrayAccessMode,
                this->ArrayId, this->ArrayName, unused))
  {
    return data;
  }
  vtkInternals& d = *this->Internals;
  const std::string name = this->ArrayName ? this->ArrayName : "";
  if (!d.EmptyPiece || d.EmptyPieceArray != name)
  {
    d.EmptyPiece = vtkSmartPointer<vtkImageData>::New();
    for (vtkDataSetAttributes* attributes : { static_cast<vtkDataSetAttributes*>(d.EmptyPiece->GetPointData()),
           static_cast<vtkDataSetAttributes*>(d.EmptyPiece->GetCellData()) })
    {
      for (int i = 0; i <= std::max(this->ArrayId, 0) && i < 16; ++i)
      {
        vtkNew<vtkFloatArray> array;
        array->SetName(i == 0 && !name.empty() ? name.c_str() : ("empty piece " + std::to_string(i)).c_str());
        attributes->AddArray(array);
      }
      attributes->SetActiveScalars(attributes->GetAbstractArray(0)->GetName());
    }
    d.EmptyPieceArray = name;
  }
  return d.EmptyPiece;
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::SetBinCount(int bins)
{
  // 0 is the sweep; 1 (no candidate plane) would make the engine throw, so it clamps to 2.
  const int v = bins <= 0 ? 0 : std::min(std::max(bins, 2), 64);
  if (v != this->BinCount)
  {
    this->BinCount = v;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Builder: " << this->GetBuilderAsString() << "\n";
  os << indent << "LeafCriterion: " << (this->LeafCriterion == Shallow ? "Shallow" : "Deep")
     << "\n";
  os << indent << "MaxLeafSize: " << this->MaxLeafSize << "\n";
  os << indent << "BinCount: " << this->BinCount << "\n";
  os << indent << "MacroCellSize: " << this->MacroCellSize << "\n";
  os << indent << "SampleDistance: " << this->SampleDistance << "\n";
  os << indent << "Backend: "
     << (this->Backend == Auto ? "Auto" : (this->Backend == CPU ? "CPU" : "CUDA")) << "\n";
  os << indent << "FilterMode: " << this->GetFilterModeAsString() << "\n";
  os << indent << "EarlyRayTermination: " << (this->EarlyRayTermination ? "On" : "Off") << "\n";
  os << indent << "EightBitComposite: " << (this->EightBitComposite ? "On" : "Off") << "\n";
  os << indent << "GPUComposite: " << (this->GPUComposite ? "On" : "Off") << "\n";
  os << indent << "CompositePathUsed: " << this->Internals->Compositor.GetCompositePath() << "\n";
  os << indent << "CompositeBlendUsed: " << this->Internals->Compositor.GetBlendPath() << "\n";
  os << indent << "UseJittering: " << (this->UseJittering ? "On" : "Off") << "\n";
  os << indent << "DeviceMemoryBudget: " << this->DeviceMemoryBudget << " MiB\n";
  os << indent << "VectorMode: " << this->VectorMode << "\n";
  os << indent << "VectorComponent: " << this->VectorComponent << "\n";
  os << indent << "BlendModeOverride: " << this->BlendModeOverride << "\n";
  os << indent << "BackendUsed: " << this->Internals->BackendUsed << "\n";
  os << indent << "BuilderUsed: " << this->Internals->BuilderUsed << "\n";
  os << indent << "LastBuildSeconds: " << this->GetLastBuildSeconds() << "\n";
  os << indent << "LastRenderSeconds: " << this->GetLastRenderSeconds() << "\n";
  os << indent << "NodeCount: " << this->GetNodeCount() << "\n";
  os << indent << "TreeHeight: " << this->GetTreeHeight() << "\n";
  os << indent << "LeafCount: " << this->GetLeafCount() << "\n";
  os << indent << "BuildCount: " << this->GetBuildCount() << "\n";
  os << indent << "ClassifyCount: " << this->GetClassifyCount() << "\n";
  os << indent << "ColorUpdateCount: " << this->GetColorUpdateCount() << "\n";
}
