// Shading with a renderer's lights (ParaView's default: vtkLightKit's key, fill, back and head
// lights), as vtkGPUVolumeRayCastMapper does with any lighting but one headlight of intensity 1:
// the wavelet through vtkSpaceSkippingVolumeMapper on the CPU backend with a light kit, regression
// image; before it, in the same window, the PSNR against vtkGPUVolumeRayCastMapper for the light
// kit (composite parallel and perspective, isosurface), two coloured directional scene lights and
// a positional spot light; every builder's image against Naive's with the light kit; more than
// spaceskip::kMaxLights lights: one warning.
#include "vtkContourValues.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkLightKit.h"

#include "SpaceSkipTestHelpers.h"

#include <functional>

namespace
{
constexpr double kMinPSNR = 40.0;

void Shaded(vtkVolumeProperty* prop)
{
  prop->ShadeOn();
  prop->SetAmbient(0.2);
  prop->SetDiffuse(0.7);
  prop->SetSpecular(0.4);
  prop->SetSpecularPower(30);
}

vtkSmartPointer<vtkLight> SceneLight(
  const double pos[3], const double rgb[3], double intensity, bool positional = false)
{
  auto l = vtkSmartPointer<vtkLight>::New();
  l->SetLightTypeToSceneLight();
  l->SetPosition(pos[0], pos[1], pos[2]);
  l->SetFocalPoint(0, 0, 0);
  l->SetColor(rgb[0], rgb[1], rgb[2]);
  l->SetIntensity(intensity);
  l->SetPositional(positional);
  return l;
}
}

int TestSpaceSkippingVolumeLightKit(int argc, char* argv[])
{
  sstest::ImageTest t;
  double range[2];
  t.Image->GetScalarRange(range);
  const double lo = range[0], hi = range[1];
  vtkVolumeProperty* prop = t.Stage.Property;
  Shaded(prop);
  t.Mapper->SetSampleDistance(0.5);
  vtkNew<sstest::MessageCollector> messages;
  sstest::Observe(t.Mapper, messages);
  vtkRenderer* ren = t.Stage.Renderer;
  vtkRenderWindow* win = t.Stage.Window;
  vtkVolume* volume = t.Stage.Volume;
  vtkCamera* cam = t.Stage.Camera();
  const std::string dir = sstest::TempDir(argc, argv);

  // The default headlight first (the image the light kit must change).
  auto headlight = t.Stage.Shot();
  vtkNew<vtkLightKit> kit;
  auto useKit = [&] {
    ren->RemoveAllLights();
    kit->AddLightsToRenderer(ren);
  };
  useKit();
  std::cout << "light kit: " << ren->GetLights()->GetNumberOfItems() << " lights\n";

  auto gpu = sstest::ReferenceGPUMapper(t.Image, 0.5);
  struct Case
  {
    const char* name;
    int blend;
    bool perspective;
    std::function<void()> lights;
  };
  auto scene2 = [&] {
    ren->RemoveAllLights();
    const double p1[3] = { 80, 50, 60 }, c1[3] = { 1.0, 0.85, 0.7 };
    const double p2[3] = { -60, -20, 70 }, c2[3] = { 0.6, 0.7, 1.0 };
    ren->AddLight(SceneLight(p1, c1, 0.8));
    ren->AddLight(SceneLight(p2, c2, 0.6));
  };
  auto spot = [&] {
    scene2();
    const double p[3] = { 40, 70, 90 }, c[3] = { 1, 1, 1 };
    auto s = SceneLight(p, c, 0.9, true);
    s->SetConeAngle(12);
    s->SetAttenuationValues(1, 0.002, 0);
    ren->AddLight(s);
  };
  const Case cases[] = {
    { "lightkit-perspective", vtkVolumeMapper::COMPOSITE_BLEND, true, useKit },
    { "lightkit-parallel", vtkVolumeMapper::COMPOSITE_BLEND, false, useKit },
    { "lightkit-isosurface", vtkVolumeMapper::ISOSURFACE_BLEND, true, useKit },
    { "two-directional", vtkVolumeMapper::COMPOSITE_BLEND, true, scene2 },
    { "two-directional-spot", vtkVolumeMapper::COMPOSITE_BLEND, true, spot },
  };
  prop->GetIsoSurfaceValues()->SetNumberOfContours(2);
  prop->GetIsoSurfaceValues()->SetValue(0, lo + 0.55 * (hi - lo));
  prop->GetIsoSurfaceValues()->SetValue(1, lo + 0.7 * (hi - lo));
  int failures = 0;
  vtkSmartPointer<vtkImageData> first;
  for (const Case& c : cases)
  {
    c.lights();
    cam->SetParallelProjection(c.perspective ? 0 : 1);
    gpu->SetBlendMode(c.blend);
    t.Mapper->SetBlendMode(c.blend);
    auto b = sstest::CompareWithGPU(
      win, volume, gpu, t.Mapper, dir, "TestSpaceSkippingVolumeLightKit", c.name, kMinPSNR, failures);
    if (!first)
    {
      first = b;
      // The light kit lights the volume otherwise than the headlight.
      std::cout << "light kit vs headlight: max |diff| " << sstest::MaxDiff(headlight, b) << "/255\n";
      if (sstest::MaxDiff(headlight, b) < 20)
      {
        ++failures;
      }
    }
  }
  cam->SetParallelProjection(0);
  t.Mapper->SetBlendModeToComposite();
  useKit();

  // Every builder equals Naive with the light kit.
  failures += t.BuildersAgainstNaive("light kit, ");
  // Only the GPU builders' fallbacks may have warned (machines without CUDA), not the lights.
  SS_CHECK(messages->Warnings.find("light") == std::string::npos);
  messages->Clear();

  // More lights than the engine takes: one warning, the first ones.
  for (int i = 0; i < 10; ++i)
  {
    const double p[3] = { 50.0 * std::cos(i), 50.0 * std::sin(i), 40.0 }, c[3] = { 1, 1, 1 };
    ren->AddLight(SceneLight(p, c, 0.1));
  }
  t.Stage.Shot();
  t.Stage.Shot();
  std::cout << "with " << ren->GetLights()->GetNumberOfItems() << " lights: " << messages->Warnings;
  SS_CHECK(messages->WarningCount == 1);
  SS_CHECK(messages->Warnings.find("lights") != std::string::npos);

  useKit();
  t.Mapper->SetBuilderToKdTreeCPU();
  SS_CHECK(failures == 0);
  return t.Check(argc, argv, t.Render());
}
