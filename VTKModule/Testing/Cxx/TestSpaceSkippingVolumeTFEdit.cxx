// Transfer-function edits between renders, checked through the mapper's counters:
//  - nothing changed            -> no classification, no build, no colour update;
//  - colour-only edit           -> colour update only (no classification, no build), image changes;
//  - opacity edit, same support -> classification, no build (occupied cells unchanged);
//  - opacity edit, new support  -> classification and build;
//  - a replaced (equal) colour function / a replaced property -> nothing redone;
//  - ScalarOpacityUnitDistance  -> re-classification (the opacity table changes), no build;
//  - the property modified without a TF change -> nothing redone, nothing resampled;
// and, through the table-sample counts, that each edit resamples only the function it edited.
#include "SpaceSkipTestHelpers.h"

namespace
{
struct Counts
{
  int classify, build, color, colorSamples, opacitySamples;
};
Counts Read(vtkSpaceSkippingVolumeMapper* m)
{
  return Counts{ m->GetClassifyCount(), m->GetBuildCount(), m->GetColorUpdateCount(),
    m->GetColorTableSampleCount(), m->GetOpacityTableSampleCount() };
}
// The colour and opacity functions sampled `dColor` and `dOpacity` times between the two.
bool Sampled(const Counts& before, const Counts& after, int dColor, int dOpacity)
{
  const int c = after.colorSamples - before.colorSamples;
  const int o = after.opacitySamples - before.opacitySamples;
  std::cout << "  table samples: colour +" << c << ", opacity +" << o << "\n";
  if (c != dColor || o != dOpacity)
  {
    std::cout << "  expected +" << dColor << ", +" << dOpacity << "\n";
    return false;
  }
  return true;
}
bool Expect(const char* what, const Counts& before, const Counts& after, int dClassify,
  int dBuild, int dColor)
{
  const int c = after.classify - before.classify;
  const int b = after.build - before.build;
  const int u = after.color - before.color;
  std::cout << what << ": classifications +" << c << ", builds +" << b << ", colour updates +"
            << u << "\n";
  if (c != dClassify || b != dBuild || u != dColor)
  {
    std::cout << "  expected +" << dClassify << ", +" << dBuild << ", +" << dColor << "\n";
    return false;
  }
  return true;
}
}

