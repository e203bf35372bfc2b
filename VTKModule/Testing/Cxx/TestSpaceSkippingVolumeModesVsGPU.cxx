// Shading and every blend mode through vtkGPUVolumeRayCastMapper and vtkSpaceSkippingVolumeMapper
// in the same scene (same sample distance, linear interpolation, no jitter): prints the PSNR per
// case and checks it, and that each case draws something and differs from the composite image.
#include "vtkCamera.h"
#include "vtkColorTransferFunction.h"
#include "vtkContourValues.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPiecewiseFunction.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkTestUtilities.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "SpaceSkipTestHelpers.h"

#include <functional>

namespace
{
// Issue 12's target for shading and each blend mode.
constexpr double kMinPSNR = 40.0;

vtkSmartPointer<vtkImageData> RenderWith(vtkRenderWindow* win, vtkVolume* volume,
  vtkVolumeMapper* mapper, int blend)
{
  mapper->SetBlendMode(blend);
  volume->SetMapper(mapper);
  win->Render();
  return sstest::Capture(win);
}

// Opaque at low values, fading towards high ones (MinIP has something to show).
void SetupLowProperty(vtkVolumeProperty* prop, double lo, double hi)
{
  vtkNew<vtkColorTransferFunction> ctf;
  ctf->AddRGBPoint(lo, 0.9, 0.8, 0.2);
  ctf->AddRGBPoint(lo + 0.5 * (hi - lo), 0.2, 0.6, 0.9);
  ctf->AddRGBPoint(hi, 0.1, 0.1, 0.8);
  vtkNew<vtkPiecewiseFunction> pwf;
  pwf->AddPoint(lo, 0.9);
  pwf->AddPoint(lo + 0.5 * (hi - lo), 0.3);
  pwf->AddPoint(hi, 0.05);
  prop->SetColor(ctf);
  prop->SetScalarOpacity(pwf);
}
}

