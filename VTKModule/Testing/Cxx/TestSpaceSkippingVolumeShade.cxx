// Gradient shading (vtkVolumeProperty Shade, Ambient, Diffuse, Specular, SpecularPower) with VTK's headlight: the wavelet through vtkSpaceSkippingVolumeMapper (KdTreeCPU builder), regression image.
#include "SpaceSkipTestHelpers.h"

int TestSpaceSkippingVolumeShade(int argc, char* argv[])
{
  sstest::ImageTest t;
  vtkVolumeProperty* prop = t.Stage.Property;
  prop->ShadeOn();
  prop->SetAmbient(0.2);
  prop->SetDiffuse(0.7);
  prop->SetSpecular(0.4);
  prop->SetSpecularPower(30);
  t.Mapper->SetBuilderToKdTreeCPU();
  return t.Check(argc, argv, t.Render());
}
