// vtkSpaceSkippingVolumeMapper: VTK types -> spaceskip::Engine, and the engine's image -> the
// window. Render() is the sequence of steps; the work is in vtkSpaceSkipInputConverter (the
// input -> a Core Volume), vtkSpaceSkipPropertyTranslator (property, settings, lights, camera ->
// Core parameters) and vtkSpaceSkipCompositor (depth readback, upload or interop, blending).
// Composite input goes to the vtkSpaceSkipMultiBlockVolumeMapper this mapper owns.
#include "vtkSpaceSkippingVolumeMapper.h"

#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkLogger.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLCamera.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkRectilinearGrid.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkipCompositor.h"
#include "vtkSpaceSkipImageRenderer.h"
#include "vtkSpaceSkipInputConverter.h"
#include "vtkSpaceSkipMultiBlockVolumeMapper.h"
#include "vtkSpaceSkipPieceCompositing.h"
#include "vtkSpaceSkipPropertyTranslator.h"
#include "vtkSpaceSkipSettings.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "spaceskip/Backend.h"
#include "spaceskip/DeviceImageCopy.h"
#include "spaceskip/Engine.h"
#include "spaceskip/PeerImages.h"
#include "spaceskip/StepMemory.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <set>
#include <string>

// BuilderTypes and FilterModeTypes are cast to Core's enums: they must stay in the same order.
static_assert(static_cast<int>(spaceskip::BuilderKind::Hybrid) == vtkSpaceSkippingVolumeMapper::Hybrid &&
    static_cast<int>(spaceskip::BuilderKind::DistanceGrid) == vtkSpaceSkippingVolumeMapper::DistanceGrid,
  "vtkSpaceSkippingVolumeMapper::BuilderTypes out of step with spaceskip::BuilderKind");
static_assert(static_cast<int>(spaceskip::FilterMode::Hardware) == vtkSpaceSkippingVolumeMapper::HardwareFilter,
  "vtkSpaceSkippingVolumeMapper::FilterModeTypes out of step with spaceskip::FilterMode");

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
    r.Backend = v == "cpu" || v == "CPU" ? vtkSpaceSkippingVolumeMapper::CPU
      : v == "cuda" || v == "CUDA"       ? vtkSpaceSkippingVolumeMapper::CUDA
      : v == "auto" || v == "Auto"       ? vtkSpaceSkippingVolumeMapper::Auto
                                         : -1;
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

double SecondsSince(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

#define vtkStatisticGetterMacro(type, name, field, deviceTimes)                                    \
  type vtkSpaceSkippingVolumeMapper::Get##name() { return this->Internals->Statistics(deviceTimes).field; }

bool IsComposite(vtkDataObject* input)
{
  return vtkCompositeDataSet::SafeDownCast(input) != nullptr;
}

bool HasExtent(const int e[6])
{
  return e[0] <= e[1] && e[2] <= e[3] && e[4] <= e[5];
}

} // namespace

struct vtkSpaceSkippingVolumeMapper::vtkInternals
{
  explicit vtkInternals(vtkSpaceSkippingVolumeMapper* self)
    : Self(self)
    , Warn([self](const std::string& m) { self->WarnOnce(m); })
    , Image(this->Warn, [this](const std::string& m) { this->Fail(m); },
        // The engine's steps as the algorithm's progress (ParaView's progress bar): the text
        // names the step, the fraction runs over the update and frame together.
        [self](double fraction, const char* step) {
          const std::string text = std::string("Space Skipping Volume: ") + step;
          if (!self->GetProgressText() || text != self->GetProgressText())
          {
            self->SetProgressText(text.c_str());
          }
          self->UpdateProgress(fraction);
        })
  {
    this->Image.SetReport(Overrides().Report);
  }

  vtkSpaceSkippingVolumeMapper* Self;
  // The mapper's WarnOnce, for the engine and the helpers below.
  const std::function<void(const std::string&)> Warn;
  // One message per distinct problem, not one per frame.
  std::string LastProblem;
  // Warnings (engine fallbacks, clamps) already said by this mapper: each cause once, also
  // across the engines that backend switches create.
  std::set<std::string> Said;
  spaceskip::Tuning Tuning; // SetTuning
  vtkSpaceSkipLabelEdits LabelEdits; // SetLabelColor, SetLabelOpacity, SetLabelVisibility
  vtkSpaceSkipStatistics Asked; // the last statistics asked for (the getters' strings live here)

  // Float compositing across processes (SetPieceExchange), and the image it hands back.
  std::shared_ptr<vtkSpaceSkipPieceExchange> Exchange;
  double WholeBounds[6] = { 1, -1, 1, -1, 1, -1 };
  double WholeGridSteps[3] = { 0, 0, 0 };
  // GetInput() of a process with an empty piece (see there), and the array name it carries.
  vtkSmartPointer<vtkImageData> EmptyPiece;
  std::string EmptyPieceArray;
  spaceskip::Image Exchanged;
  // Pieces in device memory (the exchange's DevicePieces): this process's frame shared with the
  // others of the host and theirs mapped (CUDA IPC), and their blend on this GPU.
  spaceskip::PeerImages Peers;
  spaceskip::PieceBlend DeviceBlend;
  // This process's piece as the exchange takes it (DevicePieces): shared, and downloaded too.
  void ShareDevicePiece(int how, PieceImage& piece);
  // A `width` x `height` float4 image in device memory into Exchanged (host memory) and drawn;
  // when it cannot be read back, said and nothing drawn (true: no shader failure).
  bool DrawFromDevice(const void* image, int width, int height, vtkOpenGLRenderWindow* renWin,
    bool eightBit, const char* what);
  // The exchanged pieces blended (on the GPU where this process's piece is there, else on the
  // host) and drawn; the exchange Released() once they are read. `where`: "GPU" or "host".
  bool DrawPieces(PieceExchange& exchange, std::vector<PieceImage>& pieces, const double eye[3],
    const double dir[3], bool parallel, int width, int height, double stopAt,
    vtkOpenGLRenderWindow* renWin, bool eightBit, const char*& where);
  // Image input: the engine and the window (vtkSpaceSkipImageRenderer); composite input: the
  // composite mapper that draws it with one mapper per image block (vtkBlock).
  vtkSpaceSkipImageRenderer Image;
  vtkSmartPointer<vtkSpaceSkipMultiBlockVolumeMapper> Composite;
  // vtkRectilinearGrid input as the image drawn (vtkSpaceSkipInputConverter.h).
  vtkSpaceSkipRectilinearImage Rectilinear;
  // How a frame is drawn: a block of composite input (set by vtkBlock) or a piece for the
  // exchange keeps its float image, with the table range of all blocks and its own cells.
  vtkSpaceSkipImageRenderer::FrameMode Mode;
  vtkSmartPointer<vtkDataArray> NextTimeStep; // PrefetchTimeStep, for the next RenderImage
  double TableRange[2] = { 0, 1 };
  int Owned[6] = { 0, 0, 0, 0, 0, 0 };

