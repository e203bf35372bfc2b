// Interactive renders (the render window's DesiredUpdateRate at or above InteractiveUpdateRate,
// as VTK's interactors and ParaView's view set it while the user drags): a frame that would take
// at most a quarter of the volume's allocated render time keeps SampleDistance; a slower one steps
// at least one smallest spacing, and as far as the last frame says the frame needs to fit the
// allocated time, up to 8 spacings. Still renders draw exactly the picture they drew before any
// interaction. A piece of a larger image keeps SampleDistance, whatever its timing; with
// InteractiveAdjustSampleDistances off every render is a still one. Checked through the distance
// the mapper asked the engine for and the one the engine used (counts, not timings).
#include "vtkNew.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "SpaceSkipTestHelpers.h"

#include <cmath>
#include <cstdlib>
#include <iostream>

int TestSpaceSkippingVolumeInteractive(int, char*[])
{
  unsetenv("SPACESKIP_BACKEND");
  auto image = sstest::MakeWavelet(64);
  image->SetSpacing(0.5, 0.75, 1.0); // the smallest spacing: 0.5
  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  mapper->SetInputData(image);
  mapper->SetBackendToCPU();
  mapper->SetBuilderToGrid();
  sstest::Scene scene(mapper, 200, 200, sstest::kNavy);
  vtkRenderWindow* win = scene.Window;
  sstest::SetupProperty(scene.Property, image, 0.8);
  scene.View(30, 20);
  const double h = 0.5;
  auto near = [](double a, double b) { return std::abs(a - b) <= 1e-9 * std::abs(b); };
  auto report = [&](const char* what) {
    std::cout << what << ": interactive " << mapper->GetLastRenderInteractive() << ", asked "
              << mapper->GetLastRequestedSampleDistance() << ", used " << mapper->GetSampleDistanceUsed()
              << "\n";
  };

  SS_CHECK(mapper->GetInteractiveAdjustSampleDistances());
  SS_CHECK(mapper->GetInteractiveUpdateRate() == 1.0);

  // Still (vtkRenderWindow's default rate, 0.0001): SampleDistance 0, the engine's half spacing.
  win->SetDesiredUpdateRate(0.0001);
  win->Render();
  report("still");
  auto still = sstest::Capture(win);
  SS_CHECK(!mapper->GetLastRenderInteractive());
  SS_CHECK(mapper->GetLastRequestedSampleDistance() == 0.0);
  SS_CHECK(near(mapper->GetSampleDistanceUsed(), 0.5 * h));
  SS_CHECK(sstest::CountNonBackground(still, sstest::kNavy) > 5000);

  // Interactive with a second for the frame: the frame is fast, SampleDistance (0: the engine's).
  win->SetDesiredUpdateRate(1.0);
  win->Render();
  report("interactive, 1 s allocated");
  SS_CHECK(mapper->GetLastRenderInteractive());
  SS_CHECK(mapper->GetLastRequestedSampleDistance() == 0.0);
  SS_CHECK(sstest::MaxDiff(still, sstest::Capture(win)) == 0);

  // Interactive with a microsecond: no frame fits; from frames of one distance (all work), the
  // farthest, 8 spacings; then, the time fitted to two distances, between one and 8 spacings.
  win->SetDesiredUpdateRate(1.0e6);
  win->Render();
  report("interactive, 1 us allocated");
  SS_CHECK(near(mapper->GetLastRequestedSampleDistance(), 8 * h));
  SS_CHECK(near(mapper->GetSampleDistanceUsed(), 8 * h));
  auto coarse = sstest::Capture(win);
  win->Render();
  report("interactive, 1 us allocated, again");
  SS_CHECK(mapper->GetLastRequestedSampleDistance() >= h * 0.999999);
  SS_CHECK(mapper->GetLastRequestedSampleDistance() <= 8 * h * 1.000001);
  const double psnr = sstest::PSNR(still, coarse);
  std::cout << "interactive (8 spacings) vs still: PSNR " << psnr << " dB, max diff "
            << sstest::MaxDiff(still, coarse) << "/255\n";
  SS_CHECK(psnr > 20.0); // the same picture, coarser
  SS_CHECK(sstest::MaxDiff(still, coarse) > 0);

  // Twice the last frame's time allocated: it fits, but not fast: one spacing (the floor).
  {
    win->SetDesiredUpdateRate(0.0001);
    win->Render(); // a still frame at 0.25: its time t
    const double t = mapper->GetLastRenderSeconds();
    win->SetDesiredUpdateRate(0.5 / t); // the renderer's budget 2 t
    win->Render();
    report("interactive, twice the last frame's time allocated");
    std::cout << "  engine frame " << t << " s, the volume's allocated time "
              << scene.Volume->GetAllocatedRenderTime() << " s\n";
    SS_CHECK(near(mapper->GetLastRequestedSampleDistance(), h));
  }

  // A user's SampleDistance is the base: a frame that fits keeps it.
  mapper->SetSampleDistance(3 * h);
  win->SetDesiredUpdateRate(1.0);
  win->Render();
  win->Render();
  report("interactive, SampleDistance 1.5");
  SS_CHECK(near(mapper->GetLastRequestedSampleDistance(), 3 * h));
  mapper->SetSampleDistance(0);

  // Back to still: the picture before any interaction, exactly.
  win->SetDesiredUpdateRate(0.0001);
  win->Render();
  report("still again");
  SS_CHECK(!mapper->GetLastRenderInteractive());
  SS_CHECK(sstest::MaxDiff(still, sstest::Capture(win)) == 0);

  // A piece of a larger image: one spacing, whatever the time allocated.
  int extent[6];
  image->GetExtent(extent);
  const int whole[6] = { extent[0], extent[1] + 16, extent[2], extent[3], extent[4], extent[5] };
  mapper->SetWholeExtent(const_cast<int*>(whole));
  win->SetDesiredUpdateRate(1.0e6);
  win->Render();
  win->Render();
  report("a piece, 1 us allocated");
  SS_CHECK(mapper->GetLastRequestedSampleDistance() == 0.0);
  const int none[6] = { 0, -1, 0, -1, 0, -1 };
  mapper->SetWholeExtent(const_cast<int*>(none));

  // Off: interactive renders are still ones.
  mapper->InteractiveAdjustSampleDistancesOff();
  win->Render();
  report("off, 1 us allocated");
  SS_CHECK(!mapper->GetLastRenderInteractive());
  SS_CHECK(mapper->GetLastRequestedSampleDistance() == 0.0);
  SS_CHECK(sstest::MaxDiff(still, sstest::Capture(win)) == 0);
  return EXIT_SUCCESS;
}
