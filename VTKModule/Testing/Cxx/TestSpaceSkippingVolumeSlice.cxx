// The slice blend mode (vtkVolumeMapper::SLICE_BLEND with the volume property's slice function, a
// vtkPlane): the wavelet through vtkSpaceSkippingVolumeMapper on the CPU backend, regression image;
// before it, in the same window, the PSNR against vtkGPUVolumeRayCastMapper for an oblique plane
// near the centre and for planes far from it (oblique, axis-aligned, and with the volume moved and
// turned; parallel and perspective, unshaded and shaded) and every builder's image against Naive's;
// a missing or non-plane slice function gives one warning and the centre plane.
#include "vtkPlane.h"
#include "vtkSphere.h"

#include "SpaceSkipTestHelpers.h"

namespace
{
// Issue 12's target against vtkGPUVolumeRayCastMapper.
constexpr double kMinPSNR = 40.0;

// The whole slice visible: opacity from 0.25 to 1 over the range, the usual colour ramp.
void SetupSliceProperty(vtkVolumeProperty* prop, double lo, double hi)
{
  sstest::SetupProperty(prop, lo, hi);
  sstest::SetFunctions(prop,
    { { lo, 0.1, 0.2, 0.9 }, { lo + 0.6 * (hi - lo), 0.9, 0.9, 0.9 }, { hi, 0.9, 0.3, 0.1 } },
    { { lo, 0.25 }, { hi, 1.0 } });
}
}

