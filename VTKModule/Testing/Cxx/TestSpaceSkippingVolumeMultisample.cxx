// A multisampled window (VTK's default on Linux): the mapper resolves the MSAA depth buffer and
// clips rays at the opaque geometry as without MSAA. Compared with the same scene at
// MultiSamples 0 through vtkGPUVolumeRayCastMapper (an independent depth-correct reference), the
// images may differ only along the geometry's antialiased edges.
#include "SpaceSkipTestHelpers.h"

int TestSpaceSkippingVolumeMultisample(int, char*[])
{
  auto image = sstest::MakeWavelet(64);
  auto mapper = sstest::NewMapper(image, vtkSpaceSkippingVolumeMapper::AutoBuilder, 0.5);
  vtkNew<sstest::MessageCollector> messages;
  sstest::Observe(mapper, messages);
  sstest::Scene scene(mapper, 240, 240, sstest::kNavy);
  sstest::SetupProperty(scene.Property, image, 0.3);
  scene.Renderer->AddActor(sstest::MakeSphereActor());
  vtkVolume* volume = scene.Volume;
  scene.View(25, 15, 1.8, false, volume->GetBounds());

  auto gpu = sstest::ReferenceGPUMapper(image, 0.5);
  vtkRenderWindow* win = scene.Window;
  win->SetMultiSamples(0);
  auto plain = sstest::RenderWith(win, volume, gpu);
  volume->SetMapper(mapper);
  volume->VisibilityOff();
  auto geometryOnly = scene.Shot();
  volume->VisibilityOn();

  win->SetMultiSamples(8);
  win->Render();
  auto msaa = scene.Shot();
  const double psnr = sstest::PSNR(plain, msaa);
  std::cout << "MultiSamples now " << win->GetMultiSamples() << ": PSNR(vtkGPUVolumeRayCastMapper without MSAA, ours with MSAA) = " << psnr
            << " dB, PSNR(geometry only, MSAA) = " << sstest::PSNR(geometryOnly, msaa)
            << " dB; warnings: " << messages->Warnings << "\n";
  SS_CHECK(messages->WarningCount == 0 && messages->ErrorCount == 0);
  // Measured 2026-11-22 (Mesa llvmpipe, 4 samples): 39.9 dB; with the depth
  // ignored the same comparison falls to about 20 dB (TestSpaceSkippingVolumeGeometry's scene).
  SS_CHECK(psnr >= 35.0);
  return EXIT_SUCCESS;
}