  // CudaDevice: the device this mapper's engine was bound to (-1: not yet) and its report.
  int BoundDevice = -1;
  int AskedDevice = -1;
  std::string DeviceReport;
  std::string PieceReport = "none"; // vtkSpaceSkipStatistics::PieceCompositing of the last frame
  bool DrewPieces = false;           // the last frame drew the exchanged pieces' sum (DrawPieces)
  void BindDevice(int asked, int backend);

  // Reports a problem once (until the next different one); the caller then draws nothing.
  void Fail(const std::string& msg)
  {
    if (msg != this->LastProblem)
    {
      vtkErrorWithObjectMacro(this->Self, << msg);
      this->LastProblem = msg;
    }
  }

  // Interactive sampling (InteractiveAdjustSampleDistances): the last two frames' sample
  // distances and seconds (newest first), which predict the time of the next interactive frame.
  struct FrameTime
  {
    double Distance = 0, Seconds = 0;
  };
  FrameTime Frames[2];
  double FrameSampleDistance(vtkRenderer* ren, vtkVolume* vol, vtkImageData* image, double still, bool piece);
  void FrameDrawn(double seconds, double distance, vtkImageData* image);

  /// Whether a non-uniform rectilinear grid is drawn through its coordinates
  /// (vtkSpaceSkipRectilinearImage path 4): drawn alone (no pieces composited across
  /// processes), one drawn component (a component or the magnitude of several, not dependent
  /// components), linear interpolation, no label map, no second array as the 2-D transfer
  /// function's y axis. Else it is resampled, as before.
  bool ThroughCoordinates(vtkVolume* vol, vtkRectilinearGrid* grid)
  {
    vtkSpaceSkippingVolumeMapper* self = this->Self;
    vtkVolumeProperty* prop = vol ? vol->GetProperty() : nullptr;
    if (!prop || this->Exchange || self->GetLabelMap() || self->GetTransfer2DYAxisArray() ||
      prop->GetInterpolationType() != VTK_LINEAR_INTERPOLATION)
    {
      return false;
    }
    int cellFlag = 0;
    vtkDataArray* scalars = vtkAbstractMapper::GetScalars(
      grid, self->ScalarMode, self->ArrayAccessMode, self->ArrayId, self->ArrayName, cellFlag);
    return scalars && cellFlag == 0 &&
      (scalars->GetNumberOfComponents() == 1 || prop->GetIndependentComponents() != 0);
  }
  void RenderImage(vtkRenderer* ren, vtkVolume* vol, vtkOpenGLRenderWindow* renWin, vtkOpenGLCamera* cam,
    vtkImageData* input, bool resampled);
  void RenderComposite(vtkRenderer* ren, vtkVolume* vol, vtkDataObject* input);
  vtkSpaceSkipMultiBlockVolumeMapper* CompositeMapper();
  const vtkSpaceSkipStatistics& Statistics(bool deviceTimes)
  {
    this->Asked = this->Composite ? this->Composite->GetStatistics(deviceTimes)
                                  : this->Image.Statistics(deviceTimes);
    if (!this->Composite)
    {
      const bool cuda = this->Asked.BackendUsed.find("cuda") != std::string::npos;
      if (cuda && this->DeviceReport.empty())
      {
        int used = -1, count = 0; // CudaDevice -1: the thread's current device, as it is
        std::string problem;
        if (vtkSpaceSkipCompositor::BindCudaDevice(-1, used, count, problem))
        {
          this->DeviceReport = "device " + std::to_string(used) + " of " + std::to_string(count);
        }
      }
      this->Asked.CudaDevice = cuda && !this->DeviceReport.empty() ? this->DeviceReport : "none";
    }
    this->Asked.PieceCompositing = this->PieceReport;
    if (this->Composite && this->DrewPieces)
    {
      // The blocks' pieces were drawn as one sum, through this mapper's compositor.
      this->Asked.CompositePath = this->Image.GetCompositor().GetCompositePath();
      this->Asked.CompositeBlend = this->Image.GetCompositor().GetBlendPath();
    }
    return this->Asked;
  }
};

// A block of composite input as the composite mapper drives it: a mapper of this class.
struct vtkSpaceSkippingVolumeMapper::vtkBlock : public vtkSpaceSkipMultiBlockVolumeMapper::BlockMapper
{
  vtkNew<vtkSpaceSkippingVolumeMapper> Mapper;
  vtkInternals& D = *this->Mapper->Internals;

  // The composite mapper's owner picks the blocks' sample distance (one for all of them).
  vtkBlock() { this->Mapper->InteractiveAdjustSampleDistancesOff(); }
  void SetInput(vtkImageData* image) override
  {
    if (this->Mapper->GetInputDataObject(0, 0) != image)
    {
      this->Mapper->SetInputData(image);
    }
  }
  void Configure(const vtkSpaceSkipSettings& s, bool padded, const double range[2],
    const int* whole, const int* owned) override
  {
    s.ApplyTo(this->Mapper.GetPointer(), padded);
    const int none[6] = { 0, -1, 0, -1, 0, -1 };
    this->Mapper->SetWholeExtent(whole ? whole : none);
    std::copy_n(range, 2, this->D.TableRange);
    std::copy_n(owned ? owned : none, 6, this->D.Owned);
    this->D.Mode.TableRange = this->D.TableRange;
    this->D.Mode.Owned = owned ? this->D.Owned : nullptr;
    this->D.Mode.Defer = true;
  }
  const float* Render(vtkRenderer* ren, vtkVolume* vol, const float* incomingAlpha, int& width,
    int& height) override
  {
    this->D.Mode.IncomingAlpha = incomingAlpha;
    this->Mapper->Render(ren, vol);
    this->D.Mode.IncomingAlpha = nullptr;
    return this->D.Image.DeferredImage(width, height);
  }
  vtkSpaceSkipStatistics GetStatistics(bool deviceTimes) override
  {
    return this->D.Statistics(deviceTimes);
  }
  void ReleaseGraphicsResources(vtkWindow* win) override
  {
    this->Mapper->ReleaseGraphicsResources(win);
  }
};

//------------------------------------------------------------------------------
namespace
{
double SmallestSpacing(vtkImageData* image)
{
  double smallest = 0;
  for (int a = 0; image && a < 3; ++a)
  {
    const double h = std::abs(image->GetSpacing()[a]);
    smallest = std::isfinite(h) && h > 0 && (smallest == 0 || h < smallest) ? h : smallest;
  }
  return smallest;
}
}

