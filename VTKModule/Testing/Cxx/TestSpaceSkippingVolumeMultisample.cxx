// A multisampled window (VTK's default on Linux): the mapper resolves the MSAA depth buffer and
// clips rays at the opaque geometry as without MSAA. Compared with the same scene at
// MultiSamples 0 through vtkGPUVolumeRayCastMapper (an independent depth-correct reference), the
// images may differ only along the geometry's antialiased edges.
#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkNew.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkSphereSource.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "SpaceSkipTestHelpers.h"

int TestSpaceSkippingVolumeMultisample(int, char*[])
{
  auto image = sstest::MakeWavelet(64);
  double range[2];
  image->GetScalarRange(range);
  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  mapper->SetInputData(image);
  mapper->SetSampleDistance(0.5);
  vtkNew<sstest::MessageCollector> messages;
  mapper->AddObserver(vtkCommand::WarningEvent, messages);
  mapper->AddObserver(vtkCommand::ErrorEvent, messages);
  vtkNew<vtkVolumeProperty> prop;
  sstest::SetupProperty(prop, range[0], range[1], 0.3);
  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(prop);
  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(8, 4, 6);
  sphere->SetRadius(11);
  sphere->SetThetaResolution(48);
  sphere->SetPhiResolution(48);
  vtkNew<vtkPolyDataMapper> sphereMapper;
  sphereMapper->SetInputConnection(sphere->GetOutputPort());
  vtkNew<vtkActor> sphereActor;
  sphereActor->SetMapper(sphereMapper);
  sphereActor->GetProperty()->SetColor(0.2, 0.8, 0.3);

  vtkNew<vtkRenderer> ren;
  ren->AddVolume(volume);
  ren->AddActor(sphereActor);
  ren->SetBackground(0.1, 0.1, 0.2);
  vtkNew<vtkRenderWindow> win;
  win->SetSize(240, 240);
  win->AddRenderer(ren);
  ren->ResetCamera(volume->GetBounds());
  ren->GetActiveCamera()->Azimuth(25);
  ren->GetActiveCamera()->Elevation(15);
  ren->GetActiveCamera()->Zoom(1.8);
  ren->ResetCameraClippingRange();

  vtkNew<vtkGPUVolumeRayCastMapper> gpu;
  gpu->SetInputData(image);
  gpu->AutoAdjustSampleDistancesOff();
  gpu->LockSampleDistanceToInputSpacingOff();
  gpu->SetSampleDistance(0.5);
  volume->SetMapper(gpu);
  win->SetMultiSamples(0);
  win->Render();
  auto plain = sstest::Capture(win);
  volume->SetMapper(mapper);
  volume->VisibilityOff();
  win->Render();
  auto geometryOnly = sstest::Capture(win);
  volume->VisibilityOn();

  win->SetMultiSamples(8);
  win->Render();
  win->Render();
  auto msaa = sstest::Capture(win);
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
