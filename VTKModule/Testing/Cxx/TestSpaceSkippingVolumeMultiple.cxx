// Several volumes of different voxel types in one offscreen window, one placed by its vtkVolume
// matrix (scale, rotation, translation), drawn again after a resize: regression image of the last
// frame; resizing must not rebuild anything.
#include "vtkImageShiftScale.h"

#include "SpaceSkipTestHelpers.h"

int TestSpaceSkippingVolumeMultiple(int argc, char* argv[])
{
  auto wavelet = sstest::MakeWavelet(48);
  double range[2];
  wavelet->GetScalarRange(range);

  // uint8 over [0, 255] and int16 over [-1000, 1000], from the same field.
  vtkNew<vtkImageShiftScale> toU8;
  toU8->SetInputData(wavelet);
  toU8->SetShift(-range[0]);
  toU8->SetScale(255.0 / (range[1] - range[0]));
  toU8->SetOutputScalarTypeToUnsignedChar();
  toU8->ClampOverflowOn();
  vtkNew<vtkImageShiftScale> toI16;
  toI16->SetInputData(wavelet);
  toI16->SetShift(-0.5 * (range[0] + range[1]));
  toI16->SetScale(2000.0 / (range[1] - range[0]));
  toI16->SetOutputScalarTypeToShort();

  vtkNew<vtkSpaceSkippingVolumeMapper> m8, m16, mf;
  m8->SetInputConnection(toU8->GetOutputPort());
  m16->SetInputConnection(toI16->GetOutputPort());
  mf->SetInputData(wavelet);
  m8->SetBuilderToGrid(); // a fixed structure each: the test counts builds
  mf->SetBuilderToGrid();
  m16->SetBuilderToNaive();

  const double bg[3] = { 0.15, 0.15, 0.15 };
  sstest::Scene scene(m8, 300, 150, bg, true);
  scene.Window->SetOffScreenRendering(1);
  vtkVolume* v8 = scene.Volume;
  vtkNew<vtkVolumeProperty> p16, pf;
  sstest::SetupProperty(scene.Property, 0, 255, 0.7);
  sstest::SetupProperty(p16, -1000, 1000, 0.7);
  sstest::SetupProperty(pf, range[0], range[1], 0.7);
  vtkNew<vtkVolume> v16, vf;
  v8->SetPosition(-50, 0, 0);
  v16->SetMapper(m16);
  v16->SetProperty(p16);
  v16->SetPosition(0, 0, 0);
  v16->SetOrientation(0, 0, 45);
  v16->SetScale(0.8, 1.2, 1.0);
  vf->SetMapper(mf);
  vf->SetProperty(pf);
  vf->SetPosition(50, 0, 0);

  scene.Renderer->AddVolume(v16);
  scene.Renderer->AddVolume(vf);
  scene.View(0, 20, 1.5, true);

  vtkRenderWindow* win = scene.Window;
  win->Render();
  win->SetSize(360, 180);
  auto shot = scene.Shot();
  std::cout << "pixels drawn " << sstest::CountNonBackground(shot, bg) << " at "
            << shot->GetDimensions()[0] << "x" << shot->GetDimensions()[1] << "; builds "
            << m8->GetBuildCount() << " " << m16->GetBuildCount() << " " << mf->GetBuildCount()
            << "; frames " << m8->GetFrameCount() << "\n";
  SS_CHECK(shot->GetDimensions()[0] == 360 && shot->GetDimensions()[1] == 180);
  SS_CHECK(m8->GetBuildCount() == 1 && m16->GetBuildCount() == 1 && mf->GetBuildCount() == 1);
  SS_CHECK(m8->GetFrameCount() >= 2);
  return scene.Regression(argc, argv);
}
