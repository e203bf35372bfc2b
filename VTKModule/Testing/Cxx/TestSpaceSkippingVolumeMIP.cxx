// Maximum intensity projection with value-range skipping: the wavelet through vtkSpaceSkippingVolumeMapper (Grid builder), regression image.
#include "vtkCamera.h"
#include "vtkNew.h"
#include "vtkRegressionTestImage.h"
#include "vtkRenderWindow.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "SpaceSkipTestHelpers.h"

int TestSpaceSkippingVolumeMIP(int argc, char* argv[])
{
  auto image = sstest::MakeWavelet(64);
  double range[2];
  image->GetScalarRange(range);

  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  mapper->SetInputData(image);
  mapper->SetBackendToCPU(); // the baseline is the CPU image (CUDA equals it up to rounding)
  vtkNew<vtkVolumeProperty> prop;
  sstest::SetupProperty(prop, range[0], range[1]);
  mapper->SetBlendModeToMaximumIntensity();
  mapper->SetBuilderToGrid();
  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(prop);

  vtkNew<vtkRenderer> ren;
  const double bg[3] = { 0.1, 0.1, 0.2 };
  ren->SetBackground(bg[0], bg[1], bg[2]);
  ren->AddVolume(volume);
  vtkNew<vtkRenderWindow> win;
  win->SetMultiSamples(0);
  win->SetSize(300, 300);
  win->AddRenderer(ren);
  vtkNew<vtkRenderWindowInteractor> iren;
  iren->SetRenderWindow(win);

  ren->ResetCamera();
  ren->GetActiveCamera()->Azimuth(30);
  ren->GetActiveCamera()->Elevation(20);
  ren->ResetCameraClippingRange();
  win->Render();

  auto shot = sstest::Capture(win);
  const vtkIdType drawn = sstest::CountNonBackground(shot, bg);
  std::cout << "non-background pixels: " << drawn << " of " << 300 * 300 << ", backend "
            << mapper->GetBackendUsed() << ", builder " << mapper->GetBuilderUsed() << ", frame "
            << mapper->GetLastRenderSeconds() << " s\n";
  SS_CHECK(drawn > 5000 && drawn < 300 * 300);
  // CPU here; CUDA where run-gpu-vtk.sh forces it (the same baseline holds for both).
  SS_CHECK(std::string(mapper->GetBackendUsed()) != "none");

  int retVal = vtkRegressionTestImage(win);
  if (retVal == vtkRegressionTester::DO_INTERACTOR)
  {
    iren->Start();
  }
  return !retVal;
}
