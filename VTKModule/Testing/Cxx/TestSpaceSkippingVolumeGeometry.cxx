// A volume intersected by opaque geometry (a sphere through its centre and a plane behind it):
// the rays must stop at the geometry's depth. Regression image, plus the same scene through
// vtkGPUVolumeRayCastMapper (which composites with the depth buffer) as an independent check.
#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkNew.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRegressionTestImage.h"
#include "vtkRenderWindow.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkSphereSource.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "SpaceSkipTestHelpers.h"

int TestSpaceSkippingVolumeGeometry(int argc, char* argv[])
{
  auto image = sstest::MakeWavelet(64);
  double range[2];
  image->GetScalarRange(range);

  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  mapper->SetInputData(image);
  mapper->SetBuilderToGrid();
  mapper->SetBackendToCPU();
  mapper->SetSampleDistance(0.5);
  vtkNew<vtkVolumeProperty> prop;
  sstest::SetupProperty(prop, range[0], range[1], 0.3);
  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(prop);

  // A sphere through the middle of the volume (part inside, part outside) ...
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
  // ... and a plane cutting the volume at z = -5, half of it covering the lower half of the box.
  vtkNew<vtkPlaneSource> plane;
  plane->SetOrigin(-40, -40, -5);
  plane->SetPoint1(40, -40, -5);
  plane->SetPoint2(-40, 0, -5);
  vtkNew<vtkPolyDataMapper> planeMapper;
  planeMapper->SetInputConnection(plane->GetOutputPort());
  vtkNew<vtkActor> planeActor;
  planeActor->SetMapper(planeMapper);
  planeActor->GetProperty()->SetColor(0.7, 0.7, 0.2);

  vtkNew<vtkRenderer> ren;
  const double bg[3] = { 0.1, 0.1, 0.2 };
  ren->SetBackground(bg[0], bg[1], bg[2]);
  ren->AddVolume(volume);
  ren->AddActor(sphereActor);
  ren->AddActor(planeActor);
  vtkNew<vtkRenderWindow> win;
  win->SetMultiSamples(0);
  win->SetSize(300, 300);
  win->AddRenderer(ren);
  vtkNew<vtkRenderWindowInteractor> iren;
  iren->SetRenderWindow(win);

  ren->ResetCamera(volume->GetBounds());
  ren->GetActiveCamera()->Azimuth(25);
  ren->GetActiveCamera()->Elevation(15);
  ren->GetActiveCamera()->Zoom(1.8);
  ren->ResetCameraClippingRange();

  // Reference: VTK's own GPU ray caster on the same scene (same sample distance).
  vtkNew<vtkGPUVolumeRayCastMapper> gpu;
  gpu->SetInputData(image);
  gpu->AutoAdjustSampleDistancesOff();
  gpu->LockSampleDistanceToInputSpacingOff();
  gpu->SetSampleDistance(0.5);
  volume->SetMapper(gpu);
  win->Render();
  auto reference = sstest::Capture(win);
  // The geometry alone, to prove the volume shows in front of it and is hidden behind it.
  volume->VisibilityOff();
  win->Render();
  auto geometryOnly = sstest::Capture(win);
  volume->VisibilityOn();

  volume->SetMapper(mapper);
  win->Render();
  auto ours = sstest::Capture(win);
  const double psnr = sstest::PSNR(reference, ours);
  const double psnrGeom = sstest::PSNR(geometryOnly, ours);
  std::cout << "PSNR(vtkGPUVolumeRayCastMapper, ours) with opaque geometry = " << psnr
            << " dB, max |diff| " << sstest::MaxDiff(reference, ours)
            << "/255; PSNR(geometry alone, ours) = " << psnrGeom << " dB\n";
  // Measured 44.8 dB (max 11/255, at the geometry edges) on Mesa llvmpipe; the geometry-only
  // image is far from ours (9.5 dB): the volume shows in front of the geometry.
  SS_CHECK(psnr >= 40.0);
  SS_CHECK(psnrGeom < psnr - 10.0);

  int retVal = vtkRegressionTestImage(win);
  if (retVal == vtkRegressionTester::DO_INTERACTOR)
  {
    iren->Start();
  }
  return !retVal;
}
