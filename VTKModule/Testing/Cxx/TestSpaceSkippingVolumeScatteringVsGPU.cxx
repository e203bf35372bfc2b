// Volumetric shadows and scattering (vtkGPUVolumeRayCastMapper's VolumetricScatteringBlending and
// GlobalIlluminationReach, vtkVolumeProperty's ScatteringAnisotropy) through the reference GPU
// mapper and vtkSpaceSkippingVolumeMapper in the same scene: prints the PSNR per case and checks
// it, that each case draws something, and that scattering changes both images against shading
// alone (so a mapper that ignored the properties would fail).
#include "vtkLightKit.h"

#include "SpaceSkipTestHelpers.h"

namespace
{
constexpr double kMinPSNR = 40.0;
}

int TestSpaceSkippingVolumeScatteringVsGPU(int argc, char* argv[])
{
  sstest::VsGPUScene vs;
  vtkVolumeProperty* prop = vs.Stage.Property;
  vtkRenderer* ren = vs.Stage.Renderer;
  vtkRenderWindow* win = vs.Stage.Window;
  sstest::SetupProperty(prop, vs.Lo, vs.Hi, 0.6);
  prop->SetInterpolationTypeToLinear();
  prop->SetScalarOpacityUnitDistance(1.0);
  prop->ShadeOn();
  prop->SetAmbient(0.2);
  prop->SetDiffuse(0.7);
  prop->SetSpecular(0.3);
  prop->SetSpecularPower(20);

  struct Case
  {
    const char* name;
    float blending, reach, anisotropy;
    bool lightKit;
  };
  // The default headlight (a point light at the camera for VTK's shadow rays), then ParaView's
  // light kit (five directional lights, five shadow rays per sample: one scattering case there,
  // as the CPU backend's shadow rays are scalar code; with two the test took 141 s in CI).
  const Case cases[] = { { "shade", 0.f, 0.f, 0.f, false }, { "blend0.5-reach0.6", 0.5f, 0.6f, 0.f, false },
    { "blend1.5-reach1-g0.6", 1.5f, 1.f, 0.6f, false }, { "blend2-reach0.3", 2.f, 0.3f, 0.f, false },
    { "kit-shade", 0.f, 0.f, 0.f, true }, { "kit-blend1.5-reach0.5-g-0.5", 1.5f, 0.5f, -0.5f, true } };
  vtkSmartPointer<vtkImageData> shadedGpu, shadedOurs;
  vtkNew<vtkLightKit> kit;
  bool kitOn = false;
  for (const Case& c : cases)
  {
    if (c.lightKit && !kitOn)
    {
      ren->RemoveAllLights();
      kit->AddLightsToRenderer(ren);
      kitOn = true;
    }
    vs.Gpu->SetVolumetricScatteringBlending(c.blending);
    vs.Gpu->SetGlobalIlluminationReach(c.reach);
    vs.Ours->SetVolumetricScatteringBlending(c.blending);
    vs.Ours->SetGlobalIlluminationReach(c.reach);
    prop->SetScatteringAnisotropy(c.anisotropy);
    ren->ResetCameraClippingRange();
    vs.Stage.Volume->SetMapper(vs.Gpu);
    win->Render();
    auto a = sstest::Capture(win);
    vs.Stage.Volume->SetMapper(vs.Ours);
    win->Render();
    auto b = sstest::Capture(win);
    vs.Judge(sstest::TempDir(argc, argv), "TestSpaceSkippingVolumeScatteringVsGPU", c.name, a, b, kMinPSNR);
    if (c.blending == 0.f)
    {
      shadedGpu = a;
      shadedOurs = b;
      continue;
    }
    // Scattering changes both images (the reference's too: else the case proves nothing).
    const int dGpu = sstest::MaxDiff(shadedGpu, a), dOurs = sstest::MaxDiff(shadedOurs, b);
    std::cout << "  vs shading alone: reference max diff " << dGpu << ", ours " << dOurs << "\n";
    if (dGpu < 20 || dOurs < 20)
    {
      std::cout << "  FAILED: scattering did not change the image\n";
      ++vs.Failures;
    }
  }
  std::cout << "worst PSNR " << vs.Worst << " dB (threshold " << kMinPSNR << ")\n";
  SS_CHECK(vs.Failures == 0);
  return EXIT_SUCCESS;
}
