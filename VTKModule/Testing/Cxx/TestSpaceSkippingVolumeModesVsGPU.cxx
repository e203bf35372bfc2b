// Shading and every blend mode through vtkGPUVolumeRayCastMapper and vtkSpaceSkippingVolumeMapper
// in the same scene (same sample distance, linear interpolation, no jitter): prints the PSNR per
// case and checks it, and that each case draws something and differs from the composite image.
#include "vtkContourValues.h"

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
  sstest::SetFunctions(prop,
    { { lo, 0.9, 0.8, 0.2 }, { lo + 0.5 * (hi - lo), 0.2, 0.6, 0.9 }, { hi, 0.1, 0.1, 0.8 } },
    { { lo, 0.9 }, { lo + 0.5 * (hi - lo), 0.3 }, { hi, 0.05 } });
}
}

int TestSpaceSkippingVolumeModesVsGPU(int argc, char* argv[])
{
  sstest::VsGPUScene vs;
  const double lo = vs.Lo, hi = vs.Hi;
  vtkGPUVolumeRayCastMapper* gpu = vs.Gpu;
  vtkSpaceSkippingVolumeMapper* ours = vs.Ours;
  sstest::Scene& scene = vs.Stage;
  vtkVolumeProperty* prop = scene.Property;
  vtkVolume* volume = scene.Volume;
  vtkRenderer* ren = scene.Renderer;
  vtkRenderWindow* win = scene.Window;
  vtkCamera* cam = scene.Camera();
  const std::string dir = sstest::TempDir(argc, argv);

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
  vtkSmartPointer<vtkImageData> compositeImage;
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
    vs.Judge(dir, "TestSpaceSkippingVolumeModesVsGPU", c.name, a, b, kMinPSNR);
    if (!compositeImage)
    {
      compositeImage = b;
    }
    else if (sstest::MaxDiff(compositeImage, b) < 20)
    {
      std::cout << "  FAILED: the same image as composite\n";
      ++vs.Failures;
    }
  }
  std::cout << "worst PSNR " << vs.Worst << " dB (threshold " << kMinPSNR << ")\n";
  SS_CHECK(vs.Failures == 0);
  return EXIT_SUCCESS;
}