int TestSpaceSkippingVolumeModesVsGPU(int argc, char* argv[])
{
  auto image = sstest::MakeWavelet(64);
  double range[2];
  image->GetScalarRange(range);
  const double lo = range[0], hi = range[1];
  const double sampleDistance = 0.5;

  vtkNew<vtkGPUVolumeRayCastMapper> gpu;
  gpu->SetInputData(image);
  gpu->AutoAdjustSampleDistancesOff();
  gpu->LockSampleDistanceToInputSpacingOff();
  gpu->SetSampleDistance(sampleDistance);
  gpu->UseJitteringOff();

  vtkNew<vtkSpaceSkippingVolumeMapper> ours;
  ours->SetInputData(image);
  ours->SetBuilderToGrid();
  ours->SetSampleDistance(sampleDistance);
  ours->SetEarlyRayTermination(0);

  vtkNew<vtkVolumeProperty> prop;
  vtkNew<vtkVolume> volume;
  volume->SetProperty(prop);
  volume->SetMapper(ours); // bounds for ResetCamera

  vtkNew<vtkRenderer> ren;
  ren->SetBackground(0, 0, 0);
  ren->AddVolume(volume);
  vtkNew<vtkRenderWindow> win;
  win->SetMultiSamples(0);
  win->SetSize(256, 256);
  win->AddRenderer(ren);
  ren->ResetCamera();
  vtkCamera* cam = ren->GetActiveCamera();
  cam->Zoom(1.6);
  cam->Azimuth(35);
  cam->Elevation(25);
  cam->OrthogonalizeViewUp();
  ren->ResetCameraClippingRange();

  char* tempDir =
    vtkTestUtilities::GetArgOrEnvOrDefault("-T", argc, argv, "VTK_TEMP_DIR", "Testing/Temporary");
  const std::string dir = tempDir;
  delete[] tempDir;

  struct Case
  {
    const char* name;
    int blend;
    std::function<void(vtkVolumeProperty*)> setup;
    bool perspective;
  };
  auto composite = [&](vtkVolumeProperty* p) { sstest::SetupProperty(p, lo, hi, 0.6); };
  auto shaded = [&](vtkVolumeProperty* p) {
    sstest::SetupProperty(p, lo, hi, 0.6);
    p->ShadeOn();
    p->SetAmbient(0.2);
    p->SetDiffuse(0.7);
    p->SetSpecular(0.3);
    p->SetSpecularPower(20);
  };
  auto iso = [&](vtkVolumeProperty* p) {
    sstest::SetupProperty(p, lo, hi, 0.6);
    vtkNew<vtkPiecewiseFunction> pwf; // the iso values' opacities
    pwf->AddPoint(lo, 0.3);
    pwf->AddPoint(hi, 0.9);
    p->SetScalarOpacity(pwf);
    p->GetIsoSurfaceValues()->SetNumberOfContours(2);
    p->GetIsoSurfaceValues()->SetValue(0, lo + 0.55 * (hi - lo));
    p->GetIsoSurfaceValues()->SetValue(1, lo + 0.7 * (hi - lo));
  };
  auto isoShaded = [&](vtkVolumeProperty* p) {
    iso(p);
    p->ShadeOn();
  };
  auto low = [&](vtkVolumeProperty* p) {
    sstest::SetupProperty(p, lo, hi, 0.6);
    SetupLowProperty(p, lo, hi);
  };
  const Case cases[] = {
    { "composite", vtkVolumeMapper::COMPOSITE_BLEND, composite, false },
    { "shade-parallel", vtkVolumeMapper::COMPOSITE_BLEND, shaded, false },
    { "shade-perspective", vtkVolumeMapper::COMPOSITE_BLEND, shaded, true },
    { "mip", vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND, composite, false },
    { "minip", vtkVolumeMapper::MINIMUM_INTENSITY_BLEND, low, false },
    { "average", vtkVolumeMapper::AVERAGE_INTENSITY_BLEND, composite, false },
    { "additive", vtkVolumeMapper::ADDITIVE_BLEND, composite, false },
    { "isosurface", vtkVolumeMapper::ISOSURFACE_BLEND, iso, false },
    { "isosurface-shade", vtkVolumeMapper::ISOSURFACE_BLEND, isoShaded, false },
    { "isosurface-shade-perspective", vtkVolumeMapper::ISOSURFACE_BLEND, isoShaded, true },
    { "isosurface-perspective", vtkVolumeMapper::ISOSURFACE_BLEND, iso, true },
  };
  double worst = std::numeric_limits<double>::infinity();
  vtkSmartPointer<vtkImageData> compositeImage;
  int failures = 0;
  for (const Case& c : cases)
  {
    vtkNew<vtkVolumeProperty> fresh; // no state left over from the previous case
    prop->DeepCopy(fresh);
    c.setup(prop);
    prop->SetInterpolationTypeToLinear();
    prop->SetScalarOpacityUnitDistance(1.0);
    cam->SetParallelProjection(c.perspective ? 0 : 1);
    ren->ResetCameraClippingRange();
    auto a = RenderWith(win, volume, gpu, c.blend);
    auto b = RenderWith(win, volume, ours, c.blend);
    const double psnr = sstest::PSNR(a, b);
    const double bg[3] = { 0, 0, 0 };
    const vtkIdType drawn = sstest::CountNonBackground(b, bg);
    std::cout << "case " << c.name << ": PSNR(vtkGPUVolumeRayCastMapper, ours) = " << psnr
              << " dB, max |diff| = " << sstest::MaxDiff(a, b) << "/255, drawn pixels gpu "
              << sstest::CountNonBackground(a, bg) << " ours " << drawn << "\n";
    for (int k = 0; k < 2; ++k)
    {
      vtkNew<vtkPNGWriter> w;
      w->SetFileName(
        (dir + "/TestSpaceSkippingVolumeModesVsGPU-" + c.name + (k ? "-ours" : "-gpu") + ".png")
          .c_str());
      w->SetInputData(k ? b : a);
      w->Write();
    }
    worst = std::min(worst, psnr);
    if (drawn < 1000 || psnr < kMinPSNR)
    {
      std::cout << "  FAILED\n";
      ++failures;
    }
    if (!compositeImage)
    {
      compositeImage = b;
    }
    else if (sstest::MaxDiff(compositeImage, b) < 20)
    {
      std::cout << "  FAILED: the same image as composite\n";
      ++failures;
    }
  }
  std::cout << "worst PSNR " << worst << " dB (threshold " << kMinPSNR << ")\n";
  SS_CHECK(failures == 0);
  return EXIT_SUCCESS;
}