int TestSpaceSkippingVolumeSlice(int argc, char* argv[])
{
  sstest::ImageTest t;
  double range[2];
  t.Image->GetScalarRange(range);
  vtkVolumeProperty* prop = t.Stage.Property;
  SetupSliceProperty(prop, range[0], range[1]);
  vtkNew<vtkPlane> plane;
  plane->SetOrigin(2.5, -1.5, 3.0);
  plane->SetNormal(0.35, 0.55, 0.76);
  prop->SetSliceFunction(plane);
  t.Mapper->SetBlendModeToSlice();
  t.Mapper->SetSampleDistance(0.5);
  vtkNew<sstest::MessageCollector> messages;
  sstest::Observe(t.Mapper, messages);
  vtkRenderWindow* win = t.Stage.Window;
  vtkVolume* volume = t.Stage.Volume;
  vtkCamera* cam = t.Stage.Camera();
  const std::string dir = sstest::TempDir(argc, argv);

  // Against VTK's GPU ray caster, same scene.
  auto gpu = sstest::ReferenceGPUMapper(t.Image, 0.5);
  gpu->SetBlendMode(vtkVolumeMapper::SLICE_BLEND);
  int failures = 0;
  struct Case
  {
    const char* name;
    bool perspective, shade;
    double origin[3], normal[3];
    bool transformed; // the volume moved and turned: the plane stays in world coordinates
  };
  // The first plane passes near the data's centre; the others lie far from it (the centre
  // fallback would be a different image), one of them axis-aligned, one with the volume moved.
  const Case cases[] = {
    { "slice-perspective", true, false, { 2.5, -1.5, 3.0 }, { 0.35, 0.55, 0.76 }, false },
    { "slice-parallel", false, false, { 2.5, -1.5, 3.0 }, { 0.35, 0.55, 0.76 }, false },
    { "slice-shade-perspective", true, true, { 2.5, -1.5, 3.0 }, { 0.35, 0.55, 0.76 }, false },
    { "slice-offcentre-perspective", true, false, { -19.0, 11.5, -14.0 }, { 0.8, -0.3, 0.52 },
      false },
    { "slice-offcentre-x-parallel", false, false, { 17.25, 0.0, 0.0 }, { 1.0, 0.0, 0.0 }, false },
    { "slice-offcentre-shade", true, true, { -19.0, 11.5, -14.0 }, { 0.8, -0.3, 0.52 }, false },
    { "slice-offcentre-transformed", true, false, { -12.0, 8.0, -5.0 }, { 0.2, 0.9, 0.4 }, true },
  };
  for (const Case& c : cases)
  {
    cam->SetParallelProjection(c.perspective ? 0 : 1);
    prop->SetShade(c.shade ? 1 : 0);
    plane->SetOrigin(c.origin[0], c.origin[1], c.origin[2]);
    plane->SetNormal(c.normal[0], c.normal[1], c.normal[2]);
    volume->SetPosition(c.transformed ? 6.0 : 0.0, c.transformed ? -4.0 : 0.0, c.transformed ? 3.0 : 0.0);
    volume->SetOrientation(0.0, c.transformed ? 10.0 : 0.0, c.transformed ? 25.0 : 0.0);
    auto b = sstest::CompareWithGPU(
      win, volume, gpu, t.Mapper, dir, "TestSpaceSkippingVolumeSlice", c.name, kMinPSNR, failures);
    if (std::string(c.name).find("offcentre") != std::string::npos)
    {
      // Not the centre fallback: the plane through the data's centre, normal z, differs.
      const double* bc = volume->GetCenter();
      plane->SetOrigin(bc[0], bc[1], bc[2]);
      plane->SetNormal(0.0, 0.0, 1.0);
      auto centre = sstest::RenderWith(win, volume, t.Mapper);
      const int d = sstest::MaxDiff(centre, b);
      std::cout << "  vs the centre plane: max |diff| " << d << "/255\n";
      if (d <= 30)
      {
        ++failures;
      }
    }
  }
  volume->SetPosition(0.0, 0.0, 0.0);
  volume->SetOrientation(0.0, 0.0, 0.0);
  plane->SetOrigin(2.5, -1.5, 3.0);
  plane->SetNormal(0.35, 0.55, 0.76);
  cam->SetParallelProjection(0);

  // Every builder equals Naive, unshaded and shaded.
  for (int shade = 0; shade < 2; ++shade)
  {
    prop->SetShade(shade);
    failures += t.BuildersAgainstNaive("shade " + std::to_string(shade) + " ");
  }
  prop->ShadeOff();

  // The slice is the plane's: moving the plane changes the image.
  t.Mapper->SetBuilderToGrid();
  auto before = t.Stage.Shot();
  plane->SetOrigin(2.5, -1.5, -9.0);
  auto moved = t.Stage.Shot();
  std::cout << "moved plane: max |diff| " << sstest::MaxDiff(before, moved) << "/255\n";
  SS_CHECK(sstest::MaxDiff(before, moved) > 30);

  // No slice function, or one that is not a plane: one warning each mapper, the centre plane.
  // (Until here only the GPU builders' fallbacks may have warned, on machines without CUDA.)
  SS_CHECK(messages->Warnings.find("slice") == std::string::npos);
  messages->Clear();
  vtkNew<vtkSphere> sphere;
  prop->SetSliceFunction(sphere);
  auto centre1 = t.Stage.Shot();
  t.Stage.Shot();
  SS_CHECK(messages->WarningCount == 1);
  SS_CHECK(messages->Warnings.find("vtkSphere") != std::string::npos);
  vtkNew<vtkPlane> centrePlane; // through the data's centre, normal z: the same image
  const double* bounds = t.Image->GetBounds();
  centrePlane->SetOrigin(0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
    0.5 * (bounds[4] + bounds[5]));
  centrePlane->SetNormal(0, 0, 1);
  prop->SetSliceFunction(centrePlane);
  SS_CHECK(sstest::MaxDiff(centre1, t.Stage.Shot()) == 0);
  SS_CHECK(messages->WarningCount == 1);

  prop->SetSliceFunction(plane);
  plane->SetOrigin(2.5, -1.5, 3.0);
  t.Mapper->SetBuilderToKdTreeCPU();
  SS_CHECK(failures == 0);
  return t.Check(argc, argv, t.Render());
}
