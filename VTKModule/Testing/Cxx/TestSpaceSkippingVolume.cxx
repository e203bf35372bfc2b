// A volume alone: the wavelet through vtkSpaceSkippingVolumeMapper (Grid builder), regression image.
#include "vtkPolyData.h"

#include "SpaceSkipTestHelpers.h"

#include <cstdlib>
#include <string>

int TestSpaceSkippingVolume(int argc, char* argv[])
{
  sstest::ImageTest t;
  vtkSpaceSkippingVolumeMapper* mapper = t.Mapper;
  mapper->SetBuilderToGrid();
  // A visible actor without geometry (ParaView's render view keeps one in every view): it writes
  // no depth, so the volume is still alone.
  vtkNew<vtkPolyData> nothing;
  vtkNew<vtkPolyDataMapper> nothingMapper;
  nothingMapper->SetInputData(nothing);
  vtkNew<vtkActor> empty;
  empty->SetMapper(nothingMapper);
  t.Stage.Renderer->AddActor(empty);

  // The volume must have drawn something, and only where the box projects (t.Check).
  const vtkIdType drawn = t.Render();
  std::cout << "build " << mapper->GetLastBuildSeconds() << " s, nodes " << mapper->GetNodeCount()
            << ", leaves " << mapper->GetLeafCount() << ", occupancy " << mapper->GetOccupancy()
            << "\n";
  SS_CHECK(mapper->GetBuildCount() == 1 && mapper->GetClassifyCount() == 1);
  SS_CHECK(mapper->GetOccupancy() > 0.0 && mapper->GetOccupancy() < 1.0);
  // A volume alone (and an actor of no geometry): nothing wrote depth before it, so the readback
  // is skipped.
  SS_CHECK(!mapper->GetLastFrameReadDepth());
  // SPACESKIP_BACKEND=cuda (Testing/gpu/run-gpu-vtk.sh) overrides SetBackendToCPU().
  const char* forced = std::getenv("SPACESKIP_BACKEND");
  const std::string expected = forced && std::string(forced) == "cuda" ? "cuda" : "cpu";
  SS_CHECK(std::string(mapper->GetBackendUsed()) == expected);
  return t.Check(argc, argv, drawn);
}
