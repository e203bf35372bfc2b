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
  const int nx = 72, ny = 60, nz = 48;
  auto img = vtkSmartPointer<vtkImageData>::New();
  img->SetDimensions(nx, ny, nz);
  img->SetSpacing(1, 1.5, 0.8);
  img->SetOrigin(-3, 2, 1);
  vtkNew<vtkUnsignedCharArray> a;
  a->SetName("blobs");
  a->SetNumberOfTuples(vtkIdType(nx) * ny * nz);
  const double c[3][4] = { { 20, 15, 12, 6 }, { 50, 40, 30, 9 }, { 30, 45, 20, 4 } };
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
      {
        double v = 0;
        for (const auto& b : c)
        {
          const double d2 = (x - b[0]) * (x - b[0]) + (y - b[1]) * (y - b[1]) + (z - b[2]) * (z - b[2]);
          v = std::max(v, 255.0 * std::exp(-d2 / (2 * b[3] * b[3])));
        }
        a->SetValue((vtkIdType(z) * ny + y) * nx + x, static_cast<unsigned char>(v));
      }
  img->GetPointData()->SetScalars(a);
  return img;
}

// A spherical shell in int16 (negative outside), 56^3 points.
vtkSmartPointer<vtkImageData> MakeShell()
{
  const int n = 56;
  auto img = vtkSmartPointer<vtkImageData>::New();
  img->SetDimensions(n, n, n);
  vtkNew<vtkShortArray> a;
  a->SetName("shell");
  a->SetNumberOfTuples(vtkIdType(n) * n * n);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
      {
        const double r = std::sqrt(double((x - 28) * (x - 28) + (y - 28) * (y - 28) + (z - 28) * (z - 28)));
        a->SetValue((vtkIdType(z) * n + y) * n + x, static_cast<short>(1000.0 - 120.0 * std::fabs(r - 18.0)));
      }
  img->GetPointData()->SetScalars(a);
  return img;
}
} // namespace

int TestSpaceSkippingVolumeBackends(int, char*[])
{
  // This test chooses the backend itself: no override from the environment.
  unsetenv("SPACESKIP_BACKEND");
  vtkNew<vtkRenderer> ren;
  const double bg[3] = { 0.1, 0.1, 0.2 };
  ren->SetBackground(bg[0], bg[1], bg[2]);
  vtkNew<vtkRenderWindow> win;
  win->SetMultiSamples(0);
  win->SetSize(240, 200);
  win->AddRenderer(ren);
  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  vtkNew<vtkVolumeProperty> prop;
  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(prop);
  ren->AddVolume(volume);

  const char* names[] = { "wavelet", "blobs", "shell" };
  vtkSmartPointer<vtkImageData> data[] = { sstest::MakeWavelet(64), MakeBlobs(), MakeShell() };
  int failures = 0;
  for (int i = 0; i < 3; ++i)
  {
    double range[2];
    data[i]->GetScalarRange(range);
    sstest::SetupProperty(prop, range[0], range[1], 0.8);
    mapper->SetInputData(data[i]);
    ren->ResetCamera();
    ren->GetActiveCamera()->Azimuth(35 + 20 * i);
    ren->GetActiveCamera()->Elevation(25);
    ren->ResetCameraClippingRange();
    for (int b = vtkSpaceSkippingVolumeMapper::Naive; b <= vtkSpaceSkippingVolumeMapper::DistanceGrid; ++b)
    {
      mapper->SetBuilder(b);
      mapper->SetBackendToCPU();
      win->Render();
      auto cpu = sstest::Capture(win);
      const std::string cpuBuilder = mapper->GetBuilderUsed();
      mapper->SetBackendToCUDA();
      win->Render();
      if (std::string(mapper->GetBackendUsed()) != "cuda")
      {
        std::cout << "no usable CUDA device (backend used: " << mapper->GetBackendUsed()
                  << "): skipped\n";
        return VTK_SKIP_RETURN_CODE;
      }
      auto cuda = sstest::Capture(win);
      const int diff = sstest::MaxDiff(cpu, cuda);
      const vtkIdType drawn = sstest::CountNonBackground(cuda, bg);
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
