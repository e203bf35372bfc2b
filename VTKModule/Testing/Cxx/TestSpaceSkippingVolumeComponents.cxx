// Multi-component scalars: a selected component and the magnitude, against
// vtkSmartVolumeMapper (VTK's GPU ray caster underneath) with the same VectorMode/VectorComponent
// in the same window (PSNR), every builder equal to Naive, and dependent components warned once.
#include "vtkFloatArray.h"
#include "vtkScalarsToColors.h"
#include "vtkSmartVolumeMapper.h"

#include "SpaceSkipTestHelpers.h"

#include <algorithm>
#include <cmath>

namespace
{
constexpr double kMinPSNR = 40.0;

}

int TestSpaceSkippingVolumeComponents(int argc, char* argv[])
{
  const std::string dir = sstest::TempDir(argc, argv);

  // Three components built from the wavelet: w, 300 - w, and a ball of radius 30; magnitude differs
  // from every component.
  auto wavelet = sstest::MakeWavelet(48);
  vtkDataArray* w = wavelet->GetPointData()->GetScalars();
  vtkNew<vtkFloatArray> v;
  v->SetName("v");
  v->SetNumberOfComponents(3);
  v->SetNumberOfTuples(w->GetNumberOfTuples());
  double c[3];
  wavelet->GetCenter(c);
  for (vtkIdType i = 0; i < w->GetNumberOfTuples(); ++i)
  {
    double p[3];
    wavelet->GetPoint(i, p);
    const double r = std::sqrt((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) +
      (p[2] - c[2]) * (p[2] - c[2]));
    const double a = w->GetComponent(i, 0);
    v->SetTuple3(i, a, 300.0 - a, std::max(0.0, 8.0 * (30.0 - r)));
  }
  vtkNew<vtkImageData> image;
  image->CopyStructure(wavelet);
  image->GetPointData()->SetScalars(v);

  vtkNew<vtkSmartVolumeMapper> smart;
  smart->SetInputData(image);
  smart->SetRequestedRenderModeToGPU();
  smart->SetInteractiveAdjustSampleDistances(0);
  smart->SetAutoAdjustSampleDistances(0);
  smart->SetSampleDistance(0.5);

  auto ours = sstest::NewMapper(image, vtkSpaceSkippingVolumeMapper::AutoBuilder, 0.5, false);
  sstest::Scene scene(ours, 200, 200);
  scene.View(30, 20, 1.4, true);
  vtkVolumeProperty* prop = scene.Property;
  vtkVolume* volume = scene.Volume;
  vtkRenderWindow* win = scene.Window;

  struct Case
  {
    const char* name;
    int mode;
    int component;
  };
  const Case cases[] = { { "component 0", vtkScalarsToColors::COMPONENT, 0 },
    { "component 2", vtkScalarsToColors::COMPONENT, 2 },
    { "magnitude", vtkScalarsToColors::MAGNITUDE, 0 } };
  const double bg[3] = { 0, 0, 0 };
  vtkSmartPointer<vtkImageData> previous;
  for (const Case& k : cases)
  {
    double range[2];
    if (k.mode == vtkScalarsToColors::MAGNITUDE)
    {
      v->GetRange(range, -1);
    }
    else
    {
      v->GetRange(range, k.component);
    }
    sstest::SetupProperty(prop, range[0], range[1], 0.4);
    smart->SetVectorMode(k.mode);
    smart->SetVectorComponent(k.component);
    ours->SetVectorMode(k.mode);
    ours->SetVectorComponent(k.component);
    ours->SetBuilderToNaive();
    auto a = sstest::RenderWith(win, volume, smart);
    auto naive = sstest::RenderWith(win, volume, ours);
    const double psnr = sstest::PrintComparison(k.name, a, naive, "vtkSmartVolumeMapper", "smart");
    std::cout << "\n";
    const std::string prefix =
      dir + "/TestSpaceSkippingVolumeComponents-" + std::to_string(&k - cases);
    sstest::WritePNG(a, prefix + "-smart.png");
    sstest::WritePNG(naive, prefix + "-ours.png");
    SS_CHECK(sstest::CountNonBackground(naive, bg) > 500);
    SS_CHECK(psnr >= kMinPSNR);
    if (previous)
    {
      SS_CHECK(sstest::PSNR(previous, naive) < 35.0); // each selection is a different image
    }
    previous = naive;
    for (int b : { vtkSpaceSkippingVolumeMapper::Grid, vtkSpaceSkippingVolumeMapper::KdTreeCPU,
           vtkSpaceSkippingVolumeMapper::DistanceGrid })
    {
      ours->SetBuilder(b);
      SS_CHECK(sstest::MaxDiff(naive, sstest::RenderWith(win, volume, ours)) <= 1);
    }
  }

  // Dependent components (ParaView's Multi Components Mapping): one clear warning, still drawn.
  vtkNew<sstest::MessageCollector> messages;
  ours->AddObserver(vtkCommand::WarningEvent, messages);
  prop->IndependentComponentsOff();
  volume->SetMapper(ours);
  for (int i = 0; i < 3; ++i)
  {
    win->Render();
  }
  std::cout << "dependent components: " << messages->WarningCount << " warning(s): " << messages->Warnings
            << "\n";
  SS_CHECK(messages->WarningCount == 1);
  SS_CHECK(sstest::CountNonBackground(sstest::Capture(win), bg) > 500);
  return EXIT_SUCCESS;
}
