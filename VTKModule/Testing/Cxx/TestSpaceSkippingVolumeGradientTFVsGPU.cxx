// 2-D transfer functions (vtkVolumeProperty TF_2D: value x gradient magnitude, or value x a second
// array: Transfer2DYAxisArray) and gradient opacity through vtkGPUVolumeRayCastMapper and
// vtkSpaceSkippingVolumeMapper in the same scene: prints the PSNR per case and checks it, that
// each case draws something and that it differs from the same property without the 2-D table /
// gradient opacity (so ignoring them fails), and the second array from the gradient's image.
#include "vtkFloatArray.h"
#include "vtkPointData.h"

#include "SpaceSkipTestHelpers.h"

#include <functional>

namespace
{
// Issue 34's target.
constexpr double kMinPSNR = 40.0;
}

int TestSpaceSkippingVolumeGradientTFVsGPU(int argc, char* argv[])
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
  const std::string dir = sstest::TempDir(argc, argv);

  // The second array: a ramp from -3 to 5 along the image's first axis, so that the y axis
  // picks a slab the gradient magnitude would not.
  {
    vtkImageData* img = vs.Image;
    int dims[3];
    img->GetDimensions(dims);
    vtkNew<vtkFloatArray> second;
    second->SetName("second");
    second->SetNumberOfTuples(img->GetNumberOfPoints());
    for (vtkIdType n = 0; n < img->GetNumberOfPoints(); ++n)
    {
      const int i = static_cast<int>(n % dims[0]);
      second->SetValue(n, static_cast<float>(-3.0 + 8.0 * i / (dims[0] - 1)));
    }
    img->GetPointData()->AddArray(second);
  }

  auto box = sstest::MakeBox2D(64, 32, 0.3, 0.95, 0.08, 0.5, 0.15);
  auto plain = [&](vtkVolumeProperty* p) { sstest::SetupProperty(p, lo, hi, 0.6); };
  auto twoD = [&](vtkVolumeProperty* p) {
    plain(p);
    p->SetTransferFunctionMode(vtkVolumeProperty::TF_2D);
    p->SetTransferFunction2D(box);
  };
  auto twoDShaded = [&](vtkVolumeProperty* p) {
    twoD(p);
    p->ShadeOn();
    p->SetAmbient(0.2);
    p->SetDiffuse(0.7);
    p->SetSpecular(0.3);
    p->SetSpecularPower(20);
  };
  auto gradient = [&](vtkVolumeProperty* p) {
    plain(p);
    vtkNew<vtkPiecewiseFunction> g; // over the gradient magnitude in scalar units per voxel
    g->AddPoint(0, 0.0);
    g->AddPoint(0.05 * (hi - lo), 1.0);
    g->AddPoint(0.25 * (hi - lo), 0.2);
    p->SetGradientOpacity(g);
  };
  struct Case
  {
    const char* name;
    std::function<void(vtkVolumeProperty*)> setup;
  };
  const Case cases[] = { { "1d", plain }, { "2d", twoD }, { "2d-shade", twoDShaded },
    { "gradient-opacity", gradient }, { "2d-second-array", twoD }, { "2d-second-array-shade", twoDShaded } };
  vtkSmartPointer<vtkImageData> plainImage, gradientYImage;
  for (const Case& c : cases)
  {
    vtkNew<vtkVolumeProperty> fresh;
    prop->DeepCopy(fresh);
    c.setup(prop);
    const bool second = std::string(c.name).find("second-array") != std::string::npos;
    gpu->SetTransfer2DYAxisArray(second ? "second" : nullptr);
    ours->SetTransfer2DYAxisArray(second ? "second" : nullptr);
    prop->SetInterpolationTypeToLinear();
    prop->SetScalarOpacityUnitDistance(1.0);
    ren->ResetCameraClippingRange();
    volume->SetMapper(gpu);
    win->Render();
    auto a = sstest::Capture(win);
    volume->SetMapper(ours);
    win->Render();
    auto b = sstest::Capture(win);
    vs.Judge(dir, "TestSpaceSkippingVolumeGradientTFVsGPU", c.name, a, b, kMinPSNR);
    if (std::string(c.name) == "2d")
    {
      gradientYImage = b;
    }
    if (std::string(c.name) == "2d-second-array" && sstest::MaxDiff(gradientYImage, b) < 20)
    {
      std::cout << "  FAILED: the second array draws the gradient's image\n";
      ++vs.Failures;
    }
    if (!plainImage)
    {
      plainImage = b;
    }
    else
    {
      const double change = sstest::PSNR(plainImage, b);
      std::cout << "  " << c.name << " vs 1d (ours): " << change << " dB, max diff " << sstest::MaxDiff(plainImage, b)
                << "\n";
      if (sstest::MaxDiff(plainImage, b) < 20)
      {
        std::cout << "  FAILED: the same image as without it\n";
        ++vs.Failures;
      }
    }
  }
  std::cout << "worst PSNR " << vs.Worst << " dB (threshold " << kMinPSNR << ")\n";
  SS_CHECK(vs.Failures == 0);
  return EXIT_SUCCESS;
}
