// Geometry conventions: an image with origin, anisotropic spacing and a direction matrix must
// render exactly like the same voxels with an identity direction placed by the vtkVolume's matrix
// (world = volume matrix * index-to-physical); and like vtkGPUVolumeRayCastMapper on the first.
#include "vtkCamera.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkTransform.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "SpaceSkipTestHelpers.h"

int TestSpaceSkippingVolumeTransforms(int, char*[])
{
  auto base = sstest::MakeWavelet(48);
  double range[2];
  base->GetScalarRange(range);
  const double spacing[3] = { 1.0, 1.4, 0.8 };
  const double origin[3] = { 5, -3, 2 };
  vtkNew<vtkTransform> rot;
  rot->RotateZ(30);
  rot->RotateX(20);
  vtkMatrix4x4* r4 = rot->GetMatrix();

  // A: direction matrix + origin in the image, identity prop matrix.
  vtkNew<vtkImageData> a;
  a->DeepCopy(base);
  a->SetExtent(0, 47, 0, 47, 0, 47);
  a->SetSpacing(spacing);
  a->SetOrigin(origin);
  vtkNew<vtkMatrix3x3> dir;
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      dir->SetElement(i, j, r4->GetElement(i, j));
    }
  }
  a->SetDirectionMatrix(dir);
  // B: identity direction, origin 0; the vtkVolume carries rotation and translation.
  vtkNew<vtkImageData> b;
  b->DeepCopy(base);
  b->SetExtent(0, 47, 0, 47, 0, 47);
  b->SetSpacing(spacing);
  b->SetOrigin(0, 0, 0);
  vtkNew<vtkMatrix4x4> user;
  user->DeepCopy(r4);
  for (int i = 0; i < 3; ++i)
  {
    user->SetElement(i, 3, origin[i]);
  }

  vtkNew<vtkSpaceSkippingVolumeMapper> ma, mb;
  ma->SetInputData(a);
  mb->SetInputData(b);
  ma->SetSampleDistance(0.5);
  mb->SetSampleDistance(0.5);
  vtkNew<vtkGPUVolumeRayCastMapper> gpu;
  gpu->SetInputData(a);
  gpu->AutoAdjustSampleDistancesOff();
  gpu->LockSampleDistanceToInputSpacingOff();
  gpu->SetSampleDistance(0.5);

  vtkNew<vtkVolumeProperty> prop;
  sstest::SetupProperty(prop, range[0], range[1], 0.6);
  vtkNew<vtkVolume> va, vb;
  va->SetMapper(ma);
  va->SetProperty(prop);
  vb->SetMapper(mb);
  vb->SetProperty(prop);
  vb->SetUserMatrix(user);

  vtkNew<vtkRenderer> ren;
  vtkSmartPointer<vtkRenderWindow> win = sstest::NewTestWindow();
  win->SetMultiSamples(0);
  win->SetSize(220, 220);
  win->AddRenderer(ren);
  ren->AddVolume(va);
  ren->ResetCamera(va->GetBounds());
  ren->GetActiveCamera()->Azimuth(30);
  ren->GetActiveCamera()->Elevation(10);
  ren->GetActiveCamera()->OrthogonalizeViewUp();
  ren->GetActiveCamera()->Zoom(1.3);
  ren->ResetCameraClippingRange(va->GetBounds());

  win->Render();
  auto imgA = sstest::Capture(win);
  va->SetMapper(gpu);
  win->Render();
  auto imgGPU = sstest::Capture(win);
  ren->RemoveVolume(va);
  ren->AddVolume(vb);
  win->Render();
  auto imgB = sstest::Capture(win);

  const double black[3] = { 0, 0, 0 };
  const double psnrAB = sstest::PSNR(imgA, imgB);
  const double psnrGPU = sstest::PSNR(imgGPU, imgA);
  std::cout << "direction matrix vs vtkVolume matrix: PSNR " << psnrAB << " dB, max |diff| "
            << sstest::MaxDiff(imgA, imgB) << "/255; vs vtkGPUVolumeRayCastMapper: PSNR "
            << psnrGPU << " dB, max |diff| " << sstest::MaxDiff(imgGPU, imgA)
            << "/255; pixels " << sstest::CountNonBackground(imgA, black) << "\n";
  SS_CHECK(sstest::CountNonBackground(imgA, black) > 2000);
  SS_CHECK(psnrAB >= 50.0);
  SS_CHECK(psnrGPU >= 40.0);
  return EXIT_SUCCESS;
}
