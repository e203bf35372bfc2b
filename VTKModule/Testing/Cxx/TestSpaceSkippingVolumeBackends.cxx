// CUDA == CPU in the window: every builder on three data sets (float wavelet, sparse uint8 blobs
// on an anisotropic grid, an int16 shell), each drawn by the CPU and the CUDA backend into the
// same window; the captured images must agree within 2/255. Skipped without a usable device.
#include "vtkCamera.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkShortArray.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkTesting.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "SpaceSkipTestHelpers.h"

#include <cstdlib>
#include <string>

namespace
{
// A few Gaussian blobs in uint8 on 72x60x48 points, spacing (1, 1.5, 0.8): mostly empty.
vtkSmartPointer<vtkImageData> MakeBlobs()
{
  auto img = sstest::MakeBlobs(72, 60, 48, { { 20, 15, 12, 6 }, { 50, 40, 30, 9 }, { 30, 45, 20, 4 } }, 255.0);
  img->SetSpacing(1, 1.5, 0.8);
  img->SetOrigin(-3, 2, 1);
  return img;
}

// A spherical shell in int16 (negative outside), 56^3 points.
vtkSmartPointer<vtkImageData> MakeShell()
{
  return sstest::MakePointField<vtkShortArray>(56, 56, 56, "shell", [](int x, int y, int z) {
    const double r = std::sqrt(double((x - 28) * (x - 28) + (y - 28) * (y - 28) + (z - 28) * (z - 28)));
    return static_cast<short>(1000.0 - 120.0 * std::fabs(r - 18.0));
  });
}
} // namespace

int TestSpaceSkippingVolumeBackends(int, char*[])
{
  // This test chooses the backend itself: no override from the environment.
  unsetenv("SPACESKIP_BACKEND");
  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  sstest::Scene scene(mapper, 240, 200, sstest::kNavy);
  vtkRenderWindow* win = scene.Window;
  vtkVolumeProperty* prop = scene.Property;

  const char* names[] = { "wavelet", "blobs", "shell" };
  vtkSmartPointer<vtkImageData> data[] = { sstest::MakeWavelet(64), MakeBlobs(), MakeShell() };
  int failures = 0;
  for (int i = 0; i < 3; ++i)
  {
    double range[2];
    data[i]->GetScalarRange(range);
    sstest::SetupProperty(prop, range[0], range[1], 0.8);
    mapper->SetInputData(data[i]);
    scene.View(35 + 20 * i, 25);
    for (int b = vtkSpaceSkippingVolumeMapper::Naive; b <= vtkSpaceSkippingVolumeMapper::DistanceGrid; ++b)
    {
      mapper->SetBuilder(b);
      mapper->SetBackendToCPU();
      win->Render();
      auto cpu = sstest::Capture(win);
      const std::string cpuBuilder = mapper->GetBuilderUsed();
      if (!sstest::RenderOnCUDA(mapper, win, "skipped"))
      {
        return VTK_SKIP_RETURN_CODE;
      }
      auto cuda = sstest::Capture(win);
      const int diff = sstest::MaxDiff(cpu, cuda);
      const vtkIdType drawn = sstest::CountNonBackground(cuda, sstest::kNavy);
      std::cout << names[i] << " " << mapper->GetBuilderAsString() << " (cpu ran " << cpuBuilder
                << ", cuda ran " << mapper->GetBuilderUsed() << "): max diff " << diff
                << "/255, PSNR " << sstest::PSNR(cpu, cuda) << " dB, drawn " << drawn << "\n";
      if (diff > 2 || drawn < 500)
      {
        ++failures;
      }
    }
  }
  SS_CHECK(failures == 0);
  return EXIT_SUCCESS;
}
