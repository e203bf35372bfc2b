// Four dependent components (uint8 RGBA with Multi Components Mapping): RGB straight from
// components 0-2 (normalised as vtkVolumeTexture scales them), opacity from the opacity function
// of component 3, as vtkGPUVolumeRayCastMapper draws them (PSNR in the same scene), every
// builder lossless; regression image (KdTreeCPU, CPU backend).
#include "SpaceSkipDependentTest.h"

int TestSpaceSkippingVolumeRGBA(int argc, char* argv[])
{
  auto image = sstest::MakeDependentData(4);
  return sstest::RunDependentTest(argc, argv, image, "TestSpaceSkippingVolumeRGBA");
}
