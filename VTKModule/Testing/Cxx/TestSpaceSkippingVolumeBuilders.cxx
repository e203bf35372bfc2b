// Every builder must give the image of Naive (no skipping): skipping never moves a sample, so the
// images agree up to float rounding (<= 1/255 after 8-bit quantisation). Builders that are not in
// this build yet fall back with a logged warning; the test covers them all the same. All builders
// run with the default 8^3 macro cells and again with 4^3 ones (MacroCellSize 4, what DistanceGrid
// is fastest with on sparse data), against the Naive image of the 8^3 pass.
#include "SpaceSkipTestHelpers.h"

int TestSpaceSkippingVolumeBuilders(int, char*[])
{
  auto image = sstest::MakeWavelet(80);
  auto mapper = sstest::NewMapper(image, vtkSpaceSkippingVolumeMapper::AutoBuilder, 0.5);
  vtkNew<sstest::MessageCollector> messages;
  sstest::Observe(mapper, messages);
  sstest::Scene scene(mapper, 200, 200);
  sstest::SetupProperty(scene.Property, image, 0.7);
  scene.View(20, 35, 1.5, true);
  vtkRenderWindow* win = scene.Window;
  const double* bg = sstest::kBlack;

  // MacroCellSize is clamped to [1, 64].
  SS_CHECK(mapper->GetMacroCellSize() == 8);
  mapper->SetMacroCellSize(0);
  SS_CHECK(mapper->GetMacroCellSize() == 1);
  mapper->SetMacroCellSize(100);
  SS_CHECK(mapper->GetMacroCellSize() == 64);

  vtkSmartPointer<vtkImageData> naive;
  int failures = 0;
  int lastBuilds = 0;
  double occupancy[2] = { 0, 0 };
  const int cellSizes[2] = { 8, 4 };
  for (int pass = 0; pass < 2; ++pass)
  {
    // The first render of a pass (Naive) re-classifies and rebuilds for the new cell size.
    mapper->SetMacroCellSize(cellSizes[pass]);
    for (int b = vtkSpaceSkippingVolumeMapper::Naive; b <= vtkSpaceSkippingVolumeMapper::DistanceGrid;
         ++b)
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
      std::cout << "macro cell " << mapper->GetMacroCellSize() << ", builder "
                << mapper->GetBuilderAsString() << " -> ran " << mapper->GetBuilderUsed() << " on "
                << mapper->GetBackendUsed() << ": build " << mapper->GetLastBuildSeconds()
                << " s, frame " << mapper->GetLastRenderSeconds() << " s, nodes "
                << mapper->GetNodeCount() << ", height " << mapper->GetTreeHeight() << ", leaves "
                << mapper->GetLeafCount() << ", occupancy " << mapper->GetOccupancy()
                << ", max |diff| vs Naive " << maxDiff << "/255"
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
      // Changing the builder (or, for the pass's first builder, the cell size) rebuilds once.
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
      // DistanceGrid is a Core builder of both backends: it must run, not fall back.
      if (b == vtkSpaceSkippingVolumeMapper::DistanceGrid &&
        std::string(mapper->GetBuilderUsed()) != "DistanceGrid")
      {
        std::cout << "  DistanceGrid fell back to " << mapper->GetBuilderUsed() << "\n";
        ++failures;
      }
    }
    occupancy[pass] = mapper->GetOccupancy();
    // One classification per cell size: the builder changes within a pass do not re-classify.
    SS_CHECK(mapper->GetClassifyCount() == pass + 1);
  }
  // The cell size reached the engine: every occupied 8^3 cell is the union of eight 4^3 cells, so
  // the finer grid marks a strictly smaller fraction occupied around the wavelet's iso-shells.
  std::cout << "occupancy: 8^3 cells " << occupancy[0] << ", 4^3 cells " << occupancy[1] << "\n";
  SS_CHECK(occupancy[1] < occupancy[0]);

  // The cell size alone (same builder): one re-classification and one rebuild; setting the same
  // value again changes nothing.
  mapper->SetMacroCellSize(8);
  win->Render();
  SS_CHECK(mapper->GetClassifyCount() == 3);
  SS_CHECK(mapper->GetBuildCount() == lastBuilds + 1);
  SS_CHECK(sstest::MaxDiff(naive, sstest::Capture(win)) <= 1);
  mapper->SetMacroCellSize(8);
  win->Render();
  SS_CHECK(mapper->GetClassifyCount() == 3);
  SS_CHECK(mapper->GetBuildCount() == lastBuilds + 1);
  SS_CHECK(failures == 0);
  return EXIT_SUCCESS;
}
