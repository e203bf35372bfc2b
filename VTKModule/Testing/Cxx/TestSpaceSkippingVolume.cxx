// A volume alone: the wavelet through vtkSpaceSkippingVolumeMapper (Grid builder), regression image.
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

#include <cstdlib>
#include <string>

int TestSpaceSkippingVolume(int argc, char* argv[])
{
  auto image = sstest::MakeWavelet(64);
  double range[2];
  image->GetScalarRange(range);

  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  mapper->SetInputData(image);
  mapper->SetBuilderToGrid();
  mapper->SetBackendToCPU(); // the baseline is the CPU image (CUDA equals it up to rounding)
  vtkNew<vtkVolumeProperty> prop;
  sstest::SetupProperty(prop, range[0], range[1]);
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

  // The volume must have drawn something, and only where the box projects.
  auto shot = sstest::Capture(win);
  const vtkIdType drawn = sstest::CountNonBackground(shot, bg);
  std::cout << "non-background pixels: " << drawn << " of " << 300 * 300 << "\n";
  std::cout << "backend " << mapper->GetBackendUsed() << ", builder " << mapper->GetBuilderUsed()
            << ", build " << mapper->GetLastBuildSeconds() << " s, frame "
            << mapper->GetLastRenderSeconds() << " s, nodes " << mapper->GetNodeCount()
            << ", leaves " << mapper->GetLeafCount() << ", occupancy " << mapper->GetOccupancy()
            << "\n";
  SS_CHECK(drawn > 5000 && drawn < 300 * 300);
  SS_CHECK(mapper->GetBuildCount() == 1 && mapper->GetClassifyCount() == 1);
  SS_CHECK(mapper->GetOccupancy() > 0.0 && mapper->GetOccupancy() < 1.0);
  // SPACESKIP_BACKEND=cuda (Testing/gpu/run-gpu-vtk.sh) overrides SetBackendToCPU().
  const char* forced = std::getenv("SPACESKIP_BACKEND");
  const std::string expected = forced && std::string(forced) == "cuda" ? "cuda" : "cpu";
  SS_CHECK(std::string(mapper->GetBackendUsed()) == expected);

  int retVal = vtkRegressionTestImage(win);
  if (retVal == vtkRegressionTester::DO_INTERACTOR)
  {
    iren->Start();
  }
  return !retVal;
}
