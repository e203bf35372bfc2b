// DeviceMemoryBudget: a volume above the budget is kept sparse on the GPU (only the visible
// bricks resident) and draws the in-core image, also after a TF edit that shows new bricks and
// with shading; a budget below what a view needs falls back to the CPU backend with one warning,
// same image. Without a usable device (CI) the CPU backend ignores the budget: the test checks
// that it says "in core" and draws the same image.
#include "vtkColorTransferFunction.h"
#include "vtkNew.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkUnsignedCharArray.h"

#include "SpaceSkipTestHelpers.h"

#include <cstring>
#include <iostream>

namespace
{
// Gaussian blobs in uint8 on 192^3 points (7 MiB): a few percent of the volume visible.
vtkSmartPointer<vtkImageData> MakeSparseBlobs()
{
  return sstest::MakeBlobs(192, 192, 192,
    { { 40, 50, 60, 10 }, { 130, 70, 50, 14 }, { 90, 140, 150, 12 }, { 160, 160, 40, 7 } }, 250.0, 4);
}

// Transparent below `from`, then a ramp.
void SetRamp(vtkVolumeProperty* prop, double from)
{
  sstest::SetFunctions(prop, { { 0, 0.9, 0.3, 0.1 }, { 255, 1.0, 1.0, 0.2 } },
    { { 0, 0 }, { from, 0 }, { 255, 0.8 } });
}
} // namespace

int TestSpaceSkippingVolumeSparse(int, char*[])
{
  auto image = MakeSparseBlobs();
  auto mapper = sstest::NewMapper(image, vtkSpaceSkippingVolumeMapper::KdTreeCPU);
  vtkNew<sstest::MessageCollector> messages;
  sstest::Observe(mapper, messages);
  sstest::Scene s(mapper, 240, 240);
  s.View(30, 20);
  SetRamp(s.Property, 120);

  struct Step
  {
    const char* name;
    double from;
    bool shade;
  };
  const Step steps[] = { { "ramp-120", 120, false }, { "ramp-60 (new bricks visible)", 60, false },
    { "ramp-60 shaded", 60, true } };
  for (const Step& step : steps)
  {
    SetRamp(s.Property, step.from);
    s.Property->SetShade(step.shade ? 1 : 0);
    mapper->SetDeviceMemoryBudget(0);
    auto inCore = s.Shot();
    const std::string backend = mapper->GetBackendUsed();
    SS_CHECK(std::strcmp(mapper->GetResidency(), "in core") == 0);
    mapper->SetDeviceMemoryBudget(3); // MiB: below the 7 MiB volume
    auto sparse = s.Shot();
    const std::string residency = mapper->GetResidency();
    std::cout << "case " << step.name << ": backend " << backend << ", residency \"" << residency
              << "\", max |diff| in core vs budget " << sstest::MaxDiff(inCore, sparse) << "/255"
              << std::endl;
    SS_CHECK(sstest::CountNonBackground(inCore, sstest::kBlack) > 500);
    SS_CHECK(sstest::MaxDiff(inCore, sparse) <= 1);
    if (backend == "cuda")
    {
      SS_CHECK(residency.rfind("sparse:", 0) == 0);
      SS_CHECK(mapper->GetResidentBricks() > 0);
    }
    else
    {
      SS_CHECK(residency == "in core"); // the CPU backend keeps the volume in host memory
    }
  }

  // A budget no view fits: the CUDA backend gives the frame to the CPU backend, said once.
  SetRamp(s.Property, 5);
  s.Property->ShadeOff();
  mapper->SetDeviceMemoryBudget(0);
  auto inCore = s.Shot();
  const std::string backend = mapper->GetBackendUsed();
  messages->Clear();
  mapper->SetDeviceMemoryBudget(1);
  auto tiny = s.Shot();
  std::cout << "case budget 1 MiB, everything visible: backend " << mapper->GetBackendUsed()
            << ", max |diff| " << sstest::MaxDiff(inCore, tiny) << "/255, warnings: "
            << messages->Warnings << std::endl;
  SS_CHECK(sstest::MaxDiff(inCore, tiny) <= 1);
  if (backend == "cuda")
  {
    SS_CHECK(messages->WarningCount == 1);
    SS_CHECK(messages->Warnings.find("exceed the memory budget") != std::string::npos);
  }
  SS_CHECK(messages->ErrorCount == 0);
  return EXIT_SUCCESS;
}
