// Soak: what a long ParaView session does to the mapper. 1000 transfer-function edits (opacity
// and colour, alternating) each followed by a render, then 200 builder/backend switches with a
// tiny Sample Distance, through the VTK mapper in a window. Checks that host memory does not
// grow (RSS <= 1 MB after a warm-up), that every frame still draws, and that each warning
// (a builder falling back, a CUDA request without a device, a clamped sample distance) is said
// once, not once per edit or switch.
#include "vtkObjectFactory.h"
#include "vtkOutputWindow.h"

#include "SpaceSkipTestHelpers.h"

#include <cstdlib>
#include <fstream>
#include <map>
#include <string>

namespace
{
// Counts every warning and error text that reaches VTK's output window.
class CountingOutputWindow : public vtkOutputWindow
{
public:
  static CountingOutputWindow* New();
  vtkTypeMacro(CountingOutputWindow, vtkOutputWindow);
  void DisplayText(const char* text) override
  {
    std::string s(text ? text : "");
    // VTK prefixes the file, line and object address; keep the message after them.
    const size_t cut = s.find("): ");
    this->Seen[cut == std::string::npos ? s : s.substr(cut + 3)]++;
  }
  std::map<std::string, int> Seen;
};
vtkStandardNewMacro(CountingOutputWindow);

// Resident set size of this process in bytes (Linux: /proc/self/statm, pages).
double ResidentBytes()
{
  std::ifstream in("/proc/self/statm");
  long pages = 0, resident = 0;
  in >> pages >> resident;
  return static_cast<double>(resident) * 4096.0;
}
}

