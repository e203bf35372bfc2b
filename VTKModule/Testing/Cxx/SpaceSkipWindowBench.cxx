// Window benchmark: vtkSpaceSkippingVolumeMapper (every builder) and VTK's
// vtkGPUVolumeRayCastMapper in one 1024x1024 vtkRenderWindow on a generated volume, the paper's
// protocol (orthographic camera zoomed to the volume, rotating, no early ray termination, no
// shading). Per builder: the wall time of renderWindow->Render() (+ glFinish) split into the
// mapper's parts, the first frame's parts, and the time from an opacity edit that changes the
// occupied cells to the end of the first new frame (with its engine update, kernel, builds and
// builder), and of the frame after it (where Auto rebuilds the structure a stand-in drew the
// edit's frame with). Run by bench/device/run-vtk.sh.
//
//   spaceskip_window_bench --shape nbody|menger|... --dims N [--frames F] [--size S]
//       [--builders Naive,Grid,LBVH,...[:shallow|:deep|:mlsN|:brickN|:hw|:exact|:full|:float|:glblend|:segN|:batchN|:noscatter]]
//       [--vtk-gpu]
//       [--edits E (4)] [--edit-cut C (the edits move the ramp's zero between 10% and C of the
//        range: 0.3 by default, which changes N-body's occupied cells; 0.2 does not, as its
//        particles start at 25% of the range)]
//       [--csv FILE] [--filter hw|exact (the mapper's FilterMode for every item without :hw or
//        :exact; default exact)]
//       [--egl] [--png PREFIX (the last timed frame of each item)] [--float-composite] [--ert]
//       [--host-composite (GPUComposite off)] [--blend composite|mip|minip|average|additive]
//       [--shade (gradient shading, VTK's default headlight and material)]
//       [--scatter B,R,G (volumetric scattering: VolumetricScatteringBlending B, GlobalIlluminationReach
//        R and ScatteringAnisotropy G on both mappers; implies --shade)]
//       [--depth-actor (an opaque point actor outside the volume: the mapper reads the window's
//        depth as with geometry in the scene; without it a volume-only scene skips the readback)]
//       [--time-series STEPS [--steps-held K (4)] [--step-type uint8|float32] (playback, issue 38:
//        K time steps of the shape (Generators.h generateTimeStep; N-body advected) held in host
//        memory, STEPS played cycling over them, each step a new scalar array of the image as a
//        reader hands ParaView the next step, the frame at the orbit's next angle waited for; per
//        item, then for vtkGPUVolumeRayCastMapper with --vtk-gpu (--vtk-gpu-steps M of them, default
//        STEPS: its steps can take seconds): steps/s and ms a step, in place of the orbit and edit
//        timings; ours per item in each of --step-modes (default all four, comma-separated):
//        pageable (the steps in ordinary arrays, uploaded when shown), pageable+prefetch (the next
//        step given to PrefetchTimeStep before each frame), step (the steps in the mapper's
//        NewTimeStepArray memory), step+prefetch)]
// The mapper's knobs (spaceskip::Tuning) come from the environment (Core/cli/Environment.h,
// docs/tuning.md), and item suffixes set some of them for one item, for measuring the frame
// around the kernel in one process: :full Tuning::compositeFull (copy and blend the whole window,
// not the volume's rectangle), :float the mapper's EightBitComposite off (a float texture),
// :glblend Tuning::cudaBlend off (the image copied into a texture that GL draws, instead of
// blended by CUDA into the window's framebuffer), :segN Tuning::raySegments = N (rays cut into N
// segments; 1: whole rays), :batchN Tuning::sampleBatch = N (samples a GPU march fetches
// together; 1: one at a time). Columns render_ms and finish_ms split the frame into the time in Render() and
// the wait in glFinish() after it. stream_ms / stream_fps: the same orbit rendered back to back
// with one glFinish() at the end (throughput; frame_ms is the latency of one waited-for frame).
// edit_cut_ms / edit_back_ms split edit_ms into the edits that raise the threshold to
// --edit-cut (they empty bricks) and those that lower it back (they occupy bricks).
// --egl: a vtkGenericOpenGLRenderWindow on an EGL pbuffer context (libEGL.so.1, e.g. NVIDIA's
// headless EGL) instead of an X window: Debian's VTK has no EGL window (SpaceSkipEglWindow.h makes
// one; GLEW's GLX part still wants an X display, Xvfb).
#include "vtkCamera.h"
#include "vtkColorTransferFunction.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPNGWriter.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkUnsignedCharArray.h"
#include "vtkFloatArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWindowToImageFilter.h"
#include "vtkActor.h"
#include "vtkCellArray.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkSpaceSkipOpenGL.h"
#include "SpaceSkipEglWindow.h"

#include "cli/Environment.h"
#include "spaceskip/Generators.h"
#include "spaceskip/Tuning.h"


