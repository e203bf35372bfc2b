// Window benchmark: vtkSpaceSkippingVolumeMapper (every builder) and VTK's
// vtkGPUVolumeRayCastMapper in one 1024x1024 vtkRenderWindow on a generated volume, the paper's
// protocol (orthographic camera zoomed to the volume, rotating, no early ray termination, no
// shading). Per builder: the wall time of renderWindow->Render() (+ glFinish) split into the
// mapper's parts, the first frame's parts, and the time from an opacity edit that changes the
// occupied cells to the end of the first new frame. Run by Testing/gpu/run-gpu-vtk.sh.
//
//   spaceskip_window_bench --shape nbody|menger|... --dims N [--frames F] [--size S]
//       [--builders Naive,Grid,LBVH,...[:shallow|:deep|:mlsN|:brickN]] [--vtk-gpu] [--csv FILE]
#include "vtkCamera.h"
#include "vtkColorTransferFunction.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtk_glew.h"

#include "spaceskip/Generators.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace
{
using Clock = std::chrono::steady_clock;
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

// Render and wait for the GL work: the frame as the user sees it.
double TimedRender(vtkRenderWindow* win)
{
  const auto t0 = Clock::now();
  win->Render();
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
};

bool ParseItem(const std::string& spec, Item& it)
{
  static const char* names[] = { "Naive", "Grid", "LBVH", "LBVHCPU", "KdTreeCPU", "KdTreeGPU",
    "KdTreeGPUFast", "Hybrid", "DistanceGrid" };
  const std::vector<std::string> parts = Split(spec, ':');
  if (parts.empty())
  {
    return false;
  }
  it.label = spec;
  it.builder = -1;
  for (int i = 0; i < 9; ++i)
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
} // namespace

int main(int argc, char* argv[])
{
  std::string shape = "nbody", csvPath, builders =
    "Naive,Grid,LBVH,LBVHCPU,KdTreeCPU:mls32,KdTreeGPUFast:mls32,Hybrid,DistanceGrid,DistanceGrid:brick4";
  int n = 256, frames = 16, size = 1024, edits = 4;
  bool vtkGpu = false;
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
    else if (a == "--vtk-gpu")
      vtkGpu = true;
    else if (a == "--csv")
      csvPath = next();
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
    items.push_back(it);
  }

  // The volume, generated here (nothing big travels), wrapped without a copy.
  auto t0 = Clock::now();
  spaceskip::Volume v = spaceskip::generateVolume(shape, spaceskip::vec3l{ n, n, n });
  const double genSeconds = Since(t0);
  vtkNew<vtkUnsignedCharArray> voxels;
  voxels->SetName("scalars");
  voxels->SetArray(static_cast<unsigned char*>(const_cast<void*>(v.data)),
    static_cast<vtkIdType>(v.voxelCount()), 1);
  vtkNew<vtkImageData> image;
  image->SetDimensions(n, n, n);
  image->SetSpacing(1, 1, 1);
  image->GetPointData()->SetScalars(voxels);
  double b[6];
  image->GetBounds(b);
  std::printf("volume %s %d^3 uint8 generated in %.2f s\n", shape.c_str(), n, genSeconds);

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
  prop->ShadeOff();
  prop->SetScalarOpacityUnitDistance(1.0);

  vtkNew<vtkRenderer> ren;
  ren->SetBackground(0, 0, 0);
  vtkNew<vtkRenderWindow> win;
  win->SetMultiSamples(0);
  win->SetSize(size, size);
  win->AddRenderer(ren);
  Orbit(ren, b, 0, 15);
  win->Render();
  auto* ogl = vtkOpenGLRenderWindow::SafeDownCast(win);
  const char* glr = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const char* glv = reinterpret_cast<const char*>(glGetString(GL_VENDOR));
  std::printf("GL_RENDERER %s | GL_VENDOR %s | window %dx%d%s\n", glr ? glr : "?",
    glv ? glv : "?", size, size, ogl ? "" : " (not OpenGL?)");

  std::ofstream csv;
  if (!csvPath.empty())
  {
    csv.open(csvPath, std::ios::app);
    csv << "dataset,dims,item,builder_used,backend,frames,frame_ms,fps,mapper_ms,update_ms,depth_ms,"
           "engine_ms,kernel_ms,composite_ms,other_ms,kernel_fps,first_frame_s,build_s,classify_s,"
           "nodes,occupancy,edit_ms,edit_classify_ms,edit_build_ms\n";
  }
  const std::string ds = shape + std::to_string(n);

  // The empty window's frame.
  double empty = 0;
  for (int f = 0; f < frames; ++f)
  {
    Orbit(ren, b, 360.0 * f / frames, 15);
    empty += TimedRender(win);
  }
  empty /= frames;
  std::printf("empty window: %.3f ms/frame\n", empty * 1e3);
  if (csv.is_open())
  {
    csv << ds << "," << n << ",empty,,," << frames << "," << empty * 1e3 << "," << 1 / empty
        << ",,,,,,,,,,,,,,,,\n";
  }

  std::printf("%-22s %-13s %-5s %8s %7s %8s %8s %8s %8s %8s %8s %8s %8s %9s %8s %8s %8s %9s %7s\n",
    "item", "used", "bk", "frame_ms", "fps", "mapper", "update", "depth", "engine", "kernel",
    "compos", "other", "kern_fps", "first_s", "build_ms", "class_ms", "nodes", "occupancy",
    "edit_ms");
  vtkNew<vtkVolume> volume;
  volume->SetProperty(prop);
  ren->AddVolume(volume);
  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  mapper->SetInputData(image);
  mapper->EarlyRayTerminationOff();
  volume->SetMapper(mapper);
  bool firstOfAll = true;
  for (const Item& it : items)
  {
    mapper->SetBuilder(it.builder);
    mapper->SetLeafCriterion(it.leaf);
    mapper->SetMaxLeafSize(it.mls);
    mapper->SetMacroCellSize(it.brick);
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
    const double buildS = mapper->GetLastBuildSeconds(), classifyS = mapper->GetLastClassifySeconds();
    TimedRender(win); // warm-up of the steady state
    double wall = 0, m = 0, up = 0, dep = 0, eng = 0, ker = 0, comp = 0;
    for (int f = 0; f < frames; ++f)
    {
      Orbit(ren, b, 360.0 * f / frames, 15);
      wall += TimedRender(win);
      m += mapper->GetLastMapperSeconds();
      up += mapper->GetLastUpdateSeconds();
      dep += mapper->GetLastDepthReadSeconds();
      eng += mapper->GetLastEngineRenderSeconds();
      ker += mapper->GetLastKernelSeconds();
      comp += mapper->GetLastCompositeSeconds();
    }
    const double k = 1e3 / frames;
    // Opacity edits that move the threshold (changing the occupied cells) and back: edit ->
    // end of the first new frame, with the classification and rebuild it needed.
    double edit = 0, editClassify = 0, editBuild = 0;
    for (int e = 0; e < edits; ++e)
    {
      SetRamp(ctf, pwf, lo, hi, e % 2 == 0 ? 0.2 : 0.1);
      edit += TimedRender(win);
      editClassify += mapper->GetLastClassifySeconds();
      editBuild += mapper->GetLastBuildSeconds();
    }
    if (edits % 2 == 1)
    {
      SetRamp(ctf, pwf, lo, hi, 0.1);
      TimedRender(win);
    }
    const double ke = edits > 0 ? 1e3 / edits : 0;
    std::printf("%-22s %-13s %-5s %8.3f %7.1f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.1f %9.3f "
                "%8.3f %8.3f %8lld %9.5f %7.3f\n",
      it.label.c_str(), mapper->GetBuilderUsed(), mapper->GetBackendUsed(), wall * k,
      frames / wall, m * k, up * k, dep * k, eng * k, ker * k, comp * k, (wall - m) * k,
      frames / ker, first, buildS * 1e3, classifyS * 1e3, static_cast<long long>(mapper->GetNodeCount()),
      mapper->GetOccupancy(), edit * ke);
    std::fflush(stdout);
    if (csv.is_open())
    {
      csv << ds << "," << n << "," << it.label << "," << mapper->GetBuilderUsed() << ","
          << mapper->GetBackendUsed() << "," << frames << "," << wall * k << "," << frames / wall
          << "," << m * k << "," << up * k << "," << dep * k << "," << eng * k << "," << ker * k
          << "," << comp * k << "," << (wall - m) * k << "," << frames / ker << "," << first << ","
          << buildS << "," << classifyS << "," << mapper->GetNodeCount() << ","
          << mapper->GetOccupancy() << "," << edit * ke << "," << editClassify * ke << ","
          << editBuild * ke << "\n";
    }
  }

  if (vtkGpu)
  {
    // VTK's own GPU ray caster in the same window: same property, sample distance half a voxel
    // (ours), no automatic adjustment. It has no switch for early ray termination.
    vtkNew<vtkGPUVolumeRayCastMapper> gpu;
    gpu->SetInputData(image);
    gpu->AutoAdjustSampleDistancesOff();
    gpu->SetSampleDistance(0.5);
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
    double edit = 0;
    for (int e = 0; e < edits; ++e)
    {
      SetRamp(ctf, pwf, lo, hi, e % 2 == 0 ? 0.2 : 0.1);
      edit += TimedRender(win);
    }
    std::printf("%-22s %-13s %-5s %8.3f %7.1f %62s %9.3f %44s %7.3f\n", "vtkGPUVolumeRayCast", "-",
      "gl", wall * 1e3 / frames, frames / wall, "", first, "", edits ? edit * 1e3 / edits : 0.0);
    if (csv.is_open())
    {
      csv << ds << "," << n << ",vtkGPUVolumeRayCastMapper,,gl," << frames << ","
          << wall * 1e3 / frames << "," << frames / wall << ",,,,,,,,," << first << ",,,,,"
          << (edits ? edit * 1e3 / edits : 0.0) << ",,\n";
    }
    volume->SetMapper(mapper);
  }
  return 0;
}