int TestSpaceSkippingVolumeSoak(int, char*[])
{
  vtkNew<CountingOutputWindow> out;
  vtkOutputWindow::SetInstance(out);

  auto image = sstest::MakeWavelet(32);
  double range[2];
  image->GetScalarRange(range);
  const double lo = range[0], hi = range[1], w = hi - lo;

  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  mapper->SetInputData(image);
  mapper->SetBackendToAuto(); // CUDA where a device is usable (device memory checked too)
  sstest::Scene scene(mapper, 64, 64);
  vtkVolumeProperty* prop = scene.Property;
  sstest::SetupProperty(prop, lo, hi, 0.6);
  vtkRenderWindow* win = scene.Window;
  scene.Renderer->ResetCamera();

  vtkPiecewiseFunction* pwf = prop->GetScalarOpacity(0);
  vtkColorTransferFunction* ctf = prop->GetRGBTransferFunction(0);
  const double bg[3] = { 0, 0, 0 };
  // One edit: even steps move the opacity threshold (which changes the occupied cells every few
  // steps), odd steps move a colour point.
  auto edit = [&](int i) {
    if (i % 2 == 0)
    {
      const double t = 0.35 + 0.3 * ((i / 2) % 50) / 50.0;
      pwf->RemoveAllPoints();
      pwf->AddPoint(lo, 0.0);
      pwf->AddPoint(lo + t * w, 0.0);
      pwf->AddPoint(hi, 0.6);
    }
    else
    {
      ctf->RemoveAllPoints();
      ctf->AddRGBPoint(lo, 0.1, 0.2, 0.9);
      ctf->AddRGBPoint(lo + (0.3 + 0.4 * ((i / 2) % 37) / 37.0) * w, 0.9, 0.9, 0.9);
      ctf->AddRGBPoint(hi, 0.9, 0.3, 0.1);
    }
  };

  // Warm-up: first allocations of the engine, the window, the texture and the allocator's pools.
  for (int i = 0; i < 100; ++i)
  {
    edit(i);
    win->Render();
  }
  sstest::CountNonBackground(sstest::Capture(win), bg);
  const double rss0 = ResidentBytes();
  const vtkIdType device0 = mapper->GetDeviceBytesInUse();
  const int builds0 = mapper->GetBuildCount(), classify0 = mapper->GetClassifyCount();
  const int color0 = mapper->GetColorUpdateCount();
  int blank = 0;
  for (int i = 0; i < 1000; ++i)
  {
    edit(100 + i);
    win->Render();
    if (i == 499)
    {
      std::cout << "after 500 edits: RSS growth " << (ResidentBytes() - rss0) / 1024.0 << " KiB\n";
    }
    if (i % 100 == 99 && sstest::CountNonBackground(sstest::Capture(win), bg) == 0)
    {
      ++blank;
    }
  }
  const double rss1 = ResidentBytes();
  const vtkIdType device1 = mapper->GetDeviceBytesInUse();
  const int builds = mapper->GetBuildCount() - builds0;
  const int classified = mapper->GetClassifyCount() - classify0;
  const int colored = mapper->GetColorUpdateCount() - color0;
  std::cout << "1000 edits: RSS " << rss0 / 1048576.0 << " -> " << rss1 / 1048576.0
            << " MiB (growth " << (rss1 - rss0) / 1024.0 << " KiB); " << classified
            << " classifications, " << builds << " builds, " << colored
            << " colour updates; blank frames " << blank << "/10; backend "
            << mapper->GetBackendUsed() << ", device bytes " << device0 << " -> " << device1 << "\n";
  bool ok = true;
  SS_CHECK(rss1 - rss0 <= 1048576.0);
  SS_CHECK(classified == 500 && colored == 500); // each edit did exactly what it needed
  SS_CHECK(builds > 0 && builds < 500);          // rebuilt only when the occupancy changed
  SS_CHECK(blank == 0);
  SS_CHECK(device1 == device0);

  // 200 builder/backend switches with a sample distance far below the floor.
  mapper->SetSampleDistance(1e-6);
  const int builders[] = { vtkSpaceSkippingVolumeMapper::Naive, vtkSpaceSkippingVolumeMapper::Grid,
    vtkSpaceSkippingVolumeMapper::LBVH, vtkSpaceSkippingVolumeMapper::LBVHCPU,
    vtkSpaceSkippingVolumeMapper::KdTreeCPU, vtkSpaceSkippingVolumeMapper::KdTreeGPU,
    vtkSpaceSkippingVolumeMapper::KdTreeGPUFast, vtkSpaceSkippingVolumeMapper::Hybrid,
    vtkSpaceSkippingVolumeMapper::DistanceGrid };
  const int backends[] = { vtkSpaceSkippingVolumeMapper::CPU, vtkSpaceSkippingVolumeMapper::Auto,
    vtkSpaceSkippingVolumeMapper::CUDA };
  out->Seen.clear();
  const double rss2 = ResidentBytes();
  for (int i = 0; i < 200; ++i)
  {
    mapper->SetBuilder(builders[i % 9]);
    mapper->SetBackend(backends[(i / 9) % 3]);
    win->Render();
  }
  const double rss3 = ResidentBytes();
  SS_CHECK(sstest::CountNonBackground(sstest::Capture(win), bg) > 0);
  SS_CHECK(mapper->GetSampleDistanceUsed() >= 1.0 / 16.0);
  std::cout << "200 switches: RSS " << rss2 / 1048576.0 << " -> " << rss3 / 1048576.0
            << " MiB; sample distance used " << mapper->GetSampleDistanceUsed()
            << "; messages:\n";
  int said = 0;
  for (const auto& m : out->Seen)
  {
    std::cout << "  x" << m.second << ": " << m.first;
    ok &= m.second == 1; // each cause once
    said += m.second;
  }
  SS_CHECK(said >= 1); // at least the clamped sample distance was reported
  SS_CHECK(said <= 8);
  // Each backend switch makes a new engine (and CUDA stream/events on a GPU): a bound, not zero.
  // Measured on the H100: +0.95 MB; under compute-sanitizer memcheck +5 MB with Mesa's GL and
  // +22 MB with NVIDIA's GLX (H200, its bookkeeping of every interop registration):
  // bench/device/run-vtk.sh's memcheck phase says so with SPACESKIP_UNDER_SANITIZER=1.
  const bool sanitizer = std::getenv("SPACESKIP_UNDER_SANITIZER") != nullptr;
  const double switchBound = (sanitizer ? 48.0 : 8.0) * 1048576.0;
  std::cout << "switch bound " << switchBound / 1048576.0 << " MiB"
            << (sanitizer ? " (under compute-sanitizer)" : "") << "\n";
  SS_CHECK(rss3 - rss2 <= switchBound);
  vtkOutputWindow::SetInstance(nullptr);
  return ok ? EXIT_SUCCESS : EXIT_FAILURE;
}