#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace
{
using Clock = std::chrono::steady_clock;

// The window's current RGBA frame.
vtkSmartPointer<vtkImageData> Grab(vtkRenderWindow* win)
{
  vtkNew<vtkWindowToImageFilter> w2i;
  w2i->SetInput(win);
  w2i->ReadFrontBufferOff();
  w2i->ShouldRerenderOff();
  w2i->Update();
  auto img = vtkSmartPointer<vtkImageData>::New();
  img->DeepCopy(w2i->GetOutput());
  return img;
}

int MaxDiff(vtkImageData* a, vtkImageData* b)
{
  vtkDataArray* x = a->GetPointData()->GetScalars();
  vtkDataArray* y = b->GetPointData()->GetScalars();
  if (!x || !y || x->GetNumberOfValues() != y->GetNumberOfValues())
  {
    return 256;
  }
  const auto* p = static_cast<const unsigned char*>(x->GetVoidPointer(0));
  const auto* q = static_cast<const unsigned char*>(y->GetVoidPointer(0));
  int m = 0;
  for (vtkIdType i = 0; i < x->GetNumberOfValues(); ++i)
  {
    m = std::max(m, std::abs(int(p[i]) - int(q[i])));
  }
  return m;
}

// The window's last frame as PNG (evidence of what the timed frames showed).
void SavePng(vtkRenderWindow* win, const std::string& path)
{
  vtkNew<vtkWindowToImageFilter> w2i;
  w2i->SetInput(win);
  w2i->ReadFrontBufferOff();
  w2i->ShouldRerenderOff();
  w2i->Update();
  vtkNew<vtkPNGWriter> png;
  png->SetFileName(path.c_str());
  png->SetInputConnection(w2i->GetOutputPort());
  png->Write();
}
double Since(Clock::time_point t0)
{
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::vector<std::string> Split(const std::string& s, char c)
{
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, c))
  {
    if (!item.empty())
    {
      out.push_back(item);
    }
  }
  return out;
}

// Render and wait for the GL work: the frame as the user sees it. `inRender` (if given) gets
// the part spent in Render(), the rest being the wait in glFinish().
double TimedRender(vtkRenderWindow* win, double* inRender = nullptr)
{
  const auto t0 = Clock::now();
  win->Render();
  if (inRender)
  {
    *inRender = Since(t0);
  }
  glFinish();
  return Since(t0);
}

// The CLI's "ramp" preset (Core/src/TransferFunction.cpp): opacity 0 below 10% of the range.
// `cut` moves that threshold (an opacity edit that changes the occupied cells).
void SetRamp(vtkColorTransferFunction* ctf, vtkPiecewiseFunction* pwf, double lo, double hi,
  double cut = 0.1)
{
  auto at = [&](double f) { return lo + f * (hi - lo); };
  ctf->RemoveAllPoints();
  ctf->AddRGBPoint(at(0.0), 0.2, 0.3, 0.9);
  ctf->AddRGBPoint(at(cut), 0.2, 0.3, 0.9);
  ctf->AddRGBPoint(at(0.5), 0.9, 0.8, 0.3);
  ctf->AddRGBPoint(at(1.0), 1.0, 0.2, 0.1);
  pwf->RemoveAllPoints();
  pwf->AddPoint(at(0.0), 0.0);
  pwf->AddPoint(at(cut), 0.0);
  pwf->AddPoint(at(0.5), 0.3);
  pwf->AddPoint(at(1.0), 0.9);
}

struct Item
{
  std::string label;
  int builder = vtkSpaceSkippingVolumeMapper::Grid;
  int leaf = vtkSpaceSkippingVolumeMapper::Deep;
  int mls = 0;
  int brick = 8;
  int filter = -1; ///< vtkSpaceSkippingVolumeMapper::FilterModeTypes; -1: --filter's
  bool full = false; ///< Tuning::compositeFull
  bool floatComposite = false;
  bool glBlend = false; ///< Tuning::cudaBlend off
  int segments = 0;     ///< Tuning::raySegments (0: the environment's)
  int batch = 0;        ///< Tuning::sampleBatch (0: the environment's)
  bool noScatter = false; ///< without --scatter's scattering (shading only): the ratio in one run
};

bool ParseItem(const std::string& spec, Item& it)
{
  static const char* names[] = { "Naive", "Grid", "LBVH", "LBVHCPU", "KdTreeCPU", "KdTreeGPU",
    "KdTreeGPUFast", "Hybrid", "DistanceGrid", "Auto" };
  const std::vector<std::string> parts = Split(spec, ':');
  if (parts.empty())
  {
    return false;
  }
  it.label = spec;
  it.builder = -1;
  for (int i = 0; i < 10; ++i)
  {
    if (parts[0] == names[i])
    {
      it.builder = i;
    }
  }
  for (size_t i = 1; i < parts.size(); ++i)
  {
    if (parts[i] == "shallow")
    {
      it.leaf = vtkSpaceSkippingVolumeMapper::Shallow;
    }
    else if (parts[i] == "deep")
    {
      it.leaf = vtkSpaceSkippingVolumeMapper::Deep;
    }
    else if (parts[i].rfind("mls", 0) == 0)
    {
      it.mls = std::atoi(parts[i].c_str() + 3);
    }
    else if (parts[i].rfind("brick", 0) == 0)
    {
      it.brick = std::atoi(parts[i].c_str() + 5);
    }
    else if (parts[i] == "hw")
    {
      it.filter = vtkSpaceSkippingVolumeMapper::HardwareFilter;
    }
    else if (parts[i] == "exact")
    {
      it.filter = vtkSpaceSkippingVolumeMapper::ExactFilter;
    }
    else if (parts[i] == "full")
    {
      it.full = true;
    }
    else if (parts[i] == "float")
    {
      it.floatComposite = true;
    }
    else if (parts[i] == "glblend")
    {
      it.glBlend = true;
    }
    else if (parts[i].rfind("seg", 0) == 0 && parts[i].size() > 3)
    {
      it.segments = std::atoi(parts[i].c_str() + 3);
    }
    else if (parts[i] == "noscatter")
    {
      it.noScatter = true;
    }
    else if (parts[i].rfind("batch", 0) == 0 && parts[i].size() > 5)
    {
      it.batch = std::atoi(parts[i].c_str() + 5);
    }
    else
    {
      return false;
    }
  }
  return it.builder >= 0;
}

