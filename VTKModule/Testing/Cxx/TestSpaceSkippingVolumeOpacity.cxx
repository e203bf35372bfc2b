// Opacity integration against the closed form: a homogeneous slab of opacity a per
// ScalarOpacityUnitDistance u, seen along its thickness L, has alpha = 1 - (1 - a)^(L / u).
// White emission over a black background makes the pixel value alpha * 255. The same scene
// through vtkGPUVolumeRayCastMapper is printed for comparison (not asserted).
#include "SpaceSkipTestHelpers.h"

int TestSpaceSkippingVolumeOpacity(int, char*[])
{
  struct Case
  {
    double spacingZ, unit, a, sampleDistance;
  };
  const Case cases[] = { { 1.0, 1.0, 0.05, 0.5 }, { 1.0, 1.0, 0.01, 0.5 },
    { 2.0, 3.0, 0.05, 0.5 }, { 1.0, 1.0, 0.05, 0.25 } };
  int failures = 0;
  for (const Case& c : cases)
  {
    const int n = 64;
    vtkNew<vtkImageData> img;
    img->SetDimensions(n, n, n);
    img->SetSpacing(1, 1, c.spacingZ);
    vtkNew<vtkUnsignedCharArray> v;
    v->SetName("v");
    v->SetNumberOfTuples(n * n * n);
    v->FillValue(100);
    v->SetValue(0, 0); // a non-degenerate scalar range; the TF is flat anyway
    img->GetPointData()->SetScalars(v);

    auto ours = sstest::NewMapper(img, vtkSpaceSkippingVolumeMapper::AutoBuilder, c.sampleDistance, false);
    auto gpu = sstest::ReferenceGPUMapper(img, c.sampleDistance);
    sstest::Scene scene(ours, 64, 64);
    vtkVolumeProperty* prop = scene.Property;
    sstest::SetFunctions(prop, { { 0, 1, 1, 1 }, { 100, 1, 1, 1 } }, { { 0, c.a }, { 100, c.a } });
    prop->SetInterpolationTypeToLinear();
    prop->SetScalarOpacityUnitDistance(c.unit);
    vtkVolume* volume = scene.Volume;
    vtkRenderWindow* win = scene.Window;
    vtkCamera* cam = scene.Camera();
    const double L = (n - 1) * c.spacingZ;
    cam->ParallelProjectionOn();
    cam->SetFocalPoint(31.5, 31.5, L / 2);
    cam->SetPosition(31.5, 31.5, L + 100);
    cam->SetViewUp(0, 1, 0);
    cam->SetParallelScale(10); // the view sees only the slab's interior
    cam->SetClippingRange(50, L + 150);

    win->Render();
    auto a = sstest::Capture(win);
    volume->SetMapper(gpu);
    win->Render();
    auto g = sstest::Capture(win);
    const double expected = 255.0 * (1.0 - std::pow(1.0 - c.a, L / c.unit));
    const int centre = 3 * (32 * 64 + 32);
    const int oursValue = sstest::Pixels(a)[centre];
    const int gpuValue = sstest::Pixels(g)[centre];
    std::cout << "a=" << c.a << " per " << c.unit << ", L=" << L << ", dt=" << c.sampleDistance
              << ": closed form " << expected << ", ours " << oursValue
              << ", vtkGPUVolumeRayCastMapper " << gpuValue << "\n";
    if (std::abs(oursValue - expected) > 1.0)
    {
      ++failures;
    }
  }
  SS_CHECK(failures == 0);
  return EXIT_SUCCESS;
}
