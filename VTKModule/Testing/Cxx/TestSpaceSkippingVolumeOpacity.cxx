// Opacity integration against the closed form: a homogeneous slab of opacity a per
// ScalarOpacityUnitDistance u, seen along its thickness L, has alpha = 1 - (1 - a)^(L / u).
// White emission over a black background makes the pixel value alpha * 255. The same scene
// through vtkGPUVolumeRayCastMapper is printed for comparison (not asserted).
#include "vtkCamera.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkNew.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

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

    vtkNew<vtkVolumeProperty> prop;
    vtkNew<vtkColorTransferFunction> ctf;
    ctf->AddRGBPoint(0, 1, 1, 1);
    ctf->AddRGBPoint(100, 1, 1, 1);
    vtkNew<vtkPiecewiseFunction> pwf;
    pwf->AddPoint(0, c.a);
    pwf->AddPoint(100, c.a);
    prop->SetColor(ctf);
    prop->SetScalarOpacity(pwf);
    prop->SetInterpolationTypeToLinear();
    prop->SetScalarOpacityUnitDistance(c.unit);

    vtkNew<vtkSpaceSkippingVolumeMapper> ours;
    ours->SetInputData(img);
    ours->SetSampleDistance(c.sampleDistance);
    ours->EarlyRayTerminationOff();
    vtkNew<vtkGPUVolumeRayCastMapper> gpu;
    gpu->SetInputData(img);
    gpu->AutoAdjustSampleDistancesOff();
    gpu->LockSampleDistanceToInputSpacingOff();
    gpu->SetSampleDistance(c.sampleDistance);
    vtkNew<vtkVolume> volume;
    volume->SetProperty(prop);
    volume->SetMapper(ours);

    vtkNew<vtkRenderer> ren;
    ren->AddVolume(volume);
    vtkNew<vtkRenderWindow> win;
    win->SetMultiSamples(0);
    win->SetSize(64, 64);
    win->AddRenderer(ren);
    vtkCamera* cam = ren->GetActiveCamera();
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