// Orbit like the CLI's bench (Core/src/Camera.cpp orbitCamera): azimuth 360*f/frames,
// elevation 15 degrees, orthographic with half-height = the bounding sphere's radius.
void Orbit(vtkRenderer* ren, const double b[6], double az, double el)
{
  const double c[3] = { (b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2 };
  const double dx = b[1] - b[0], dy = b[3] - b[2], dz = b[5] - b[4];
  const double r = 0.5 * std::sqrt(dx * dx + dy * dy + dz * dz);
  const double a = az * M_PI / 180, e = el * M_PI / 180;
  const double dir[3] = { std::sin(a) * std::cos(e), std::sin(e), std::cos(a) * std::cos(e) };
  vtkCamera* cam = ren->GetActiveCamera();
  cam->ParallelProjectionOn();
  cam->SetFocalPoint(c);
  cam->SetPosition(c[0] + 3 * r * dir[0], c[1] + 3 * r * dir[1], c[2] + 3 * r * dir[2]);
  cam->SetViewUp(0, 1, 0);
  cam->SetParallelScale(r);
  cam->SetClippingRange(3 * r - 1.01 * r, 3 * r + 1.01 * r);
}

// The same orbit as the timed frames, back to back with one glFinish() at the end: frames in
// flight overlap (the host queues frame f+1 while the GPU still draws frame f), as when a user
// drags the camera. Seconds for all `frames`: the throughput, where TimedRender gives latency.
double StreamedRender(vtkRenderWindow* win, vtkRenderer* ren, const double b[6], int frames)
{
  glFinish();
  const auto t0 = Clock::now();
  for (int f = 0; f < frames; ++f)
  {
    Orbit(ren, b, 360.0 * f / frames, 15);
    win->Render();
  }
  glFinish();
  return Since(t0);
}

// The voxels of `v` as a VTK array, without a copy (v keeps the storage).
vtkSmartPointer<vtkDataArray> WrapVoxels(const spaceskip::Volume& v)
{
  const auto count = static_cast<vtkIdType>(v.voxelCount());
  if (v.type == spaceskip::VoxelType::Float32)
  {
    auto a = vtkSmartPointer<vtkFloatArray>::New();
    a->SetArray(static_cast<float*>(const_cast<void*>(v.data)), count, 1);
    a->SetName("scalars");
    return a;
  }
  auto a = vtkSmartPointer<vtkUnsignedCharArray>::New();
  a->SetArray(static_cast<unsigned char*>(const_cast<void*>(v.data)), count, 1);
  a->SetName("scalars");
  return a;
}

double Median(std::vector<double> x)
{
  if (x.empty())
  {
    return 0;
  }
  std::sort(x.begin(), x.end());
  const size_t m = x.size() / 2;
  return x.size() % 2 ? x[m] : 0.5 * (x[m - 1] + x[m]);
}

// Plays `played` time steps on the volume's current mapper, cycling over `arrays`: per step the
// image's scalars are replaced (a new array of the same shape, as a reader hands over the next
// step) and the frame at the orbit's next angle is rendered and waited for. Milliseconds a step;
// `update` and `range` (if given) get what `ours` reports for each step's engine update (upload,
// brick ranges, classification, build) and scalar-range pass.
std::vector<double> PlaySteps(vtkRenderWindow* win, vtkRenderer* ren, vtkImageData* image,
  const std::vector<vtkSmartPointer<vtkDataArray>>& arrays, const double b[6], int played,
  vtkSpaceSkippingVolumeMapper* ours = nullptr, std::vector<double>* update = nullptr,
  std::vector<double>* range = nullptr, bool prefetch = false)
{
  std::vector<double> ms;
  for (int i = 1; i <= played; ++i)
  {
    Orbit(ren, b, 360.0 * i / played, 15);
    const auto t0 = Clock::now();
    image->GetPointData()->SetScalars(arrays[static_cast<size_t>(i) % arrays.size()]);
    if (ours && prefetch)
    {
      ours->PrefetchTimeStep(arrays[static_cast<size_t>(i + 1) % arrays.size()]);
    }
    win->Render();
    glFinish();
    ms.push_back(1e3 * Since(t0));
    if (ours && update && range)
    {
      update->push_back(1e3 * ours->GetLastUpdateSeconds());
      range->push_back(1e3 * ours->GetLastScalarRangeSeconds());
    }
  }
  return ms;
}

// VTK's own GPU ray caster for the same window: same property, sample distance half a voxel
// (ours), no automatic adjustment, --scatter's blending and reach. It has no switch for early ray
// termination.
vtkSmartPointer<vtkGPUVolumeRayCastMapper> NewVtkGpuMapper(
  vtkImageData* image, int blend, const float scatter[3])
{
  auto gpu = vtkSmartPointer<vtkGPUVolumeRayCastMapper>::New();
  gpu->SetInputData(image);
  gpu->AutoAdjustSampleDistancesOff();
  gpu->SetSampleDistance(0.5);
  gpu->SetBlendMode(blend);
  gpu->SetVolumetricScatteringBlending(scatter[0]);
  gpu->SetGlobalIlluminationReach(scatter[1]);
  return gpu;
}

// `out` set to the value that `names` gives `m`; false (printing "unknown <what> <m><hint>")
// where m is none of the names.
bool Named(const std::string& m, std::initializer_list<std::pair<const char*, int>> names, int& out,
  const char* what, const char* hint = "")
{
  for (const auto& n : names)
  {
    if (m == n.first)
    {
      out = n.second;
      return true;
    }
  }
  std::cerr << "unknown " << what << " " << m << hint << "\n";
  return false;
}
} // namespace

