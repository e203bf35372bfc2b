// Parallel and perspective cameras, side by side in two viewports of one window (so the mapper
// also has to honour the renderer's viewport when it reads depth and draws). Regression image,
// plus the same two viewports through vtkGPUVolumeRayCastMapper as an independent check.
#include "vtkCubeSource.h"

#include "SpaceSkipTestHelpers.h"

int TestSpaceSkippingVolumeCameras(int argc, char* argv[])
{
  auto image = sstest::MakeWavelet(64);
  auto mapper = sstest::NewMapper(image, vtkSpaceSkippingVolumeMapper::Grid, 0.5);
  mapper->SetBackendToCPU();
  auto gpu = sstest::ReferenceGPUMapper(image, 0.5);
  vtkNew<vtkVolumeProperty> prop;
  sstest::SetupProperty(prop, image, 0.5);

  // A thin opaque bar through the volume in both views (depth read per viewport).
  vtkNew<vtkCubeSource> bar;
  bar->SetXLength(70);
  bar->SetYLength(3);
  bar->SetZLength(3);
  vtkNew<vtkPolyDataMapper> barMapper;
  barMapper->SetInputConnection(bar->GetOutputPort());

  vtkSmartPointer<vtkRenderWindow> win = sstest::NewTestWindow();
  win->SetMultiSamples(0);
  win->SetSize(400, 220);
  vtkNew<vtkVolume> volumes[2];
  vtkNew<vtkActor> bars[2];
  vtkNew<vtkRenderer> rens[2];
  for (int i = 0; i < 2; ++i)
  {
    volumes[i]->SetMapper(mapper);
    volumes[i]->SetProperty(prop);
    bars[i]->SetMapper(barMapper);
    bars[i]->GetProperty()->SetColor(0.9, 0.9, 0.2);
    rens[i]->SetViewport(0.5 * i, 0, 0.5 * (i + 1), 1);
    rens[i]->SetBackground(0.1, 0.1 + 0.1 * i, 0.2);
    rens[i]->AddVolume(volumes[i]);
    rens[i]->AddActor(bars[i]);
    win->AddRenderer(rens[i]);
    vtkCamera* cam = rens[i]->GetActiveCamera();
    cam->SetParallelProjection(i == 0 ? 1 : 0);
    rens[i]->ResetCamera(volumes[i]->GetBounds());
    cam->Azimuth(40);
    cam->Elevation(30);
    cam->OrthogonalizeViewUp();
    cam->Zoom(i == 0 ? 1.5 : 1.8);
    rens[i]->ResetCameraClippingRange();
  }
  vtkNew<vtkRenderWindowInteractor> iren;
  iren->SetRenderWindow(win);

  for (int i = 0; i < 2; ++i)
  {
    volumes[i]->SetMapper(gpu);
  }
  win->Render();
  auto reference = sstest::Capture(win);
  for (int i = 0; i < 2; ++i)
  {
    volumes[i]->SetMapper(mapper);
  }
  win->Render();
  auto ours = sstest::Capture(win);
  const double psnr = sstest::PSNR(reference, ours);
  std::cout << "PSNR(vtkGPUVolumeRayCastMapper, ours), parallel | perspective viewports = "
            << psnr << " dB, max |diff| " << sstest::MaxDiff(reference, ours) << "/255\n";
  SS_CHECK(psnr >= 40.0);
  // One mapper drew two viewports of different cameras in one frame: two frames, one build.
  SS_CHECK(mapper->GetBuildCount() == 1);

  int retVal = vtkRegressionTestImage(win);
  if (retVal == vtkRegressionTester::DO_INTERACTOR)
  {
    iren->Start();
  }
  return !retVal;
}
