// The same scene through VTK's vtkGPUVolumeRayCastMapper and vtkSpaceSkippingVolumeMapper at the
// same sample distance, linear interpolation, no shading, no jitter: prints the PSNR between them.
#include "SpaceSkipTestHelpers.h"

namespace
{
// Measured 2026-11-23 on Mesa llvmpipe (Xvfb), first sample one step in as VTK's: 51.7 to 66.3 dB
// over the cases below; the check keeps about 6 dB of margin for other Mesa/driver versions.
constexpr double kMinPSNR = 45.0;
// Camera inside the volume: measured 50.9 dB (max 2/255); 41.9 dB before the mapper started its
// rays one step in as VTK does (NOTES.md).
constexpr double kMinPSNRInside = 45.0;

}

int TestSpaceSkippingVolumeVsGPU(int argc, char* argv[])
{
  auto image = sstest::MakeWavelet(64);
  double range[2];
  image->GetScalarRange(range);
  const double sampleDistance = 0.5;

  auto gpu = sstest::ReferenceGPUMapper(image, sampleDistance);
  auto ours = sstest::NewMapper(image, vtkSpaceSkippingVolumeMapper::Grid, sampleDistance);
  sstest::Scene scene(ours, 256, 256);
  vtkVolumeProperty* prop = scene.Property;
  vtkVolume* volume = scene.Volume;
  vtkRenderer* ren = scene.Renderer;
  vtkRenderWindow* win = scene.Window;
  // Each case below turns the camera further from here.
  ren->ResetCamera();
  ren->GetActiveCamera()->Zoom(1.6);
  const std::string dir = sstest::TempDir(argc, argv);

  struct Case
  {
    const char* name;
    bool perspective;
    double top; // opacity at the top of the range
    bool ert;
  };
  const Case cases[] = {
    { "parallel-a0.6", false, 0.6, false },
    { "perspective-a0.6", true, 0.6, false },
    { "parallel-a0.1", false, 0.1, false },
    { "perspective-a1.0-ert", true, 1.0, true },
  };
  double worst = std::numeric_limits<double>::infinity();
  for (const Case& c : cases)
  {
    sstest::SetupProperty(prop, range[0], range[1], c.top);
    ren->GetActiveCamera()->SetParallelProjection(c.perspective ? 0 : 1);
    ren->GetActiveCamera()->Azimuth(35);
    ren->GetActiveCamera()->Elevation(25);
    ren->GetActiveCamera()->OrthogonalizeViewUp();
    ren->ResetCameraClippingRange();
    ours->SetEarlyRayTermination(c.ert);
    auto a = sstest::RenderWith(win, volume, gpu);
    auto b = sstest::RenderWith(win, volume, ours);
    const double psnr = sstest::PrintComparison(c.name, a, b);
    std::cout << ", sample distance " << sampleDistance << "\n";
    const std::string prefix = dir + "/TestSpaceSkippingVolumeVsGPU-" + c.name;
    sstest::WritePNG(a, prefix + "-gpu.png");
    sstest::WritePNG(b, prefix + "-ours.png");
    worst = std::min(worst, psnr);
    SS_CHECK(sstest::CountNonBackground(b, sstest::kBlack) > 1000);
  }
  // Camera inside the volume (perspective, near plane inside the box): rays start at the near
  // plane instead of the box entry.
  {
    sstest::SetupProperty(prop, range[0], range[1], 0.3);
    vtkCamera* cam = ren->GetActiveCamera();
    cam->SetParallelProjection(0);
    cam->SetPosition(4, 3, 20);
    cam->SetFocalPoint(0, 0, 0);
    cam->SetViewUp(0, 1, 0);
    cam->SetViewAngle(60);
    cam->SetClippingRange(0.5, 100);
    ours->SetEarlyRayTermination(0);
    auto a = sstest::RenderWith(win, volume, gpu);
    auto b = sstest::RenderWith(win, volume, ours);
    const double psnr = sstest::PrintComparison("camera-inside", a, b);
    std::cout << "\n";
    const std::string prefix = dir + "/TestSpaceSkippingVolumeVsGPU-camera-inside";
    sstest::WritePNG(a, prefix + "-gpu.png");
    sstest::WritePNG(b, prefix + "-ours.png");
    SS_CHECK(psnr >= kMinPSNRInside);
  }
  std::cout << "worst PSNR " << worst << " dB (threshold " << kMinPSNR << ")\n";
  SS_CHECK(worst >= kMinPSNR);
  return EXIT_SUCCESS;
}
