// Bad input gives one clear error (or a warning and a fallback), never a crash, and rendering
// goes on: each case is rendered twice next to a good volume in the same window, then the good
// volume must still be drawn and the bad mapper must have reported exactly once.
#include "vtkBitArray.h"
#include "vtkCamera.h"
#include "vtkFloatArray.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkCellData.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "vtkPlane.h"

#include "SpaceSkipTestHelpers.h"

#include <functional>

namespace
{
vtkSmartPointer<vtkImageData> Blank(int n)
{
  auto img = vtkSmartPointer<vtkImageData>::New();
  img->SetDimensions(n, n, n);
  img->SetOrigin(40, 0, 0); // beside the good volume
  return img;
}
}

int TestSpaceSkippingVolumeBadInput(int, char*[])
{
  // The good volume every case renders next to.
  auto good = sstest::MakeWavelet(32);
  double range[2];
  good->GetScalarRange(range);
  vtkNew<vtkVolumeProperty> prop;
  sstest::SetupProperty(prop, range[0], range[1], 0.8);
  vtkNew<vtkSpaceSkippingVolumeMapper> goodMapper;
  goodMapper->SetInputData(good);
  vtkNew<vtkVolume> goodVolume;
  goodVolume->SetMapper(goodMapper);
  goodVolume->SetProperty(prop);

  vtkNew<vtkRenderer> ren;
  ren->AddVolume(goodVolume);
  vtkSmartPointer<vtkRenderWindow> win = sstest::NewTestWindow();
  win->SetMultiSamples(0);
  win->SetSize(160, 120);
  win->AddRenderer(ren);
  ren->GetActiveCamera()->SetPosition(20, 0, 150);
  ren->GetActiveCamera()->SetFocalPoint(20, 0, 0);
  ren->ResetCameraClippingRange(-20, 60, -20, 20, -20, 20);
  const double black[3] = { 0, 0, 0 };

  struct Case
  {
    std::string name;
    vtkSmartPointer<vtkImageData> input;
    std::string expect;   // substring of the message
    bool warningOnly;     // a warning and a fallback rather than an error and nothing drawn
    bool drawn;           // whether the bad volume itself still draws
    std::string array;    // array to select by name ("" = default scalars)
  };
  std::vector<Case> cases;
  {
    auto img = Blank(16); // dimensions but no arrays at all
    cases.push_back({ "no scalars", img, "no point scalars", false, false, "" });
  }
  {
    auto img = Blank(16);
    vtkNew<vtkFloatArray> a;
    a->SetName("cellvalues");
    a->SetNumberOfTuples(15 * 15 * 15);
    a->FillValue(100.f);
    img->GetCellData()->SetScalars(a);
    cases.push_back({ "cell scalars", img, "are cell data", false, false, "" });
  }
  {
    auto img = Blank(16);
    vtkNew<vtkBitArray> a;
    a->SetName("bits");
    a->SetNumberOfTuples(16 * 16 * 16);
    img->GetPointData()->SetScalars(a);
    cases.push_back({ "bit type", img, "scalar type bit is not supported", false, false, "" });
  }
  {
    auto img = vtkSmartPointer<vtkImageData>::New();
    img->SetExtent(0, -1, 0, -1, 0, -1);
    cases.push_back({ "empty extent", img, "empty extent", false, false, "" });
  }
  {
    auto img = Blank(16);
    img->DeepCopy(good);
    img->SetOrigin(40 - 16, -16, -16);
    cases.push_back({ "missing selected array", img, "no point scalars", false, false, "nope" });
  }
  {
    // int32: converted to float with a warning, and drawn.
    auto img = vtkSmartPointer<vtkImageData>::New();
    img->DeepCopy(good);
    img->SetOrigin(40 - 16, -16, -16);
    vtkDataArray* f = good->GetPointData()->GetScalars();
    vtkNew<vtkIntArray> a;
    a->SetName("ints");
    a->SetNumberOfTuples(f->GetNumberOfTuples());
    for (vtkIdType i = 0; i < f->GetNumberOfTuples(); ++i)
    {
      a->SetValue(i, static_cast<int>(f->GetComponent(i, 0)));
    }
    img->GetPointData()->SetScalars(a);
    cases.push_back({ "int32", img, "converted to float", true, true, "" });
  }

  int failures = 0;
  for (const Case& c : cases)
  {
    vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
    mapper->SetInputData(c.input);
    if (!c.array.empty())
    {
      mapper->SetScalarModeToUsePointFieldData();
      mapper->SelectScalarArray(c.array.c_str());
    }
    vtkNew<sstest::MessageCollector> messages;
    mapper->AddObserver(vtkCommand::ErrorEvent, messages);
    mapper->AddObserver(vtkCommand::WarningEvent, messages);
    vtkNew<vtkVolume> volume;
    volume->SetMapper(mapper);
    volume->SetProperty(prop);
    ren->AddVolume(volume);

    // Alone first (is the bad volume drawn?), then with the good one, twice (one message only).
    goodVolume->VisibilityOff();
    win->Render();
    const vtkIdType badDrawn = sstest::CountNonBackground(sstest::Capture(win), black);
    goodVolume->VisibilityOn();
    win->Render();
    win->Render();
    const vtkIdType drawn = sstest::CountNonBackground(sstest::Capture(win), black);
    const std::string& text = c.warningOnly ? messages->Warnings : messages->Errors;
    const int count = c.warningOnly ? messages->WarningCount : messages->ErrorCount;
    std::cout << c.name << ": " << (c.warningOnly ? "warnings " : "errors ") << count
              << ", bad volume pixels " << badDrawn << ", all pixels " << drawn << "\n    message: "
              << text << "\n";
    bool ok = count == 1 && text.find(c.expect) != std::string::npos;
    ok &= c.warningOnly ? messages->ErrorCount == 0 : true;
    ok &= c.drawn ? badDrawn > 500 : badDrawn == 0;
    ok &= drawn > 500; // the good volume still renders
    if (!ok)
    {
      std::cout << "  FAILED (expected one message containing \"" << c.expect << "\")\n";
      ++failures;
    }
    ren->RemoveVolume(volume);
  }

  // Unsupported rendering options: one warning each, the volume still drawn (as composite,
  // trilinear, uncropped); supported ones: no message.
  {
    struct Option
    {
      const char* name;
      std::function<void(vtkSpaceSkippingVolumeMapper*, vtkVolumeProperty*)> set;
      const char* expect;
    };
    const Option options[] = {
      { "slice blend mode without a slice function",
        [](vtkSpaceSkippingVolumeMapper* m, vtkVolumeProperty*) { m->SetBlendModeToSlice(); },
        "no slice function" },
      { "slice blend mode with a vtkPlane",
        [](vtkSpaceSkippingVolumeMapper* m, vtkVolumeProperty* p) {
          m->SetBlendModeToSlice();
          vtkNew<vtkPlane> plane;
          p->SetSliceFunction(plane);
        },
        nullptr },
      // Supported since issue 12: no message at all.
      // Nearest-voxel sampling (render/LabelSampler.h), supported with the label maps.
      { "nearest interpolation",
        [](vtkSpaceSkippingVolumeMapper*, vtkVolumeProperty* p) {
          p->SetInterpolationTypeToNearest();
        },
        nullptr },
      { "shading (headlight)",
        [](vtkSpaceSkippingVolumeMapper*, vtkVolumeProperty* p) { p->ShadeOn(); }, nullptr },
      { "MIP",
        [](vtkSpaceSkippingVolumeMapper* m, vtkVolumeProperty*) {
          m->SetBlendModeToMaximumIntensity();
        },
        nullptr },
    };
    for (const Option& o : options)
    {
      vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
      mapper->SetInputData(good);
      vtkNew<vtkVolumeProperty> p;
      p->DeepCopy(prop);
      o.set(mapper, p);
      vtkNew<sstest::MessageCollector> messages;
      mapper->AddObserver(vtkCommand::ErrorEvent, messages);
      mapper->AddObserver(vtkCommand::WarningEvent, messages);
      goodVolume->SetMapper(mapper);
      goodVolume->SetProperty(p);
      win->Render();
      win->Render();
      const vtkIdType drawn = sstest::CountNonBackground(sstest::Capture(win), black);
      std::cout << o.name << ": warnings " << messages->WarningCount << ", errors "
                << messages->ErrorCount << ", pixels " << drawn << "\n    message: "
                << messages->Warnings << "\n";
      const bool messageOk = o.expect
        ? messages->WarningCount == 1 && messages->Warnings.find(o.expect) != std::string::npos
        : messages->WarningCount == 0;
      if (!messageOk || messages->ErrorCount != 0 || drawn < 500)
      {
        std::cout << "  FAILED\n";
        ++failures;
      }
    }
    goodVolume->SetMapper(goodMapper);
    goodVolume->SetProperty(prop);
  }

  // A forced CUDA backend without a usable device: one warning, the CPU backend draws.
  {
    vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
    mapper->SetInputData(good);
    mapper->SetBackendToCUDA();
    vtkNew<sstest::MessageCollector> messages;
    mapper->AddObserver(vtkCommand::ErrorEvent, messages);
    mapper->AddObserver(vtkCommand::WarningEvent, messages);
    goodVolume->SetMapper(mapper);
    win->Render();
    win->Render();
    const vtkIdType drawn = sstest::CountNonBackground(sstest::Capture(win), black);
    const std::string used = mapper->GetBackendUsed();
    std::cout << "Backend CUDA requested: used " << used << ", warnings "
              << messages->WarningCount << ", errors " << messages->ErrorCount
              << ", pixels " << drawn << "\n    message: " << messages->Warnings << "\n";
    if (used == "cpu")
    {
      // No device here: the fallback must have been announced once.
      if (messages->WarningCount != 1 ||
        messages->Warnings.find("CUDA backend unavailable") == std::string::npos)
      {
        ++failures;
      }
    }
    else if (used != "cuda" || messages->WarningCount != 0)
    {
      ++failures;
    }
    if (messages->ErrorCount != 0 || drawn < 500)
    {
      ++failures;
    }
    goodVolume->SetMapper(goodMapper);
  }
  SS_CHECK(failures == 0);
  return EXIT_SUCCESS;
}