// The sample distance of this frame: `still` (SampleDistance; 0: the engine's half smallest
// spacing) in still renders, and in interactive ones whose frame at `still` would be fast (a
// quarter of the volume's allocated render time or less: ParaView allocates 1/5 s among its
// renderers, e.g. on a GPU). Otherwise at least one smallest spacing (where
// vtkGPUVolumeRayCastMapper steps while dragged) and, if that does not fit the allocated time,
// farther, up to 8 smallest spacings. A frame's time is modelled as fixed + work / distance,
// fitted to the last two frames where their distances differ (else all work): the distance that
// fits the allocated time, or where the fixed part alone nearly fills it, the one at which
// sampling takes a quarter of the fixed part (farther would gain under 20 %). A piece of a larger
// image keeps `still` (no process's own timing may give it another distance than the others').
double vtkSpaceSkippingVolumeMapper::vtkInternals::FrameSampleDistance(
  vtkRenderer* ren, vtkVolume* vol, vtkImageData* image, double still, bool piece)
{
  vtkSpaceSkippingVolumeMapper* self = this->Self;
  vtkRenderWindow* w = ren ? ren->GetRenderWindow() : nullptr;
  const double rate = w ? w->GetDesiredUpdateRate() : 0.0;
  const double smallest = SmallestSpacing(image);
  self->LastRenderInteractive =
    self->InteractiveAdjustSampleDistances && rate >= self->InteractiveUpdateRate && smallest > 0;
  const FrameTime& a = this->Frames[0];
  const FrameTime& b = this->Frames[1];
  if (!self->LastRenderInteractive || piece || !(a.Seconds > 0 && a.Distance > 0))
  {
    return still;
  }
  const double base = still > 0 ? still : 0.5 * smallest;
  const double allocated = vol->GetAllocatedRenderTime();
  const double budget = allocated > 0 ? allocated : 1.0 / rate;
  double work = a.Seconds * a.Distance, fixed = 0;
  if (!std::isfinite(work) || !(work / base > 0.25 * budget))
  {
    return still;
  }
  if (b.Seconds > 0 && b.Distance > 0 && std::abs(a.Distance - b.Distance) > 0.1 * a.Distance)
  {
    const double wk = (a.Seconds - b.Seconds) / (1.0 / a.Distance - 1.0 / b.Distance);
    const double fx = a.Seconds - wk / a.Distance;
    if (std::isfinite(wk) && std::isfinite(fx) && wk > 0 && fx >= 0)
    {
      work = wk;
      fixed = fx;
    }
  }
  const double d = budget > 1.25 * fixed ? work / (budget - fixed) : work / (0.25 * fixed);
  return std::clamp(d, std::max(base, smallest), std::max(base, 8.0 * smallest));
}

void vtkSpaceSkippingVolumeMapper::vtkInternals::FrameDrawn(double seconds, double distance, vtkImageData* image)
{
  this->Frames[1] = this->Frames[0];
  this->Frames[0].Seconds = seconds;
  this->Frames[0].Distance = distance > 0 ? distance : 0.5 * SmallestSpacing(image);
  this->Self->LastRequestedSampleDistance = distance;
}

//------------------------------------------------------------------------------
// One image through vtkSpaceSkipImageRenderer; SPACESKIP_BACKEND overrides the backend.
void vtkSpaceSkippingVolumeMapper::vtkInternals::RenderImage(vtkRenderer* ren, vtkVolume* vol,
  vtkOpenGLRenderWindow* renWin, vtkOpenGLCamera* cam, vtkImageData* input, bool resampled)
{
  vtkSpaceSkippingVolumeMapper* self = this->Self;
  const auto t0 = std::chrono::steady_clock::now();
  this->Image.ResetFrameTimes();
  vtkSpaceSkipSettings s = vtkSpaceSkipSettings::From(self);
  if (resampled)
  {
    // A resampled grid is not on the lattice of the grid's WholeExtent: a piece of one is on
    // the whole grid's resampling lattice, else it is drawn whole.
    const int none[6] = { 0, -1, 0, -1, 0, -1 };
    const int* lattice = this->Rectilinear.GetPath() == 3 ? this->Rectilinear.GetLatticeWholeExtent() : none;
    std::copy(lattice, lattice + 6, s.WholeExtent);
  }
  s.Backend = Overrides().Backend >= 0 ? Overrides().Backend : s.Backend;
  // A piece of a larger image (ParaView sets WholeExtent serially too: the image's own).
  const bool piece = this->Exchange != nullptr ||
    (s.HasWholeExtent() && input && !std::equal(s.WholeExtent, s.WholeExtent + 6, input->GetExtent()));
  s.SampleDistance = this->FrameSampleDistance(ren, vol, input, s.SampleDistance, piece);
  int cellFlag = 0;
  vtkDataArray* scalars = input ? vtkAbstractMapper::GetScalars(input, self->ScalarMode,
                                    self->ArrayAccessMode, self->ArrayId, self->ArrayName, cellFlag)
                                : nullptr;
  vtkSpaceSkipImageRenderer::FrameMode mode = this->Mode;
  mode.Prefetch = this->NextTimeStep;
  this->NextTimeStep = nullptr; // one Render() each (the converter holds it while it uploads)
  if (this->Image.Render(ren, vol, renWin, cam, input, scalars, cellFlag, s, mode))
  {
    this->Image.SetMapperSeconds(SecondsSince(t0));
    this->FrameDrawn(SecondsSince(t0), s.SampleDistance, input);
    this->LastProblem.clear();
  }
}

//------------------------------------------------------------------------------
// Composite input: every image block through a mapper of its own (the composite mapper).
void vtkSpaceSkippingVolumeMapper::vtkInternals::RenderComposite(
  vtkRenderer* ren, vtkVolume* vol, vtkDataObject* input)
{
  if (this->CompositeMapper()->GetInputDataObject(0, 0) != input)
  {
    this->Composite->SetInputDataObject(input);
  }
  const auto t0 = std::chrono::steady_clock::now();
  vtkSpaceSkipSettings s = vtkSpaceSkipSettings::From(this->Self);
  vtkImageData* first = vtkSpaceSkipMultiBlockVolumeMapper::FirstImage(input);
  s.SampleDistance = this->FrameSampleDistance(ren, vol, first, s.SampleDistance, this->Exchange != nullptr);
  this->Composite->SetSettings(s);
  this->Composite->Render(ren, vol);
  const std::string& problem = this->Composite->GetLastProblem();
  if (problem.empty())
  {
    this->FrameDrawn(SecondsSince(t0), s.SampleDistance, first);
    this->LastProblem.clear();
  }
  else
  {
    this->Fail(problem);
  }
}

//------------------------------------------------------------------------------
vtkSpaceSkipMultiBlockVolumeMapper* vtkSpaceSkippingVolumeMapper::vtkInternals::CompositeMapper()
{
  if (!this->Composite)
  {
    this->Composite = vtkSmartPointer<vtkSpaceSkipMultiBlockVolumeMapper>::New();
    this->Composite->SetBlockFactory([]() { return std::unique_ptr<vtkBlock>(new vtkBlock); });
    this->Composite->SetWarnFunction(this->Warn);
  }
  return this->Composite;
}

