// The mapper's FilterMode (ExactFilter / HardwareFilter, the engine's FilterMode). The CPU backend
// has no texture unit: HardwareFilter draws exactly the ExactFilter image there, and a change of
// the mode neither re-classifies nor rebuilds. With a usable CUDA device the hardware filter's
// image stays close to the exact one (8-bit texture weights) and every builder still equals Naive
// under it (skipping is lossless with either filter); without one that part is skipped.
#include "vtkCamera.h"
#include "vtkNew.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "SpaceSkipTestHelpers.h"

#include <cstdlib>
#include <string>

int TestSpaceSkippingVolumeFilterMode(int, char*[])
{
  // This test chooses the backend itself: no override from the environment.
  unsetenv("SPACESKIP_BACKEND");
  auto image = sstest::MakeWavelet(64);
  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  mapper->SetInputData(image);
  sstest::Scene scene(mapper, 200, 200, sstest::kNavy);
  vtkRenderWindow* win = scene.Window;
  sstest::SetupProperty(scene.Property, image, 0.8);
  scene.View(30, 20);

  // The property: default Exact, clamped, named.
  SS_CHECK(mapper->GetFilterMode() == vtkSpaceSkippingVolumeMapper::ExactFilter);
  SS_CHECK(std::string(mapper->GetFilterModeAsString()) == "Exact");
  mapper->SetFilterMode(7);
  SS_CHECK(mapper->GetFilterMode() == vtkSpaceSkippingVolumeMapper::HardwareFilter);
  SS_CHECK(std::string(mapper->GetFilterModeAsString()) == "Hardware");
  mapper->SetFilterMode(-3);
  SS_CHECK(mapper->GetFilterMode() == vtkSpaceSkippingVolumeMapper::ExactFilter);

  // CPU backend: the same image either way, and no new classification or build.
  mapper->SetBackendToCPU();
  mapper->SetBuilderToGrid();
  mapper->SetFilterModeToExact();
  win->Render();
  auto exact = sstest::Capture(win);
  SS_CHECK(std::string(mapper->GetBackendUsed()) == "cpu");
  const int builds = mapper->GetBuildCount(), classifications = mapper->GetClassifyCount();
  mapper->SetFilterModeToHardware();
  win->Render();
  auto hw = sstest::Capture(win);
  const vtkIdType drawn = sstest::CountNonBackground(hw, sstest::kNavy);
  std::cout << "CPU backend: Hardware vs Exact max diff " << sstest::MaxDiff(exact, hw)
            << "/255, drawn " << drawn << " pixels; builds " << builds << " -> "
            << mapper->GetBuildCount() << ", classifications " << classifications << " -> "
            << mapper->GetClassifyCount() << "\n";
  SS_CHECK(drawn > 5000);
  SS_CHECK(sstest::MaxDiff(exact, hw) == 0);
  SS_CHECK(mapper->GetBuildCount() == builds);
  SS_CHECK(mapper->GetClassifyCount() == classifications);

  // CUDA backend, when there is a usable device.
  mapper->SetBuilderToNaive();
  mapper->SetFilterModeToExact();
  if (!sstest::RenderOnCUDA(mapper, win, "CUDA part skipped"))
  {
    return EXIT_SUCCESS;
  }
  auto cudaExact = sstest::Capture(win);
  mapper->SetFilterModeToHardware();
  win->Render();
  auto naiveHw = sstest::Capture(win);
  const double psnr = sstest::PSNR(cudaExact, naiveHw);
  std::cout << "CUDA: Naive Hardware vs Exact max diff " << sstest::MaxDiff(cudaExact, naiveHw)
            << "/255, PSNR " << psnr << " dB; Exact CUDA vs CPU max diff "
            << sstest::MaxDiff(cudaExact, exact) << "/255\n";
  SS_CHECK(psnr > 35.0);
  SS_CHECK(sstest::MaxDiff(cudaExact, exact) <= 2);
  int failures = 0;
  for (int b = vtkSpaceSkippingVolumeMapper::Grid; b <= vtkSpaceSkippingVolumeMapper::AutoBuilder; ++b)
  {
    mapper->SetBuilder(b);
    win->Render();
    const int diff = sstest::MaxDiff(naiveHw, sstest::Capture(win));
    std::cout << "CUDA Hardware: " << mapper->GetBuilderAsString() << " (ran "
              << mapper->GetBuilderUsed() << ") vs Naive max diff " << diff << "/255\n";
    failures += diff > 1;
  }
  SS_CHECK(failures == 0);
  return EXIT_SUCCESS;
}
