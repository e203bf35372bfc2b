// A CT-like intensity volume and its segmentation (a label map on the same grid) as two volumes
// in one renderer (issue 37): two of ours (the label volume with LabelMap on, nearest labels,
// categorical colours) against two of VTK's GPU ray casters (the label volume through nearest
// interpolation and a step opacity, the stock way to keep ids crisp), with the labels drawn
// through a translucent CT and inside an opaque bone shell, in both orders of the renderer's
// volumes. VTK draws a renderer's volumes one after the other in the order they were added, each
// over what is drawn, not interleaved by depth; ours does the same, so each pair of images must
// agree (PSNR). Both orders are checked to differ from each other (the order is what decides
// where the two overlap: what neither mapper does is interleave their samples, as
// vtkMultiVolume does for the GPU mapper alone).
#include "SpaceSkipTestHelpers.h"

#include "vtkColorTransferFunction.h"
#include "vtkFloatArray.h"
#include "vtkVariant.h"

namespace
{
// Measured on Mesa llvmpipe (Xvfb), 2026-11-28: see the printed PSNRs; the margin covers other
// GL drivers.
constexpr double kMinPSNR = 35.0;
constexpr int kN = 48;
constexpr double kSampleDistance = 0.5;

// Soft tissue (about 60-100) in an ellipsoid, a bone shell (220) near its surface, air 0 outside.
float Density(int x, int y, int z)
{
  const double c = 0.5 * (kN - 1);
  const double u = (x - c) / 21.0, v = (y - c) / 17.0, w = (z - c) / 19.0;
  const double r = std::sqrt(u * u + v * v + w * w);
  if (r > 1.0)
  {
    return 0.f;
  }
  if (r > 0.86)
  {
    return 220.f;
  }
  return static_cast<float>(60.0 + 40.0 * (1.0 - r));
}

// Two organs inside the body: label 3 (a ball) and label 7 (an elongated blob touching it).
unsigned char Label(int x, int y, int z)
{
  const double c = 0.5 * (kN - 1);
  const double a2 = (x - c + 5) * (x - c + 5) + (y - c) * (y - c) + (z - c) * (z - c);
  if (a2 <= 7.0 * 7.0)
  {
    return 3;
  }
  const double u = (x - c - 7) / 9.0, v = (y - c - 2) / 5.0, w = (z - c) / 5.0;
  return u * u + v * v + w * w <= 1.0 ? 7 : 0;
}
}