vtkStandardNewMacro(vtkSpaceSkippingVolumeMapper);

//------------------------------------------------------------------------------
vtkSpaceSkippingVolumeMapper::vtkSpaceSkippingVolumeMapper()
  : Internals(new vtkInternals(this))
{
}
vtkSpaceSkippingVolumeMapper::~vtkSpaceSkippingVolumeMapper()
{
  this->SetTransfer2DYAxisArray(nullptr);
}

//------------------------------------------------------------------------------
const char* vtkSpaceSkippingVolumeMapper::GetBuilderAsString()
{
  return spaceskip::builderName(static_cast<spaceskip::BuilderKind>(this->Builder));
}

const char* vtkSpaceSkippingVolumeMapper::GetFilterModeAsString()
{
  return this->FilterMode == HardwareFilter ? "Hardware" : "Exact";
}

//------------------------------------------------------------------------------
// Statistics (of the blocks together for composite input: vtkSpaceSkipStatistics::Combine).
vtkStatisticGetterMacro(double, LastBuildSeconds, BuildSeconds, false);
vtkStatisticGetterMacro(double, LastClassifySeconds, ClassifySeconds, false);
vtkStatisticGetterMacro(double, LastRenderSeconds, RenderSeconds, true);
vtkStatisticGetterMacro(double, LastKernelSeconds, KernelSeconds, true);
vtkStatisticGetterMacro(double, LastScalarRangeSeconds, ScalarRangeSeconds, false);
vtkStatisticGetterMacro(double, LastUpdateSeconds, UpdateSeconds, false);
vtkStatisticGetterMacro(double, LastDepthReadSeconds, DepthReadSeconds, false);
vtkStatisticGetterMacro(bool, LastFrameReadDepth, DepthRead, false);
vtkStatisticGetterMacro(double, LastEngineRenderSeconds, EngineRenderSeconds, false);
vtkStatisticGetterMacro(double, LastCompositeSeconds, CompositeSeconds, false);
vtkStatisticGetterMacro(double, LastMapperSeconds, MapperSeconds, false);
vtkStatisticGetterMacro(vtkIdType, NodeCount, Nodes, false);
vtkStatisticGetterMacro(int, TreeHeight, TreeHeight, false);
vtkStatisticGetterMacro(vtkIdType, LeafCount, Leaves, false);
vtkStatisticGetterMacro(double, Occupancy, Occupancy, false);
vtkStatisticGetterMacro(const char*, BackendUsed, BackendUsed.c_str(), false);
vtkStatisticGetterMacro(const char*, BuilderUsed, BuilderUsed.c_str(), false);
vtkStatisticGetterMacro(const char*, CompositePathUsed, CompositePath.c_str(), false);
vtkStatisticGetterMacro(const char*, CompositeBlendUsed, CompositeBlend.c_str(), false);
vtkStatisticGetterMacro(const char*, PieceCompositingUsed, PieceCompositing.c_str(), false);
vtkStatisticGetterMacro(const char*, BuilderChoice, BuilderChoice.c_str(), false);
vtkStatisticGetterMacro(double, SampleDistanceUsed, SampleDistanceUsed, false);
vtkStatisticGetterMacro(const char*, Residency, Residency.c_str(), false);
vtkStatisticGetterMacro(vtkIdType, ResidentBricks, ResidentBricks, false);
vtkStatisticGetterMacro(int, BuildCount, Builds, false);
vtkStatisticGetterMacro(int, ClassifyCount, Classifications, false);
vtkStatisticGetterMacro(int, ColorUpdateCount, ColorUpdates, false);
vtkStatisticGetterMacro(int, FrameCount, Frames, false);
vtkStatisticGetterMacro(int, TimeStepCount, TimeSteps, false);
vtkStatisticGetterMacro(int, PrefetchedTimeStepCount, PrefetchedTimeSteps, false);
vtkStatisticGetterMacro(int, ColorTableSampleCount, ColorTableSamples, false);
vtkStatisticGetterMacro(int, OpacityTableSampleCount, OpacityTableSamples, false);
void vtkSpaceSkippingVolumeMapper::GetLastCompositeRect(int rect[4])
{
  std::copy_n(this->Internals->Statistics(false).CompositeRect, 4, rect);
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

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::ReleaseGraphicsResources(vtkWindow* win)
{
  if (this->Internals->Composite)
  {
    this->Internals->Composite->ReleaseGraphicsResources(win);
  }
  this->Internals->Image.ReleaseGraphicsResources(win);
  this->Superclass::ReleaseGraphicsResources(win);
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::SetTuning(const spaceskip::Tuning& tuning)
{
  this->Internals->Tuning = tuning;
  this->Internals->Image.SetTuning(tuning);
}
const spaceskip::Tuning& vtkSpaceSkippingVolumeMapper::GetTuning() const
{
  return this->Internals->Tuning;
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::SetLabelColor(int id, double r, double g, double b)
{
  vtkSpaceSkipLabelEdit& e = this->Internals->LabelEdits[id];
  if (!e.HasColor || e.Color[0] != r || e.Color[1] != g || e.Color[2] != b)
  {
    e.HasColor = true;
    e.Color[0] = r;
    e.Color[1] = g;
    e.Color[2] = b;
    this->Modified();
  }
}

void vtkSpaceSkippingVolumeMapper::SetLabelOpacity(int id, double opacity)
{
  vtkSpaceSkipLabelEdit& e = this->Internals->LabelEdits[id];
  if (!e.HasOpacity || e.Opacity != opacity)
  {
    e.HasOpacity = true;
    e.Opacity = opacity;
    this->Modified();
  }
}

void vtkSpaceSkippingVolumeMapper::SetLabelVisibility(int id, vtkTypeBool visible)
{
  vtkSpaceSkipLabelEdit& e = this->Internals->LabelEdits[id];
  if (!e.HasVisible || e.Visible != (visible != 0))
  {
    e.HasVisible = true;
    e.Visible = visible != 0;
    this->Modified();
  }
}

void vtkSpaceSkippingVolumeMapper::RemoveLabelVisibility(int id)
{
  auto it = this->Internals->LabelEdits.find(id);
  if (it == this->Internals->LabelEdits.end() || !it->second.HasVisible)
  {
    return;
  }
  it->second.HasVisible = false;
  it->second.Visible = true;
  if (!it->second.HasColor && !it->second.HasOpacity)
  {
    this->Internals->LabelEdits.erase(it);
  }
  this->Modified();
}

void vtkSpaceSkippingVolumeMapper::RemoveAllLabels()
{
  if (!this->Internals->LabelEdits.empty())
  {
    this->Internals->LabelEdits.clear();
    this->Modified();
  }
}

const std::map<int, vtkSpaceSkipLabelEdit>& vtkSpaceSkippingVolumeMapper::GetLabelEdits() const
{
  return this->Internals->LabelEdits;
}

void vtkSpaceSkippingVolumeMapper::SetLabelEdits(const std::map<int, vtkSpaceSkipLabelEdit>& edits)
{
  if (edits != this->Internals->LabelEdits)
  {
    this->Internals->LabelEdits = edits;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
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
void vtkSpaceSkippingVolumeMapper::SetWholeGridSteps(const double steps[3])
{
  if (!std::equal(steps, steps + 3, this->Internals->WholeGridSteps))
  {
    std::copy(steps, steps + 3, this->Internals->WholeGridSteps);
    this->Modified();
  }
}
const std::shared_ptr<vtkSpaceSkippingVolumeMapper::PieceExchange>&
vtkSpaceSkippingVolumeMapper::GetPieceExchange() const
{
  return this->Internals->Exchange;
}

//------------------------------------------------------------------------------
// The rendering thread on the CUDA device (CudaDevice) before the engine allocates on it, and
// again every frame (other code on the thread may switch). The CPU backend: nothing at all.
void vtkSpaceSkippingVolumeMapper::vtkInternals::BindDevice(int asked, int backend)
{
  if (backend == vtkSpaceSkippingVolumeMapper::CPU || (asked < 0 && this->BoundDevice < 0))
  {
    return; // as before: no CUDA call for this
  }
  if (this->BoundDevice >= 0 && asked >= 0 && asked != this->AskedDevice)
  {
    this->Warn("CudaDevice " + std::to_string(asked) + " asked after this mapper's engine was made on CUDA device " +
      std::to_string(this->BoundDevice) + ": it stays there");
  }
  this->AskedDevice = asked;
  int used = -1, count = 0;
  std::string problem;
  if (!vtkSpaceSkipCompositor::BindCudaDevice(this->BoundDevice >= 0 ? this->BoundDevice : asked, used, count, problem))
  {
    return; // no CUDA: the engine finds out and falls back as before
  }
  this->BoundDevice = used;
  this->DeviceReport = "device " + std::to_string(used) + " of " + std::to_string(count);
}

//------------------------------------------------------------------------------
const char* vtkSpaceSkippingVolumeMapper::GetCudaDeviceUsed()
{
  return this->Internals->Statistics(false).CudaDevice.c_str();
}

//------------------------------------------------------------------------------
// With a piece exchange (MPI) and a piece of a larger image, RenderExchanged(); else the input
// drawn here.
void vtkSpaceSkippingVolumeMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  this->Internals->BindDevice(this->CudaDevice, this->Backend);
  if (this->Internals->Exchange && ren && HasExtent(this->WholeExtent))
  {
    this->RenderExchanged(ren, vol);
    return;
  }
  this->RenderLocal(ren, vol);
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::RenderLocal(vtkRenderer* ren, vtkVolume* vol)
{
  vtkInternals& d = *this->Internals;
  d.Image.ResetFrameTimes(); // and no deferred frame until this one is drawn
  vtkOpenGLRenderWindow* renWin = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  vtkOpenGLCamera* cam = vtkOpenGLCamera::SafeDownCast(ren->GetActiveCamera());
  if (!renWin || !cam || !vol || !vol->GetProperty())
  {
    d.Fail("needs an OpenGL render window, an OpenGL camera and a volume with a property");
    return;
  }
  if (this->GetNumberOfInputConnections(0) > 0 && this->GetInputAlgorithm())
  {
    this->GetInputAlgorithm()->Update();
  }
  vtkDataObject* input = this->GetInputDataObject(0, 0);
  if (IsComposite(input))
  {
    d.RenderComposite(ren, vol, input);
    return;
  }
  if (d.Composite)
  {
    d.Composite->ReleaseGraphicsResources(renWin); // back to an image: the blocks go
    d.Composite = nullptr;
  }
  vtkImageData* image = vtkImageData::SafeDownCast(this->GetInput());
  bool resampled = false;
  if (auto* grid = vtkRectilinearGrid::SafeDownCast(input))
  {
    // The grid as an image (its own arrays when uniform, else resampled), made again only
    // when the grid changed.
    // A piece of a larger grid (MPI): resampled on the whole grid's lattice.
    vtkSpaceSkipRectilinearImage::WholeGrid whole;
    std::copy_n(d.WholeBounds, 6, whole.Bounds);
    std::copy_n(d.WholeGridSteps, 3, whole.SmallestStep);
    std::copy_n(this->WholeExtent, 6, whole.Extent);
    std::string problem;
    image = d.Rectilinear.From(grid, d.Warn, problem, &whole, d.ThroughCoordinates(vol, grid));
    if (!image)
    {
      d.Fail(problem);
      return;
    }
    resampled = d.Rectilinear.GetPath() == 2 || d.Rectilinear.GetPath() == 3;
  }
  else if (d.Rectilinear.GetImage())
  {
    d.Rectilinear.Release(); // a grid's image (a resampled copy) is not kept for an image input
  }
  d.Image.SetWarp(d.Rectilinear.GetImage() ? d.Rectilinear.GetWarp() : nullptr);
  d.RenderImage(ren, vol, renWin, cam, image, resampled);
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::vtkInternals::ShareDevicePiece(int how, PieceImage& piece)
{
  std::string problem;
  if (how == 1 || how == 2)
  {
    spaceskip::PeerImages::Handle handle;
    if (this->Peers.share(piece.Device, size_t(piece.Width) * size_t(piece.Height), piece.Stream, handle, problem))
    {
      piece.Shared = true;
      std::copy(handle.begin(), handle.end(), piece.Handle);
    }
    else
    {
      this->Warn("could not share this process's frame with the other processes of the host "
                 "through CUDA IPC (" + problem + "): it goes through host memory");
    }
  }
  if (how != 3 && (how == 2 || !piece.Shared))
  {
    const size_t n = size_t(piece.Width) * size_t(piece.Height);
    piece.Pixels.resize(4 * n);
    if (!spaceskip::PeerImages::download(piece.Device, n, piece.Pixels.data(), problem))
    {
      this->Warn("could not read this process's frame back from the GPU (" + problem + ")");
      piece.Pixels.clear();
      piece.Width = piece.Height = 0;
    }
    if (!piece.Shared)
    {
      piece.Device = nullptr; // host pixels only
    }
  }
}

//------------------------------------------------------------------------------
bool vtkSpaceSkippingVolumeMapper::vtkInternals::DrawFromDevice(const void* image, int width,
  int height, vtkOpenGLRenderWindow* renWin, bool eightBit, const char* what)
{
  std::string problem;
  this->Exchanged.width = width;
  this->Exchanged.height = height;
  this->Exchanged.rgba.resize(size_t(width) * size_t(height));
  if (!spaceskip::PeerImages::download(image, this->Exchanged.rgba.size(), &this->Exchanged.rgba[0].x, problem))
  {
    this->Warn(std::string("could not read ") + what + " back from the GPU (" + problem + "): not drawn");
    return true;
  }
  return this->Image.GetCompositor().Draw(renWin, this->Exchanged, width, height, eightBit);
}

//------------------------------------------------------------------------------
bool vtkSpaceSkippingVolumeMapper::vtkInternals::DrawPieces(PieceExchange& exchange,
  std::vector<PieceImage>& pieces, const double eye[3], const double dir[3], bool parallel,
  int width, int height, double stopAt, vtkOpenGLRenderWindow* renWin, bool eightBit,
  const char*& where)
{
  namespace pc = vtkSpaceSkipPieceCompositing;
  vtkSpaceSkipCompositor& compositor = this->Image.GetCompositor();
  std::string problem;
  bool mapped = true;
  if (std::any_of(pieces.begin(), pieces.end(), [](const PieceImage& p) { return p.Shared; }))
  {
    mapped = pc::MapShared(pieces, this->Peers, problem);
    if (!mapped)
    {
      this->Warn("could not map another process's frame through CUDA IPC (" + problem +
        "): the pieces go through host memory from the next frame on");
    }
  }
  // This process's piece in device memory (its own frame, not another's): blend on this GPU.
  void* stream = nullptr;
  for (const PieceImage& p : pieces)
  {
    stream = p.Device && !p.Shared ? p.Stream : stream;
  }
  where = "host";
  if (stream)
  {
    const void* sum = pc::BlendOnDevice(
      pieces, eye, dir, parallel, width, height, stopAt, this->DeviceBlend, stream, problem);
    if (sum && spaceskip::PeerImages::wait(stream, problem))
    {
      exchange.Released(mapped); // the others' images are read: they may draw the next frame
      where = "GPU";
      const int whole[4] = { 0, 0, width, height };
      const spaceskip::DeviceImageView view{ sum, {} };
      if (compositor.CopyDeviceImage(renWin, view, [sum]() { return sum; }, stream, width, height, whole, eightBit))
      {
        return compositor.Draw(renWin, this->Exchanged, width, height, eightBit);
      }
      // The interop is off (another GPU, Mesa): the sum through host memory.
      return this->DrawFromDevice(sum, width, height, renWin, eightBit, "the blended pieces");
    }
    this->Warn("could not blend the pieces on the GPU (" + problem + "): blended on the host");
  }
  if (!pc::ToHost(pieces, problem))
  {
    this->Warn("could not read a piece back from the GPU (" + problem + "): left out");
  }
  pc::Blend(pieces, eye, dir, parallel, width, height, this->Exchanged, stopAt);
  exchange.Released(mapped);
  return compositor.Draw(renWin, this->Exchanged, width, height, eightBit);
}

//------------------------------------------------------------------------------
// With a piece exchange (MPI): every process draws its piece (or each of its blocks) exactly
// into a float image, the exchange composites them all in float on one process, which draws the
// sum; the others draw nothing. Every call reaches Finish(), whatever the piece drew (the
// others wait for it).
void vtkSpaceSkippingVolumeMapper::RenderExchanged(vtkRenderer* ren, vtkVolume* vol)
{
  namespace pc = vtkSpaceSkipPieceCompositing;
  vtkInternals& d = *this->Internals;
  const std::shared_ptr<PieceExchange> exchange = d.Exchange;
  // The frame's phases, logged at verbosity 5 (pvbatch -v 5): where a composited frame goes.
  const auto t0 = std::chrono::steady_clock::now();
  exchange->Begin();
  const int devicePieces = exchange->DevicePieces();
  std::vector<PieceImage> mine;
  const void* deviceImage = nullptr; // the same, left in device memory
  double eye[3] = { 0, 0, 0 }, dir[3] = { 0, 0, 1 };
  bool parallel = false;
  const float* image = nullptr; // an image piece's own frame (drawn if the exchange is off)
  const bool blocks = IsComposite(this->GetInputDataObject(0, 0));
  if (blocks)
  {
    // The composite mapper leaves its blocks' images (on the whole image's lattice) to us.
    d.CompositeMapper()->SetExchangePieces(&mine);
    this->RenderLocal(ren, vol);
    d.Composite->SetExchangePieces(nullptr);
    d.Composite->ExchangeCamera(ren, vol, eye, dir, parallel);
  }
  else
  {
    const vtkSpaceSkipImageRenderer::FrameMode mode = d.Mode;
    d.Mode.Defer = d.Mode.Exact = true;
    // A CUDA frame stays on the GPU where the exchange takes it there (one host, CUDA IPC).
    d.Mode.OnDevice = devicePieces != 0;
    auto* data = vtkDataSet::SafeDownCast(this->GetInputDataObject(0, 0));
    d.Image.ResetFrameTimes();
    if (data && data->GetNumberOfPoints() > 0)
    {
      this->RenderLocal(ren, vol); // an empty piece draws nothing (and says nothing)
    }
    d.Mode = mode;
    int w = 0, h = 0;
    image = d.Image.DeferredImage(w, h);
    void* stream = nullptr;
    deviceImage = image ? nullptr : d.Image.DeferredDeviceImage(w, h, stream);
    auto* input = vtkImageData::SafeDownCast(this->GetInput());
    if (!input && vtkRectilinearGrid::SafeDownCast(this->GetInputDataObject(0, 0)))
    {
      // A uniform grid's piece is the image of its points, on the grid's index lattice; a
      // non-uniform one is resampled on the whole grid's lattice (path 3) where the whole grid's
      // steps are known, else on a lattice of its own, which the exchange cannot place.
      const int path = d.Rectilinear.GetPath();
      input = path == 1 || path == 3 ? d.Rectilinear.GetImage() : nullptr;
      if (path == 2)
      {
        this->WarnOnce("a vtkRectilinearGrid piece with non-uniform coordinates is not drawn "
                       "when pieces are composited across processes unless the whole grid's "
                       "steps are known (SetWholeGridSteps; ParaView's representation gathers "
                       "them)");
      }
    }
    if ((image || deviceImage) && input && ren->GetActiveCamera())
    {
      const int* whole = vtkImageData::SafeDownCast(this->GetInput()) || d.Rectilinear.GetPath() != 3
        ? this->WholeExtent
        : d.Rectilinear.GetLatticeWholeExtent();
      const int shift[3] = { whole[0], whole[2], whole[4] };
      if (image)
      {
        mine.push_back(pc::CropPiece(image, w, h, d.Image.LastPiece(), input, whole));
      }
      else
      {
        mine.push_back(pc::DevicePiece(deviceImage, stream, w, h, d.Image.LastPiece(), input, whole));
        d.ShareDevicePiece(devicePieces, mine.back());
      }
      pc::CameraInIndexSpace(ren, vol, input, shift, eye, dir, parallel);
    }
    else
    {
      image = nullptr;
      deviceImage = nullptr;
    }
  }
  int width = 0, height = 0, x0 = 0, y0 = 0;
  ren->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
  std::vector<PieceImage> others;
  const double drawnAt = SecondsSince(t0);
  const bool logPhases = vtkLogger::GetCurrentVerbosityCutoff() >= vtkLogger::VERBOSITY_5;
  const vtkSpaceSkipStatistics piece = logPhases ? d.Image.Statistics(true) : vtkSpaceSkipStatistics();
  const int draw = exchange->Finish(width, height, mine, others);
  const double exchangedAt = SecondsSince(t0);
  d.DrewPieces = false;
  d.PieceReport = draw == -1 ? "own frame only"
    : draw == 1              ? "pieces received, not drawn"
    : devicePieces != 0      ? "piece shared through CUDA IPC"
                             : "piece sent as pixels";
  auto phases = [&](const char* end) {
    if (!logPhases)
    {
      return;
    }
    vtkVLogF(vtkLogger::VERBOSITY_5,
      "exchanged frame: piece %.3f ms (update %.3f, depth read %.3f, engine %.3f, kernel %.3f), "
      "exchange %.3f ms, %s %.3f ms",
      1e3 * drawnAt, 1e3 * piece.UpdateSeconds, 1e3 * piece.DepthReadSeconds, 1e3 * piece.EngineRenderSeconds,
      1e3 * piece.KernelSeconds, 1e3 * (exchangedAt - drawnAt), end, 1e3 * (SecondsSince(t0) - exchangedAt));
  };
  auto* renWin = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  if (draw == 0 || !renWin || width <= 0 || height <= 0)
  {
    if (draw == 1)
    {
      exchange->Released(true);
    }
    phases("nothing drawn");
    return;
  }
  const bool eightBit = this->EightBitComposite != 0;
  vtkSpaceSkipCompositor& compositor = d.Image.GetCompositor();
  bool drawn = true;
  if (draw == -1 && blocks) // the exchange is off: this process's own blocks
  {
    drawn = !d.Composite || d.Composite->DrawSum(ren, eightBit);
  }
  else if (draw == -1 && deviceImage) // the exchange is off: this process's frame, from the GPU
  {
    drawn = mine.empty() || mine[0].Width != width || mine[0].Height != height ||
      d.DrawFromDevice(deviceImage, width, height, renWin, eightBit, "this process's frame");
  }
  else if (draw == -1) // the exchange is off: this process's own frame, as without it
  {
    drawn = !image || compositor.Draw(renWin, d.Image.GetImage(), width, height, eightBit);
  }
  else
  {
    // Every piece front to back in the order the rays meet them, blended in float: one
    // rounding to 8 bits, as the serial image.
    // A pixel whose ray stopped early in front pieces takes nothing from those behind it, as
    // the single image's ray (composite and isosurface blending accumulate opacity).
    std::move(mine.begin(), mine.end(), std::back_inserter(others));
    const vtkSpaceSkipSettings s = vtkSpaceSkipSettings::From(this);
    const double stopAt =
      s.AccumulatesOpacity() ? vtkSpaceSkipPropertyTranslator::EarlyTerminationOpacity(s) : 2.0;
    const char* where = "host";
    const auto shared = std::count_if(others.begin(), others.end(), [](const PieceImage& p) { return p.Shared; });
    drawn = d.DrawPieces(*exchange, others, eye, dir, parallel, width, height, stopAt, renWin, eightBit, where);
    d.DrewPieces = true;
    d.PieceReport = std::to_string(others.size()) + " pieces blended on the " + where + ", " +
      std::to_string(shared) + " shared through CUDA IPC";
    if (logPhases)
    {
      vtkVLogF(vtkLogger::VERBOSITY_5, "exchanged frame: blend of %d pieces on the %s",
        static_cast<int>(others.size()), where);
    }
  }
  phases("blend + draw");
  if (!drawn)
  {
    d.Fail("could not compile the compositing shader: nothing drawn");
  }
}

//------------------------------------------------------------------------------
bool vtkSpaceSkippingVolumeMapper::FillRangeCaches(vtkDataArray* array)
{
  return vtkSpaceSkipInputConverter::FillRangeCaches(array);
}

//------------------------------------------------------------------------------
vtkDataArray* vtkSpaceSkippingVolumeMapper::NewTimeStepArray(
  int dataType, int numberOfComponents, vtkIdType numberOfTuples)
{
  if (!vtkSpaceSkipInputConverter::DrawnInPlace(dataType) || numberOfComponents < 1 ||
    numberOfTuples < 0)
  {
    vtkErrorMacro(<< "NewTimeStepArray: no array of type " << dataType << " with "
                  << numberOfComponents << " components and " << numberOfTuples
                  << " tuples is drawn in place (types: unsigned char, char, signed char, "
                     "short, unsigned short, float, double)");
    return nullptr;
  }
  vtkDataArray* a = vtkDataArray::CreateDataArray(dataType);
  a->SetNumberOfComponents(numberOfComponents);
  const vtkIdType values = numberOfTuples * numberOfComponents;
  const size_t bytes = static_cast<size_t>(values) * static_cast<size_t>(a->GetDataTypeSize());
  const int backend = Overrides().Backend >= 0 ? Overrides().Backend : this->Backend;
  void* locked = backend == CPU ? nullptr : spaceskip::allocatePageLockedRaw(bytes);
  if (locked)
  {
    a->SetVoidArray(locked, values, 0, vtkAbstractArray::VTK_DATA_ARRAY_USER_DEFINED);
    a->SetArrayFreeFunction(spaceskip::freePageLocked);
    return a;
  }
  a->SetNumberOfTuples(numberOfTuples);
  if (values > 0 && !a->GetVoidPointer(0))
  {
    vtkErrorMacro(<< "NewTimeStepArray: " << bytes << " bytes cannot be had");
    a->Delete();
    return nullptr;
  }
  return a;
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::PrefetchTimeStep(vtkDataArray* next)
{
  this->Internals->NextTimeStep = next;
}

//------------------------------------------------------------------------------
bool vtkSpaceSkippingVolumeMapper::GetOwnedExtent(vtkImageData* image, int extent[6])
{
  if (!image)
  {
    return false;
  }
  image->GetExtent(extent);
  int cells[6];
  const int found = vtkSpaceSkipInputConverter::UnmarkedCells(image, cells);
  if (found == 1)
  {
    for (int a = 0; a < 3; ++a)
    {
      extent[2 * a] = cells[2 * a];
      extent[2 * a + 1] = std::max(cells[2 * a + 1], cells[2 * a]);
    }
  }
  return found != 0;
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
  const double* whole = this->Internals->WholeBounds;
  if (this->Internals->Exchange && HasExtent(this->WholeExtent) && vtkMath::AreBoundsInitialized(whole))
  {
    std::copy(whole, whole + 6, this->Bounds);
    return this->Bounds;
  }
  if (this->GetNumberOfInputConnections(0) == 0 || !IsComposite(this->GetInputDataObject(0, 0)))
  {
    return this->Superclass::GetBounds();
  }
  this->Update();
  vtkSpaceSkipMultiBlockVolumeMapper::ComputeBounds(this->GetInputDataObject(0, 0), this->Bounds);
  return this->Bounds;
}

//------------------------------------------------------------------------------
vtkDataSet* vtkSpaceSkippingVolumeMapper::GetInput()
{
  vtkDataObject* input =
    this->GetNumberOfInputConnections(0) > 0 ? this->GetInputDataObject(0, 0) : nullptr;
  vtkDataSet* data = IsComposite(input) ? vtkSpaceSkipMultiBlockVolumeMapper::FirstImage(input)
                                        : this->Superclass::GetInput();
  int unused = 0;
  if (!this->Internals->Exchange || !HasExtent(this->WholeExtent) ||
    (data && vtkAbstractMapper::GetScalars(data, this->ScalarMode, this->ArrayAccessMode,
               this->ArrayId, this->ArrayName, unused)))
  {
    return data;
  }
  // Exchanging pieces, a process with an empty piece must still draw every frame (the others
  // wait for it): an empty image with an empty array of the selected name stands in.
  vtkInternals& d = *this->Internals;
  return vtkSpaceSkipPieceCompositing::EmptyPiece(this->ArrayName, this->ArrayId, d.EmptyPiece, d.EmptyPieceArray);
}

//------------------------------------------------------------------------------
// Setters of bounded properties: a value outside [lo, hi] becomes the nearest bound, with one
// warning naming the property, the value and what was used.
namespace
{
template <class T>
T ClampSaid(vtkObject* self, const char* name, T v, T lo, T hi, const char* (*label)(T) = nullptr)
{
  const T used = v < lo ? lo : (v > hi ? hi : v);
  if (used != v)
  {
    vtkWarningWithObjectMacro(self, << name << " " << v << " is outside its domain [" << lo << ", " << hi
                                    << "]: using " << used << (label ? " (" : "") << (label ? label(used) : "")
                                    << (label ? ")" : ""));
  }
  return used;
}
const char* BuilderLabel(int b)
{
  static const char* names[] = { "Naive", "Grid", "LBVH", "LBVHCPU", "KdTreeCPU", "KdTreeGPU", "KdTreeGPUFast",
    "Hybrid", "DistanceGrid", "Auto" };
  return b >= 0 && b < int(sizeof(names) / sizeof(names[0])) ? names[b] : "";
}
const char* BlendOverrideLabel(int m)
{
  static const char* names[] = { "composite", "maximum intensity", "minimum intensity", "average intensity",
    "additive", "isosurface" };
  return m < 0 ? "the volume mapper's BlendMode" : (m < 6 ? names[m] : "");
}
} // namespace

#define vtkSpaceSkipSetClampedMacro(name, type, lo, hi, label)                                    \
  void vtkSpaceSkippingVolumeMapper::Set##name(type v)                                          \
  {                                                                                              \
    const type used = ClampSaid<type>(this, #name, v, lo, hi, label);                            \
    if (used != this->name)                                                                      \
    {                                                                                            \
      this->name = used;                                                                         \
      this->Modified();                                                                          \
    }                                                                                            \
  }
vtkSpaceSkipSetClampedMacro(Builder, int, Naive, AutoBuilder, BuilderLabel)
vtkSpaceSkipSetClampedMacro(LeafCriterion, int, Shallow, Deep, nullptr)
vtkSpaceSkipSetClampedMacro(MaxLeafSize, int, 0, VTK_INT_MAX, nullptr)
vtkSpaceSkipSetClampedMacro(MacroCellSize, int, 1, 64, nullptr)
vtkSpaceSkipSetClampedMacro(Backend, int, Auto, CUDA, nullptr)
vtkSpaceSkipSetClampedMacro(FilterMode, int, ExactFilter, HardwareFilter, nullptr)
vtkSpaceSkipSetClampedMacro(BlendModeOverride, int, -1, vtkVolumeMapper::ISOSURFACE_BLEND, BlendOverrideLabel)
vtkSpaceSkipSetClampedMacro(DeviceMemoryBudget, vtkIdType, 0, VTK_ID_MAX, nullptr)

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::SetSampleDistance(double distance)
{
  // 0 is automatic; negative, NaN or infinite are not distances (the engine took them as 0
  // without a word). Too small or too large finite ones are the engine's to clamp, said once.
  double used = distance;
  if (!(distance >= 0) || !std::isfinite(distance))
  {
    used = 0;
    vtkWarningMacro(<< "SampleDistance " << distance
                    << " is not a non-negative finite distance: using 0 (automatic: half the smallest spacing)");
  }
  if (used != this->SampleDistance)
  {
    this->SampleDistance = used;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::SetBinCount(int bins)
{
  // 0 is the sweep; 1 (no candidate plane) would make the engine throw, so it clamps to 2.
  const int v = bins <= 0 ? 0 : std::min(std::max(bins, 2), 64);
  if (v != bins)
  {
    vtkWarningMacro(<< "BinCount " << bins << " is outside its domain (0, or 2..64): using " << v);
  }
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
  os << indent << "InteractiveAdjustSampleDistances: " << this->InteractiveAdjustSampleDistances << "\n";
  os << indent << "InteractiveUpdateRate: " << this->InteractiveUpdateRate << "\n";
  os << indent << "Backend: "
     << (this->Backend == Auto ? "Auto" : (this->Backend == CPU ? "CPU" : "CUDA")) << "\n";
  os << indent << "FilterMode: " << this->GetFilterModeAsString() << "\n";
  os << indent << "EarlyRayTermination: " << (this->EarlyRayTermination ? "On" : "Off") << "\n";
  os << indent << "EightBitComposite: " << (this->EightBitComposite ? "On" : "Off") << "\n";
  os << indent << "GPUComposite: " << (this->GPUComposite ? "On" : "Off") << "\n";
  os << indent << "UseJittering: " << (this->UseJittering ? "On" : "Off") << "\n";
  os << indent << "GlobalIlluminationReach: " << this->GlobalIlluminationReach << "\n";
  os << indent << "VolumetricScatteringBlending: " << this->VolumetricScatteringBlending << "\n";
  os << indent << "DeviceMemoryBudget: " << this->DeviceMemoryBudget << " MiB\n";
  os << indent << "VectorMode: " << this->VectorMode << "\n";
  os << indent << "VectorComponent: " << this->VectorComponent << "\n";
  os << indent << "Transfer2DYAxisArray: "
     << (this->Transfer2DYAxisArray ? this->Transfer2DYAxisArray : "(none)") << "\n";
  os << indent << "Transfer2DYAxisComponent: " << this->Transfer2DYAxisComponent << "\n";
  os << indent << "BlendModeOverride: " << this->BlendModeOverride << "\n";
  this->Internals->Statistics(true).Print(os, indent);
}