int main(int argc, char* argv[])
{
  std::string shape = "nbody", csvPath, pngPrefix, builders =
    "Naive,Grid,LBVH,LBVHCPU,KdTreeCPU:mls32,KdTreeGPUFast:mls32,Hybrid,DistanceGrid,DistanceGrid:brick4";
  int n = 256, frames = 16, size = 1024, edits = 4;
  int timeSeries = 0, stepsHeld = 4, vtkGpuSteps = 0; // --time-series, --steps-held, --vtk-gpu-steps
  std::string stepModes = "pageable,pageable+prefetch,step,step+prefetch"; // --step-modes
  spaceskip::VoxelType stepType = spaceskip::VoxelType::UInt8;
  double editCut = 0.3;
  bool vtkGpu = false, egl = false, floatComposite = false, ert = false, hostComposite = false;
  bool shade = false, depthActor = false;
  float scatter[3] = { 0.f, 0.f, 0.f }; // --scatter: blending, reach, anisotropy
  int blend = vtkVolumeMapper::COMPOSITE_BLEND;
  int filter = vtkSpaceSkippingVolumeMapper::ExactFilter;
  // The on/off options.
  const std::pair<const char*, bool*> flags[] = { { "--vtk-gpu", &vtkGpu }, { "--egl", &egl },
    { "--float-composite", &floatComposite }, { "--ert", &ert }, { "--host-composite", &hostComposite },
    { "--shade", &shade }, { "--depth-actor", &depthActor } };
  auto Flag = [&](const std::string& a) -> bool* {
    for (const auto& f : flags)
    {
      if (a == f.first)
      {
        return f.second;
      }
    }
    return nullptr;
  };
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    auto next = [&]() { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (a == "--shape")
      shape = next();
    else if (a == "--dims")
      n = std::atoi(next().c_str());
    else if (a == "--frames")
      frames = std::max(1, std::atoi(next().c_str()));
    else if (a == "--size")
      size = std::atoi(next().c_str());
    else if (a == "--builders")
      builders = next();
    else if (a == "--edits")
      edits = std::max(0, std::atoi(next().c_str()));
    else if (a == "--edit-cut")
      editCut = std::atof(next().c_str());
    else if (bool* flag = Flag(a))
      *flag = true;
    else if (a == "--blend")
    {
      if (!Named(next(),
            { { "composite", vtkVolumeMapper::COMPOSITE_BLEND },
              { "mip", vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND },
              { "minip", vtkVolumeMapper::MINIMUM_INTENSITY_BLEND },
              { "average", vtkVolumeMapper::AVERAGE_INTENSITY_BLEND },
              { "additive", vtkVolumeMapper::ADDITIVE_BLEND } },
            blend, "blend mode"))
      {
        return 2;
      }
    }
    else if (a == "--filter")
    {
      if (!Named(next(),
            { { "hw", vtkSpaceSkippingVolumeMapper::HardwareFilter },
              { "hardware", vtkSpaceSkippingVolumeMapper::HardwareFilter },
              { "exact", vtkSpaceSkippingVolumeMapper::ExactFilter } },
            filter, "filter", " (hw or exact)"))
      {
        return 2;
      }
    }
    else if (a == "--scatter")
    {
      if (std::sscanf(next().c_str(), "%f,%f,%f", &scatter[0], &scatter[1], &scatter[2]) != 3)
      {
        std::cerr << "--scatter takes B,R,G (blending, reach, anisotropy)\n";
        return 2;
      }
      shade = true;
    }
    else if (a == "--time-series")
      timeSeries = std::max(1, std::atoi(next().c_str()));
    else if (a == "--vtk-gpu-steps")
      vtkGpuSteps = std::max(1, std::atoi(next().c_str()));
    else if (a == "--step-modes")
      stepModes = next();
    else if (a == "--steps-held")
      stepsHeld = std::max(1, std::atoi(next().c_str()));
    else if (a == "--step-type")
    {
      const std::string t = next();
      if (t == "float32")
        stepType = spaceskip::VoxelType::Float32;
      else if (t != "uint8")
      {
        std::cerr << "--step-type takes uint8 or float32\n";
        return 2;
      }
    }
    else if (a == "--csv")
      csvPath = next();
    else if (a == "--png")
      pngPrefix = next();
    else
    {
      std::cerr << "unknown argument " << a << "\n";
      return 2;
    }
  }
  std::vector<Item> items;
  for (const std::string& s : Split(builders, ','))
  {
    Item it;
    if (!ParseItem(s, it))
    {
      std::cerr << "bad builder item " << s << "\n";
      return 2;
    }
    if (floatComposite)
    {
      it.label += "+float-composite";
    }
    if (ert)
    {
      it.label += "+ert";
    }
    if (hostComposite)
    {
      it.label += "+host";
    }
    if (it.filter < 0)
    {
      it.filter = filter;
      if (filter == vtkSpaceSkippingVolumeMapper::HardwareFilter)
      {
        it.label += "+hw";
      }
    }
    items.push_back(it);
  }

  // The volume, generated here (nothing big travels), wrapped without a copy; with
  // --time-series the held steps, the first one shown.
  auto t0 = Clock::now();
  std::vector<spaceskip::Volume> steps;
  std::vector<vtkSmartPointer<vtkDataArray>> stepArrays;
  if (timeSeries > 0)
  {
    for (int k = 0; k < stepsHeld; ++k)
    {
      steps.push_back(spaceskip::generateTimeStep(shape, spaceskip::vec3l{ n, n, n }, k, stepType));
    }
  }
  else
  {
    steps.push_back(spaceskip::generateVolume(shape, spaceskip::vec3l{ n, n, n }));
  }
  for (const spaceskip::Volume& s : steps)
  {
    stepArrays.push_back(WrapVoxels(s));
  }
  const spaceskip::Volume& v = steps[0];
  const double genSeconds = Since(t0);
  vtkNew<vtkImageData> image;
  image->SetDimensions(n, n, n);
  image->SetSpacing(1, 1, 1);
  image->GetPointData()->SetScalars(stepArrays[0]);
  double b[6];
  image->GetBounds(b);
  std::printf("volume %s %d^3 %s generated in %.2f s%s\n", shape.c_str(), n,
    v.type == spaceskip::VoxelType::Float32 ? "float32" : "uint8", genSeconds,
    timeSeries > 0 ? (" (" + std::to_string(stepsHeld) + " time steps)").c_str() : "");

  vtkNew<vtkColorTransferFunction> ctf;
  vtkNew<vtkPiecewiseFunction> pwf;
  // The CLI's range: the voxels' (uint8) min/max.
  double lo = 0, hi = 1;
  v.scalarRange(lo, hi);
  SetRamp(ctf, pwf, lo, hi);
  vtkNew<vtkVolumeProperty> prop;
  prop->SetColor(ctf);
  prop->SetScalarOpacity(pwf);
  prop->SetInterpolationTypeToLinear();
  prop->SetShade(shade ? 1 : 0);
  prop->SetScalarOpacityUnitDistance(1.0);
  prop->SetScatteringAnisotropy(scatter[2]);
  std::printf("blend mode %d, shading %s, scattering blending %g reach %g anisotropy %g\n", blend,
    shade ? "on" : "off", scatter[0], scatter[1], scatter[2]);

  vtkNew<vtkRenderer> ren;
  ren->SetBackground(0, 0, 0);
  vtkSmartPointer<vtkRenderWindow> win;
  if (egl)
  {
    std::string why;
    win = sstest::NewEglWindow(size, size, why);
    if (!win)
    {
      std::fprintf(stderr, "--egl: %s\n", why.c_str());
      return 3;
    }
  }
  else
  {
    win = vtkSmartPointer<vtkRenderWindow>::New();
  }
  win->SetMultiSamples(0);
  win->SetSize(size, size);
  win->AddRenderer(ren);
  Orbit(ren, b, 0, 15);
  win->Render();
  auto* ogl = vtkOpenGLRenderWindow::SafeDownCast(win);
  const char* glr = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const char* glv = reinterpret_cast<const char*>(glGetString(GL_VENDOR));
  std::printf("GL_RENDERER %s | GL_VENDOR %s | %s %dx%d%s\n", glr ? glr : "?", glv ? glv : "?",
    egl ? (std::string(win->GetClassName()) + " on EGL").c_str() : "X window", size, size,
    ogl ? "" : " (not OpenGL?)");

  std::ofstream csv;
  if (!csvPath.empty())
  {
    csv.open(csvPath, std::ios::app);
    csv << "dataset,dims,item,builder_used,backend,frames,frame_ms,fps,mapper_ms,update_ms,depth_ms,"
           "engine_ms,kernel_ms,composite_ms,other_ms,kernel_fps,first_frame_s,build_s,classify_s,"
           "nodes,occupancy,edit_ms,edit_classify_ms,edit_build_ms,edit_update_ms,edit_kernel_ms,"
           "edit_builds,edit_builder,edit_next_ms,render_ms,finish_ms,stream_ms,stream_fps,"
           "edit_cut_ms,edit_back_ms\n";
  }
  const std::string ds = shape + std::to_string(n);

  // The empty window's frame.
  double empty = 0, emptyCall = 0;
  for (int f = 0; f < frames; ++f)
  {
    Orbit(ren, b, 360.0 * f / frames, 15);
    double call = 0;
    empty += TimedRender(win, &call);
    emptyCall += call;
  }
  empty /= frames;
  emptyCall /= frames;
  const double emptyStream = StreamedRender(win, ren, b, frames) / frames;
  std::printf("empty window: %.3f ms/frame (in Render() %.3f ms, glFinish() %.3f ms); streamed "
              "%.3f ms/frame (%.1f fps)\n",
    empty * 1e3, emptyCall * 1e3, (empty - emptyCall) * 1e3, emptyStream * 1e3, 1 / emptyStream);
  if (csv.is_open())
  {
    csv << ds << "," << n << ",empty,,," << frames << "," << empty * 1e3 << "," << 1 / empty
        << std::string(22, ',') << emptyCall * 1e3 << "," << (empty - emptyCall) * 1e3 << ","
        << emptyStream * 1e3 << "," << 1 / emptyStream << ",,\n";
  }

  if (timeSeries == 0)
    std::printf("%-22s %-13s %-5s %8s %7s %8s %8s %8s %8s %8s %8s %8s %8s %9s %8s %8s %8s %9s %7s "
              "%8s %8s %6s %9s %8s %8s %8s %7s %7s %7s %s\n",
    "item", "used", "bk", "frame_ms", "fps", "mapper", "update", "depth", "engine", "kernel",
    "compos", "other", "kern_fps", "first_s", "build_ms", "class_ms", "nodes", "occupancy",
    "edit_ms", "ed_upd", "ed_kern", "ed_bld", "ed_next", "render", "finish", "stream",
    "s_fps", "ed_cut", "ed_back", "ed_used");
  vtkNew<vtkVolume> volume;
  volume->SetProperty(prop);
  ren->AddVolume(volume);
  if (depthActor)
  {
    // One opaque point at a corner of the volume's bounds: a visible non-volume prop, so the
    // mapper reads the depth buffer (vtkSpaceSkipCompositor::SceneHasDepth).
    vtkNew<vtkPoints> pts;
    pts->InsertNextPoint(b[0], b[2], b[4]);
    vtkNew<vtkCellArray> verts;
    const vtkIdType id = 0;
    verts->InsertNextCell(1, &id);
    vtkNew<vtkPolyData> pd;
    pd->SetPoints(pts);
    pd->SetVerts(verts);
    vtkNew<vtkPolyDataMapper> pm;
    pm->SetInputData(pd);
    vtkNew<vtkActor> actor;
    actor->SetMapper(pm);
    ren->AddActor(actor);
    std::printf("depth actor: one opaque point (the mapper reads the window's depth)\n");
  }
  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  mapper->SetInputData(image);
  // The paper's protocol has no early ray termination; --ert turns it on (at 0.99, as VTK's
  // vtkGPUVolumeRayCastMapper always does) for a like-for-like comparison with VTK's mapper.
  mapper->SetEarlyRayTermination(ert);
  mapper->SetEightBitComposite(!floatComposite);
  mapper->SetGPUComposite(!hostComposite);
  mapper->SetBlendMode(blend);
  mapper->SetVolumetricScatteringBlending(scatter[0]);
  mapper->SetGlobalIlluminationReach(scatter[1]);
  std::printf("composite: %s image upload\n", floatComposite ? "32-bit float" : "8-bit");
  volume->SetMapper(mapper);
  const spaceskip::Tuning baseTuning = spaceskip::cli::tuningFromEnvironment();
  // One item's settings on the mapper.
  auto apply = [&](const Item& it) {
    mapper->SetBuilder(it.builder);
    mapper->SetLeafCriterion(it.leaf);
    mapper->SetMaxLeafSize(it.mls);
    mapper->SetMacroCellSize(it.brick);
    mapper->SetFilterMode(it.filter);
    mapper->SetEightBitComposite(!(floatComposite || it.floatComposite));
    spaceskip::Tuning tuning = baseTuning;
    tuning.compositeFull = tuning.compositeFull || it.full;
    tuning.cudaBlend = tuning.cudaBlend && !it.glBlend;
    if (it.segments > 0)
    {
      tuning.raySegments = it.segments;
    }
    if (it.batch > 0)
    {
      tuning.sampleBatch = it.batch;
    }
    mapper->SetTuning(tuning);
    mapper->SetVolumetricScatteringBlending(it.noScatter ? 0.f : scatter[0]);
  };
  // Builder Auto measures its candidates first (one to four frames each): the steady state
  // starts after.
  auto settle = [&]() {
    for (int i = 0; i < 40 && std::string(mapper->GetBuilderChoice()).rfind("Auto: measuring", 0) == 0; ++i)
    {
      TimedRender(win);
    }
  };
  if (timeSeries > 0)
  {
    // Playback: per item, then VTK's mapper in the same window; the same steps and camera path.
    const double stepMiB = double(v.byteSize()) / 1048576.0;
    std::printf("time series: %d steps played over %d held, %.1f MiB a step\n", timeSeries,
      stepsHeld, stepMiB);
    std::printf("%-36s %-13s %-5s %9s %9s %9s %9s %10s %9s %9s %10s\n", "item [step mode]", "used", "bk",
      "first_s", "step_ms", "max_ms", "steps/s", "update_ms", "range_ms", "builds", "prefetched");
    // The same steps in the mapper's time-step memory (NewTimeStepArray), for the step modes.
    std::vector<vtkSmartPointer<vtkDataArray>> stepMemory;
    if (stepModes.find("step") != std::string::npos)
    {
      for (size_t k = 0; k < steps.size(); ++k)
      {
        const int type = stepArrays[k]->GetDataType();
        stepMemory.push_back(vtk::TakeSmartPointer(mapper->NewTimeStepArray(type, 1, stepArrays[k]->GetNumberOfTuples())));
        if (!stepMemory.back())
        {
          return 1;
        }
        std::memcpy(stepMemory.back()->GetVoidPointer(0), steps[k].data, steps[k].byteSize());
        stepMemory.back()->SetName("scalars");
      }
    }
    double oursMs = 0, bestMs = 0; // the first row's and the fastest row's median step
    for (const Item& it : items)
    {
      std::stringstream modes(stepModes);
      for (std::string mode; std::getline(modes, mode, ',');)
      {
        const bool prefetch = mode.find("+prefetch") != std::string::npos;
        const bool inStepMemory = mode.rfind("step", 0) == 0;
        if (!prefetch && mode != "pageable" && mode != "step")
        {
          std::cerr << "unknown step mode " << mode << " (pageable, pageable+prefetch, step, step+prefetch)\n";
          return 1;
        }
        const auto& arrays = inStepMemory ? stepMemory : stepArrays;
        apply(it);
        image->GetPointData()->SetScalars(arrays[0]);
        Orbit(ren, b, 0, 15);
        const double first = TimedRender(win);
        settle();
        const int builds = mapper->GetBuildCount();
        const int fetched = mapper->GetPrefetchedTimeStepCount();
        std::vector<double> update, range;
        const auto t = Clock::now();
        const std::vector<double> ms =
          PlaySteps(win, ren, image, arrays, b, timeSeries, mapper, &update, &range, prefetch);
        const double sec = Since(t);
        const std::string label = it.label + " [" + mode + "]";
        std::printf("%-36s %-13s %-5s %9.3f %9.3f %9.3f %9.2f %10.3f %9.3f %9d %10d\n", label.c_str(),
          mapper->GetBuilderUsed(), mapper->GetBackendUsed(), first, Median(ms),
          *std::max_element(ms.begin(), ms.end()), timeSeries / sec, Median(update), Median(range),
          mapper->GetBuildCount() - builds, mapper->GetPrefetchedTimeStepCount() - fetched);
        std::fflush(stdout);
        if (oursMs == 0)
        {
          oursMs = Median(ms);
        }
        bestMs = bestMs == 0 ? Median(ms) : std::min(bestMs, Median(ms));
      }
    }
    if (vtkGpu)
    {
      auto gpu = NewVtkGpuMapper(image, blend, scatter);
      volume->SetMapper(gpu);
      image->GetPointData()->SetScalars(stepArrays[0]);
      Orbit(ren, b, 0, 15);
      const double first = TimedRender(win);
      TimedRender(win);
      const auto t = Clock::now();
      const int played = vtkGpuSteps > 0 ? vtkGpuSteps : timeSeries;
      const std::vector<double> ms = PlaySteps(win, ren, image, stepArrays, b, played);
      const double sec = Since(t);
      std::printf("%-36s %-13s %-5s %9.3f %9.3f %9.3f %9.2f %10s %9s %9s (%d steps)\n",
        "vtkGPUVolumeRayCast [pageable]", "-", "gl", first, Median(ms), *std::max_element(ms.begin(), ms.end()),
        played / sec, "-", "-", "-", played);
      std::printf("time series: the first row's step is %.2fx faster than vtkGPUVolumeRayCastMapper's "
                  "(median ms a step, same window, steps and camera path); the fastest row's %.2fx\n",
        oursMs > 0 ? Median(ms) / oursMs : 0.0, bestMs > 0 ? Median(ms) / bestMs : 0.0);
      volume->SetMapper(mapper);
    }
    return 0;
  }
  bool firstOfAll = true;
  int imageMismatches = 0; // items whose GPU-path image differs from the host path's by > 1/255
  for (const Item& it : items)
  {
    apply(it);
    Orbit(ren, b, 0, 15);
    const double first = TimedRender(win);
    if (firstOfAll)
    {
      std::printf("first frame (volume not yet seen): %.3f s = scalar range %.3f s + engine "
                  "update %.3f s (upload, brick ranges, classify %.3f s, build %.3f s) + depth %.4f "
                  "s + engine frame %.4f s + composite %.4f s + rest\n",
        first, mapper->GetLastScalarRangeSeconds(), mapper->GetLastUpdateSeconds(),
        mapper->GetLastClassifySeconds(), mapper->GetLastBuildSeconds(),
        mapper->GetLastDepthReadSeconds(), mapper->GetLastEngineRenderSeconds(),
        mapper->GetLastCompositeSeconds());
      firstOfAll = false;
    }
    settle();
    const double buildS = mapper->GetLastBuildSeconds(), classifyS = mapper->GetLastClassifySeconds();
    TimedRender(win); // warm-up of the steady state
    double wall = 0, m = 0, up = 0, dep = 0, eng = 0, ker = 0, comp = 0, call = 0;
    for (int f = 0; f < frames; ++f)
    {
      Orbit(ren, b, 360.0 * f / frames, 15);
      double c = 0;
      wall += TimedRender(win, &c);
      call += c;
      m += mapper->GetLastMapperSeconds();
      up += mapper->GetLastUpdateSeconds();
      dep += mapper->GetLastDepthReadSeconds();
      eng += mapper->GetLastEngineRenderSeconds();
      ker += mapper->GetLastKernelSeconds();
      comp += mapper->GetLastCompositeSeconds();
    }
    const double k = 1e3 / frames;
    const double stream = StreamedRender(win, ren, b, frames);
    const std::string path = mapper->GetCompositePathUsed();
    const std::string blendUsed = mapper->GetCompositeBlendUsed(); // the timed frames' (the check below draws through host memory)
    std::string check;
    if (path == "gpu")
    {
      // The interop image against the host path's, same camera.
      Orbit(ren, b, 0, 15);
      TimedRender(win);
      auto gpuShot = Grab(win);
      mapper->GPUCompositeOff();
      TimedRender(win);
      auto hostShot = Grab(win);
      mapper->GPUCompositeOn();
      const int diff = MaxDiff(gpuShot, hostShot);
      check = ", gpu vs host image max diff " + std::to_string(diff) + "/255";
      if (diff > 1)
      {
        // Lossless means the same picture whichever way it reaches the window: the exit status
        // says so (run-gpu-vtk.sh reports it).
        std::fprintf(stderr, "%s: the GPU path's image differs from the host path's by %d/255\n",
          it.label.c_str(), diff);
        ++imageMismatches;
      }
    }
    std::printf("  %s: image %s%s\n", it.label.c_str(),
      path == "gpu"
        ? (std::string("on the GPU (CUDA-GL interop, blended by ") + blendUsed + ")").c_str()
        : "through host memory",
      check.c_str());
    if (!pngPrefix.empty())
    {
      std::string name = it.label;
      std::replace(name.begin(), name.end(), ':', '_');
      SavePng(win, pngPrefix + "-" + ds + "-" + name + ".png");
    }
    // Opacity edits that move the threshold (changing the occupied cells) and back: edit ->
    // end of the first new frame, with the classification and rebuild it needed (the engine's
    // update), its kernel, the builds and the builder it drew with; then the frame after it.
    double edit = 0, editClassify = 0, editBuild = 0, editUpdate = 0, editKernel = 0, editNext = 0;
    double editCutS = 0, editBack = 0; // the edits to --edit-cut (bricks emptied) and back to 0.1
    int editBuilds = 0;
    std::string editBuilder;
    for (int e = 0; e < edits; ++e)
    {
      SetRamp(ctf, pwf, lo, hi, e % 2 == 0 ? editCut : 0.1);
      const int builds = mapper->GetBuildCount();
      const double te = TimedRender(win);
      edit += te;
      (e % 2 == 0 ? editCutS : editBack) += te;
      editBuilds += mapper->GetBuildCount() - builds;
      editClassify += mapper->GetLastClassifySeconds();
      editBuild += mapper->GetLastBuildSeconds();
      editUpdate += mapper->GetLastUpdateSeconds();
      editKernel += mapper->GetLastKernelSeconds();
      const std::string used = mapper->GetBuilderUsed();
      if (editBuilder.find(used) == std::string::npos)
      {
        editBuilder += (editBuilder.empty() ? "" : "+") + used;
      }
      editNext += TimedRender(win);
    }
    if (edits % 2 == 1)
    {
      SetRamp(ctf, pwf, lo, hi, 0.1);
      TimedRender(win);
    }
    const double ke = edits > 0 ? 1e3 / edits : 0;
    const int cuts = (edits + 1) / 2, backs = edits / 2;
    std::printf("%-22s %-13s %-5s %8.3f %7.1f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.1f %9.3f "
                "%8.3f %8.3f %8lld %9.5f %7.3f %8.3f %8.3f %6.2f %9.3f %8.3f %8.3f %8.3f %7.1f %7.3f "
                "%7.3f %s\n",
      it.label.c_str(), mapper->GetBuilderUsed(), mapper->GetBackendUsed(), wall * k,
      frames / wall, m * k, up * k, dep * k, eng * k, ker * k, comp * k, (wall - m) * k,
      frames / ker, first, buildS * 1e3, classifyS * 1e3, static_cast<long long>(mapper->GetNodeCount()),
      mapper->GetOccupancy(), edit * ke, editUpdate * ke, editKernel * ke,
      edits > 0 ? double(editBuilds) / edits : 0.0, editNext * ke, call * k, (wall - call) * k,
      stream * k, frames / stream, cuts ? editCutS * 1e3 / cuts : 0.0,
      backs ? editBack * 1e3 / backs : 0.0, editBuilder.c_str());
    std::fflush(stdout);
    if (csv.is_open())
    {
      csv << ds << "," << n << "," << it.label << "," << mapper->GetBuilderUsed() << ","
          << mapper->GetBackendUsed() << "," << frames << "," << wall * k << "," << frames / wall
          << "," << m * k << "," << up * k << "," << dep * k << "," << eng * k << "," << ker * k
          << "," << comp * k << "," << (wall - m) * k << "," << frames / ker << "," << first << ","
          << buildS << "," << classifyS << "," << mapper->GetNodeCount() << ","
          << mapper->GetOccupancy() << "," << edit * ke << "," << editClassify * ke << ","
          << editBuild * ke << "," << editUpdate * ke << "," << editKernel * ke << ","
          << (edits > 0 ? double(editBuilds) / edits : 0.0) << "," << editBuilder << ","
          << editNext * ke << "," << call * k << "," << (wall - call) * k << "," << stream * k
          << "," << frames / stream << "," << (cuts ? editCutS * 1e3 / cuts : 0.0) << ","
          << (backs ? editBack * 1e3 / backs : 0.0) << "\n";
    }
  }

  mapper->SetTuning(baseTuning);
  if (vtkGpu)
  {
    auto gpu = NewVtkGpuMapper(image, blend, scatter);
    volume->SetMapper(gpu);
    Orbit(ren, b, 0, 15);
    const double first = TimedRender(win);
    TimedRender(win);
    double wall = 0;
    for (int f = 0; f < frames; ++f)
    {
      Orbit(ren, b, 360.0 * f / frames, 15);
      wall += TimedRender(win);
    }
    const double gpuStream = StreamedRender(win, ren, b, frames);
    if (!pngPrefix.empty())
    {
      SavePng(win, pngPrefix + "-" + ds + "-vtkGPUVolumeRayCastMapper.png");
    }
    double edit = 0;
    for (int e = 0; e < edits; ++e)
    {
      SetRamp(ctf, pwf, lo, hi, e % 2 == 0 ? editCut : 0.1);
      edit += TimedRender(win);
    }
    std::printf("%-22s %-13s %-5s %8.3f %7.1f %62s %9.3f %44s %7.3f (streamed %.3f ms/frame, "
                "%.1f fps)\n",
      "vtkGPUVolumeRayCast", "-", "gl", wall * 1e3 / frames, frames / wall, "", first, "",
      edits ? edit * 1e3 / edits : 0.0, gpuStream * 1e3 / frames, frames / gpuStream);
    if (csv.is_open())
    {
      csv << ds << "," << n << ",vtkGPUVolumeRayCastMapper,,gl," << frames << ","
          << wall * 1e3 / frames << "," << frames / wall << ",,,,,,,,," << first << ",,,,,"
          << (edits ? edit * 1e3 / edits : 0.0) << ",,,,,,,,," << gpuStream * 1e3 / frames << ","
          << frames / gpuStream << ",,\n";
    }
    volume->SetMapper(mapper);
  }
  return imageMismatches ? 3 : 0;
}