int TestSpaceSkippingVolumeLabelOverlay(int argc, char* argv[])
{
  auto ct = sstest::MakePointField<vtkFloatArray>(kN, kN, kN, "density", Density);
  auto labels = sstest::MakePointField<vtkUnsignedCharArray>(kN, kN, kN, "labels", Label);

  // The CT: air transparent, soft tissue faint, bone (220) opaque or faint per case.
  vtkNew<vtkVolumeProperty> ctProp;
  ctProp->SetInterpolationTypeToLinear();
  ctProp->ShadeOff();
  ctProp->SetScalarOpacityUnitDistance(1.0);
  vtkNew<vtkColorTransferFunction> ctColour;
  ctColour->AddRGBPoint(0, 0, 0, 0);
  ctColour->AddRGBPoint(60, 0.8, 0.5, 0.4);
  ctColour->AddRGBPoint(220, 1, 1, 0.95);
  vtkNew<vtkPiecewiseFunction> ctOpacity;
  ctProp->SetColor(ctColour);
  ctProp->SetScalarOpacity(ctOpacity);
  auto setBone = [&](double bone) {
    ctOpacity->RemoveAllPoints();
    ctOpacity->AddPoint(0, 0);
    ctOpacity->AddPoint(40, 0);
    ctOpacity->AddPoint(60, 0.02);
    ctOpacity->AddPoint(100, 0.03);
    ctOpacity->AddPoint(200, bone);
    ctOpacity->AddPoint(220, bone);
  };

  // The segmentation: categorical colours for ours (annotations + indexed colours), the same
  // colours at the ids as a continuous map for the stock mapper (nearest interpolation samples
  // exact ids, where the two agree).
  const int ids[2] = { 3, 7 };
  const double colours[2][3] = { { 1, 0.25, 0.2 }, { 0.2, 0.8, 1 } };
  vtkNew<vtkColorTransferFunction> categorical, continuous;
  categorical->IndexedLookupOn();
  for (int i = 0; i < 2; ++i)
  {
    categorical->AddRGBPoint(ids[i], colours[i][0], colours[i][1], colours[i][2]);
    categorical->SetAnnotation(vtkVariant(ids[i]), std::to_string(ids[i]));
    continuous->AddRGBPoint(ids[i], colours[i][0], colours[i][1], colours[i][2]);
  }
  vtkNew<vtkPiecewiseFunction> labelOpacity;
  labelOpacity->AddPoint(0, 0);
  labelOpacity->AddPoint(2.5, 0);
  labelOpacity->AddPoint(3, 0.4);
  labelOpacity->AddPoint(7, 0.4);
  vtkNew<vtkVolumeProperty> oursLabelProp, stockLabelProp;
  for (vtkVolumeProperty* p : { oursLabelProp.Get(), stockLabelProp.Get() })
  {
    p->SetInterpolationTypeToNearest();
    p->ShadeOff();
    p->SetScalarOpacityUnitDistance(1.0);
    p->SetScalarOpacity(labelOpacity);
  }
  oursLabelProp->SetColor(categorical);
  stockLabelProp->SetColor(continuous);

  auto oursCT = sstest::NewMapper(ct, vtkSpaceSkippingVolumeMapper::Grid, kSampleDistance, false);
  auto oursLabels = sstest::NewMapper(labels, vtkSpaceSkippingVolumeMapper::Grid, kSampleDistance, false);
  oursLabels->LabelMapOn();
  oursLabels->SetLabelSampling(vtkSpaceSkippingVolumeMapper::NearestLabel);
  auto stockCT = sstest::ReferenceGPUMapper(ct, kSampleDistance);
  auto stockLabels = sstest::ReferenceGPUMapper(labels, kSampleDistance);

  sstest::Scene scene(oursCT, 256, 256, sstest::kNavy);
  scene.Volume->SetProperty(ctProp);
  vtkNew<vtkVolume> labelVolume;
  labelVolume->SetProperty(oursLabelProp);
  labelVolume->SetMapper(oursLabels);
  scene.Renderer->AddVolume(labelVolume);
  scene.View(30, 20, 1.3, true);
  const std::string dir = sstest::TempDir(argc, argv);

  auto draw = [&](bool ours) {
    scene.Volume->SetMapper(ours ? static_cast<vtkAbstractVolumeMapper*>(oursCT)
                                 : static_cast<vtkAbstractVolumeMapper*>(stockCT));
    labelVolume->SetMapper(ours ? static_cast<vtkAbstractVolumeMapper*>(oursLabels)
                                : static_cast<vtkAbstractVolumeMapper*>(stockLabels));
    labelVolume->SetProperty(ours ? oursLabelProp.Get() : stockLabelProp.Get());
    return scene.Shot();
  };

  int failures = 0;
  vtkSmartPointer<vtkImageData> firstOrder[2];
  for (int order = 0; order < 2; ++order)
  {
    // order 0: the CT added first, the labels drawn over it; 1: the labels first.
    scene.Renderer->RemoveAllViewProps();
    if (order == 0)
    {
      scene.Renderer->AddVolume(scene.Volume);
      scene.Renderer->AddVolume(labelVolume);
    }
    else
    {
      scene.Renderer->AddVolume(labelVolume);
      scene.Renderer->AddVolume(scene.Volume);
    }
    for (double bone : { 0.05, 1.0 })
    {
      setBone(bone);
      const std::string name =
        std::string(order == 0 ? "ct-then-labels" : "labels-then-ct") + (bone < 1 ? "-translucent" : "-bone");
      auto stock = draw(false);
      auto ours = draw(true);
      const double psnr = sstest::PrintComparison(name, stock, ours, "vtkGPUVolumeRayCastMapper x2");
      std::cout << "\n";
      sstest::WritePNG(stock, dir + "/LabelOverlay-" + name + "-stock.png");
      sstest::WritePNG(ours, dir + "/LabelOverlay-" + name + "-ours.png");
      if (psnr < kMinPSNR || sstest::CountNonBackground(ours, sstest::kNavy) < 5000)
      {
        std::cout << "  FAILED (threshold " << kMinPSNR << " dB)\n";
        ++failures;
      }
      if (bone < 1)
      {
        firstOrder[order] = ours;
      }
    }
  }
  // The renderer's order decides what is over what: the two orders' images differ.
  const double between = sstest::PSNR(firstOrder[0], firstOrder[1]);
  std::cout << "ours, CT first vs labels first (translucent): PSNR " << between << " dB\n";
  SS_CHECK(between < 40.0);
  SS_CHECK(failures == 0);
  return EXIT_SUCCESS;
}
