// Maximum intensity projection with value-range skipping: the wavelet through vtkSpaceSkippingVolumeMapper (Grid builder), regression image.
#include "SpaceSkipTestHelpers.h"

int TestSpaceSkippingVolumeMIP(int argc, char* argv[])
{
  sstest::ImageTest t;
  t.Mapper->SetBlendModeToMaximumIntensity();
  t.Mapper->SetBuilderToGrid();
  return t.Check(argc, argv, t.Render());
}
