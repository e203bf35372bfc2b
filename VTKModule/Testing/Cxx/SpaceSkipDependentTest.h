// Dependent components (vtkVolumeProperty::IndependentComponentsOff) through
// vtkSpaceSkippingVolumeMapper and vtkGPUVolumeRayCastMapper in the same scene: the data, the
// comparisons and the checks the 2- and 4-component regression tests share.
#ifndef SpaceSkipDependentTest_h
#define SpaceSkipDependentTest_h

#include "vtkFloatArray.h"
#include "vtkUnsignedCharArray.h"

#include "SpaceSkipTestHelpers.h"

#include <cmath>

namespace sstest
{

// The wavelet's points with `ncomp` components: 2 (float): the wavelet (the colour value) and a
// shell of radius 20 around the centre (the opacity value, 0..250); 4 (uint8): red = x ramp,
// green = the wavelet scaled to 0..255, blue = 255 - y ramp, opacity value = the shell. The shell
// leaves the centre and the corners empty, so the builders skip much of the box.
inline vtkSmartPointer<vtkImageData> MakeDependentData(int ncomp, int n = 64)
{
  auto wavelet = MakeWavelet(n);
  vtkDataArray* w = wavelet->GetPointData()->GetScalars();
  double wr[2];
  w->GetRange(wr);
  vtkSmartPointer<vtkDataArray> out;
  if (ncomp == 2)
  {
    out = vtkSmartPointer<vtkFloatArray>::New();
  }
  else
  {
    out = vtkSmartPointer<vtkUnsignedCharArray>::New();
  }
  out->SetName("dep");
  out->SetNumberOfComponents(ncomp);
  out->SetNumberOfTuples(w->GetNumberOfTuples());
  int ext[6];
  wavelet->GetExtent(ext);
  for (vtkIdType i = 0; i < w->GetNumberOfTuples(); ++i)
  {
    double p[3];
    wavelet->GetPoint(i, p);
    const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    const double shell = 250.0 * std::exp(-(r - 20.0) * (r - 20.0) / 18.0);
    const double a = w->GetComponent(i, 0);
    if (ncomp == 2)
    {
      out->SetComponent(i, 0, a);
      out->SetComponent(i, 1, shell);
    }
    else
    {
      const double fx = (p[0] - ext[0]) / double(ext[1] - ext[0]);
      const double fy = (p[1] - ext[2]) / double(ext[3] - ext[2]);
      out->SetComponent(i, 0, std::round(255.0 * fx));
      out->SetComponent(i, 1, std::round(255.0 * (a - wr[0]) / (wr[1] - wr[0])));
      out->SetComponent(i, 2, std::round(255.0 * (1.0 - fy)));
      out->SetComponent(i, 3, std::round(shell));
    }
  }
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->CopyStructure(wavelet);
  image->GetPointData()->SetScalars(out);
  return image;
}

// Colour over the wavelet's range (component 0 of the 2-component data; unused with 4), opacity
// over the shell's 0..250: transparent below 60.
inline void SetupDependentProperty(vtkVolumeProperty* prop, vtkImageData* image)
{
  double c[2];
  image->GetPointData()->GetScalars()->GetRange(c, 0);
  SetFunctions(prop,
    { { c[0], 0.1, 0.2, 0.9 }, { c[0] + 0.6 * (c[1] - c[0]), 0.9, 0.9, 0.9 }, { c[1], 0.9, 0.3, 0.1 } },
    { { 0, 0.0 }, { 60, 0.0 }, { 250, 0.5 } });
  prop->SetInterpolationTypeToLinear();
  prop->IndependentComponentsOff();
}

// The test: `image` (2 or 4 components) against vtkGPUVolumeRayCastMapper without and with
// shading (PSNR >= 40 dB), every CPU builder equal to Naive (max 1/255), the image differs from
// the independent-components one, no warning; then the baseline of the unshaded KdTreeCPU image.
inline int RunDependentTest(int argc, char* argv[], vtkImageData* image, const char* name)
{
  constexpr double kMinPSNR = 40.0;
  const double sampleDistance = 0.5;
  auto gpu = ReferenceGPUMapper(image, sampleDistance);
  auto ours = NewMapper(image, vtkSpaceSkippingVolumeMapper::Naive, sampleDistance, false);
  ours->SetBackendToCPU();
  vtkNew<MessageCollector> messages;
  Observe(ours, messages);
  Scene scene(ours, 300, 300, kNavy, true);
  scene.View(30, 20);
  vtkVolumeProperty* prop = scene.Property;
  SetupDependentProperty(prop, image);
  const std::string dir = TempDir(argc, argv);
  for (bool shade : { false, true })
  {
    prop->SetShade(shade);
    prop->SetAmbient(0.2);
    prop->SetDiffuse(0.7);
    prop->SetSpecular(0.3);
    prop->SetSpecularPower(20);
    ours->SetBuilderToNaive();
    auto ref = RenderWith(scene.Window, scene.Volume, gpu);
    auto naive = RenderWith(scene.Window, scene.Volume, ours);
    const std::string c = std::string(name) + (shade ? " shaded" : "");
    const double psnr = PrintComparison(c, ref, naive);
    std::cout << "\n";
    const std::string prefix = dir + "/" + name + (shade ? "-shade" : "");
    WritePNG(ref, prefix + "-gpu.png");
    WritePNG(naive, prefix + "-ours.png");
    SS_CHECK(CountNonBackground(naive, kNavy) > 5000);
    SS_CHECK(psnr >= kMinPSNR);
    for (int b : { vtkSpaceSkippingVolumeMapper::Grid, vtkSpaceSkippingVolumeMapper::DistanceGrid,
           vtkSpaceSkippingVolumeMapper::LBVHCPU, vtkSpaceSkippingVolumeMapper::KdTreeCPU,
           vtkSpaceSkippingVolumeMapper::Hybrid })
    {
      ours->SetBuilder(b);
      const int diff = MaxDiff(naive, RenderWith(scene.Window, scene.Volume, ours));
      std::cout << "  builder " << ours->GetBuilderUsed() << ": max |diff| vs Naive " << diff
                << "/255, " << ours->GetNodeCount() << " nodes, occupancy "
                << ours->GetOccupancy() << "\n";
      SS_CHECK(diff <= 1);
      SS_CHECK(ours->GetOccupancy() < 0.9); // the shell leaves empty bricks to skip
    }
  }
  // Independent components (the first component through the transfer functions) is another
  // image: the dependent mode is really taken.
  prop->ShadeOff();
  ours->SetBuilderToKdTreeCPU();
  auto dependent = RenderWith(scene.Window, scene.Volume, ours);
  prop->IndependentComponentsOn();
  auto independent = RenderWith(scene.Window, scene.Volume, ours);
  std::cout << "dependent vs independent: PSNR " << PSNR(dependent, independent) << " dB\n";
  SS_CHECK(PSNR(dependent, independent) < 30.0);
  prop->IndependentComponentsOff();
  scene.Shot();
  std::cout << "warnings: " << messages->WarningCount << " " << messages->Warnings << "\n";
  SS_CHECK(messages->WarningCount == 0 && messages->ErrorCount == 0);
  // No dependent-component rule for the other blend modes: one warning, then component 0
  // through the transfer functions (still drawn).
  ours->SetBlendModeToMaximumIntensity();
  scene.Shot();
  auto mip = scene.Shot();
  std::cout << "maximum intensity: " << messages->WarningCount << " warning(s): " << messages->Warnings
            << "\n";
  SS_CHECK(messages->WarningCount == 1 && messages->ErrorCount == 0);
  SS_CHECK(CountNonBackground(mip, kNavy) > 5000);
  ours->SetBlendModeToComposite();
  scene.Shot();
  return scene.Regression(argc, argv);
}

} // namespace sstest

#endif
