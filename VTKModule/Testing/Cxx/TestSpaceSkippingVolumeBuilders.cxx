// Every builder must give the image of Naive (no skipping): skipping never moves a sample, so the
// images agree up to float rounding (<= 1/255 after 8-bit quantisation). Builders that are not in
// this build yet fall back with a logged warning; the test covers them all the same.
#include "vtkCamera.h"
#include "vtkNew.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "SpaceSkipTestHelpers.h"

int TestSpaceSkippingVolumeBuilders(int, char*[])
{
  auto image = sstest::MakeWavelet(80);
  double range[2];
  image->GetScalarRange(range);

  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  mapper->SetInputData(image);
  mapper->SetSampleDistance(0.5);
  vtkNew<sstest::MessageCollector> messages;
  mapper->AddObserver(vtkCommand::WarningEvent, messages);
  mapper->AddObserver(vtkCommand::ErrorEvent, messages);
  vtkNew<vtkVolumeProperty> prop;
  sstest::SetupProperty(prop, range[0], range[1], 0.7);
  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(prop);

  vtkNew<vtkRenderer> ren;
  const double bg[3] = { 0, 0, 0 };
  ren->SetBackground(bg[0], bg[1], bg[2]);
  ren->AddVolume(volume);
  vtkNew<vtkRenderWindow> win;
  win->SetMultiSamples(0);
  win->SetSize(200, 200);
  win->AddRenderer(ren);
  ren->ResetCamera();
  ren->GetActiveCamera()->Azimuth(20);
  ren->GetActiveCamera()->Elevation(35);
  ren->GetActiveCamera()->OrthogonalizeViewUp();
  ren->GetActiveCamera()->Zoom(1.5);
  ren->ResetCameraClippingRange();

  vtkSmartPointer<vtkImageData> naive;
  int failures = 0;
  int lastBuilds = 0;
  for (int b = vtkSpaceSkippingVolumeMapper::Naive; b <= vtkSpaceSkippingVolumeMapper::Hybrid; ++b)
  {
    messages->Clear();
    mapper->SetBuilder(b);
    win->Render();
    auto shot = sstest::Capture(win);
    if (!naive)
    {
      naive = shot;
    }
    const int maxDiff = sstest::MaxDiff(naive, shot);
    std::cout << "builder " << mapper->GetBuilderAsString() << " -> ran "
              << mapper->GetBuilderUsed() << " on " << mapper->GetBackendUsed() << ": build "
              << mapper->GetLastBuildSeconds() << " s, frame " << mapper->GetLastRenderSeconds()
              << " s, nodes " << mapper->GetNodeCount() << ", height " << mapper->GetTreeHeight()
              << ", leaves " << mapper->GetLeafCount() << ", occupancy "
              << mapper->GetOccupancy() << ", max |diff| vs Naive " << maxDiff << "/255"
              << ", PSNR " << sstest::PSNR(naive, shot) << " dB\n";
    if (!messages->Warnings.empty())
    {
      std::cout << "  logged: " << messages->Warnings << "\n";
    }
    if (messages->ErrorCount)
    {
      std::cout << "  unexpected error: " << messages->Errors << "\n";
      ++failures;
    }
    if (maxDiff > 1)
    {
      std::cout << "  image differs from Naive\n";
      ++failures;
    }
    // Changing the builder rebuilds (once), nothing else.
    if (mapper->GetBuildCount() != lastBuilds + 1)
    {
      std::cout << "  expected exactly one build, got " << mapper->GetBuildCount() - lastBuilds
                << "\n";
      ++failures;
    }
    lastBuilds = mapper->GetBuildCount();
    if (sstest::CountNonBackground(shot, bg) < 2000)
    {
      std::cout << "  nothing drawn\n";
      ++failures;
    }
  }
  SS_CHECK(mapper->GetClassifyCount() == 1);
  SS_CHECK(failures == 0);
  return EXIT_SUCCESS;
}