int TestSpaceSkippingVolumeTFEdit(int, char*[])
{
  auto image = sstest::MakeWavelet(64);
  double range[2];
  image->GetScalarRange(range);
  const double lo = range[0], hi = range[1];

  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  mapper->SetInputData(image);
  mapper->SetBackendToCPU();
  mapper->SetBuilderToGrid(); // Auto would measure several structures: the test counts builds
  sstest::Scene scene(mapper, 160, 160);
  vtkVolumeProperty* prop = scene.Property;
  sstest::SetupProperty(prop, lo, hi, 0.6);
  vtkVolume* volume = scene.Volume;
  vtkRenderWindow* win = scene.Window;
  scene.Renderer->ResetCamera();
  scene.Camera()->Zoom(1.4);

  win->Render();
  Counts c0 = Read(mapper);
  SS_CHECK(c0.classify == 1 && c0.build == 1);
  const double occupancy0 = mapper->GetOccupancy();
  auto img0 = sstest::Capture(win);
  bool ok = true;

  // Nothing changed.
  win->Render();
  Counts c1 = Read(mapper);
  ok &= Expect("re-render, no edit", c0, c1, 0, 0, 0);
  ok &= Sampled(c0, c1, 0, 0);

  // Colour-only edit.
  vtkColorTransferFunction* ctf = prop->GetRGBTransferFunction(0);
  ctf->AddRGBPoint(lo + 0.8 * (hi - lo), 0.1, 0.9, 0.2);
  win->Render();
  Counts c2 = Read(mapper);
  ok &= Expect("colour-only edit", c1, c2, 0, 0, 1);
  ok &= Sampled(c1, c2, 1, 0);
  auto img2 = sstest::Capture(win);
  const double psnrColor = sstest::PSNR(img0, img2);
  std::cout << "  PSNR(before, after colour edit) = " << psnrColor << " dB\n";
  ok &= psnrColor < 40.0; // the image did change

  // Opacity edit that keeps the set of non-zero opacity values (only the top point moves).
  vtkPiecewiseFunction* pwf = prop->GetScalarOpacity(0);
  pwf->AddPoint(hi, 0.3);
  win->Render();
  Counts c3 = Read(mapper);
  ok &= Expect("opacity edit, same occupied cells", c2, c3, 1, 0, 0);
  ok &= Sampled(c2, c3, 0, 1);
  ok &= mapper->GetOccupancy() == occupancy0;

  // Opacity edit that empties more space: the zero plateau extends to 75% of the range.
  pwf->RemoveAllPoints();
  pwf->AddPoint(lo, 0.0);
  pwf->AddPoint(lo + 0.75 * (hi - lo), 0.0);
  pwf->AddPoint(hi, 0.3);
  win->Render();
  Counts c4 = Read(mapper);
  ok &= Expect("opacity edit, fewer occupied cells", c3, c4, 1, 1, 0);
  ok &= Sampled(c3, c4, 0, 1);
  std::cout << "  occupancy " << occupancy0 << " -> " << mapper->GetOccupancy() << "\n";
  ok &= mapper->GetOccupancy() < occupancy0;

  // A new colour function object with the same content: re-sampled, nothing redone.
  vtkNew<vtkColorTransferFunction> same;
  same->DeepCopy(ctf);
  prop->SetColor(same);
  win->Render();
  Counts c5 = Read(mapper);
  ok &= Expect("replaced colour function (same content)", c4, c5, 0, 0, 0);
  ok &= Sampled(c4, c5, 1, 0);

  // The property modified for another reason (ParaView does so often): nothing to resample.
  prop->Modified();
  win->Render();
  Counts c5b = Read(mapper);
  ok &= Expect("property modified, functions unchanged", c5, c5b, 0, 0, 0);
  ok &= Sampled(c5, c5b, 0, 0);
  c5 = c5b;

  // A replaced property with a different colour function, same opacity: colour update only.
  vtkNew<vtkVolumeProperty> prop2;
  prop2->DeepCopy(prop);
  vtkNew<vtkColorTransferFunction> other;
  other->AddRGBPoint(lo, 1, 1, 1);
  other->AddRGBPoint(hi, 1, 0, 0);
  vtkNew<vtkPiecewiseFunction> pwf2;
  pwf2->DeepCopy(pwf);
  prop2->SetColor(other);
  prop2->SetScalarOpacity(pwf2);
  volume->SetProperty(prop2);
  win->Render();
  Counts c6 = Read(mapper);
  ok &= Expect("replaced property, new colours", c5, c6, 0, 0, 1);
  ok &= Sampled(c5, c6, 1, 1); // new objects, both

  // The opacity unit distance changes every corrected opacity but not which cells are empty.
  prop2->SetScalarOpacityUnitDistance(2.0);
  win->Render();
  Counts c7 = Read(mapper);
  ok &= Expect("unit distance 1 -> 2", c6, c7, 1, 0, 0);
  ok &= Sampled(c6, c7, 0, 1);

  // Opacity 0 everywhere: classification finds nothing, the build yields an empty structure and
  // the frame is the background.
  pwf2->RemoveAllPoints();
  pwf2->AddPoint(lo, 0.0);
  pwf2->AddPoint(hi, 0.0);
  win->Render();
  Counts c8 = Read(mapper);
  ok &= Expect("opacity 0 everywhere", c7, c8, 1, 1, 0);
  ok &= mapper->GetOccupancy() == 0.0;
  auto img8 = sstest::Capture(win);
  const double black[3] = { 0, 0, 0 };
  ok &= sstest::CountNonBackground(img8, black) == 0;

  mapper->Print(std::cout);
  SS_CHECK(ok);
  return EXIT_SUCCESS;
}
