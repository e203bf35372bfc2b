// Two dependent components (ParaView's Multi Components Mapping on a 2-component array): colour
// from the colour function of component 0, opacity from the opacity function of component 1, as
// vtkGPUVolumeRayCastMapper draws them (PSNR in the same scene), every builder lossless;
// regression image (KdTreeCPU, CPU backend).
#include "SpaceSkipDependentTest.h"

int TestSpaceSkippingVolumeTwoComponents(int argc, char* argv[])
{
  auto image = sstest::MakeDependentData(2);
  return sstest::RunDependentTest(argc, argv, image, "TestSpaceSkippingVolumeTwoComponents");
}
