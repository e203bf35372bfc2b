// Time steps played as new scalar arrays of one image: every frame equals a fresh mapper's
// render of its step (within 1/255), played as a reader hands steps over (ordinary arrays set
// one after the other) and through the time-step API (NewTimeStepArray's memory, the next step
// given to PrefetchTimeStep before each frame), for uint8 and float steps. Through the counters:
// every step after the first is a time step, and on the CUDA backend (SPACESKIP_BACKEND=cuda on
// the GPU machine) every step that was prefetched is found on the device, on the CPU backend
// none is.
// Misuse: an array type the mapper does not draw in place is refused by NewTimeStepArray (an
// error, nullptr); an array that cannot be prefetched (another tuple count) is said once in a
// warning and the frame is still right.
#include "SpaceSkipTestHelpers.h"

#include "vtkIntArray.h"

#include <cstring>
#include <vector>

namespace
{
constexpr int kN = 48;
constexpr int kHeld = 4;   // distinct steps
constexpr int kPlayed = 9; // frames, cycling over them

// Step k: two blobs moving along x and z, as `type` (VTK_UNSIGNED_CHAR or VTK_FLOAT).
void FillStep(vtkDataArray* a, int k)
{
  const double c1[3] = { 12.0 + 5 * k, 20, 24 }, c2[3] = { 34, 28, 10.0 + 6 * k };
  vtkIdType i = 0;
  for (int z = 0; z < kN; ++z)
  {
    for (int y = 0; y < kN; ++y)
    {
      for (int x = 0; x < kN; ++x, ++i)
      {
        double v = 0;
        for (const double* c : { c1, c2 })
        {
          const double d2 = (x - c[0]) * (x - c[0]) + (y - c[1]) * (y - c[1]) + (z - c[2]) * (z - c[2]);
          v = std::max(v, 250.0 * std::exp(-d2 / (2 * 6.0 * 6.0)));
        }
        a->SetComponent(i, 0, v < 20 ? 0 : std::floor(v));
      }
    }
  }
}

vtkSmartPointer<vtkDataArray> OrdinaryStep(int type, int k)
{
  vtkSmartPointer<vtkDataArray> a = vtk::TakeSmartPointer(vtkDataArray::CreateDataArray(type));
  a->SetNumberOfTuples(vtkIdType(kN) * kN * kN);
  FillStep(a, k);
  a->SetName("step");
  return a;
}

// Plays the steps on `mapper` (its input `image`); frame i against `reference[i % kHeld]`.
// Returns the largest difference (0..255) over all frames.
int Play(sstest::Scene& scene, vtkImageData* image, vtkSpaceSkippingVolumeMapper* mapper,
  const std::vector<vtkSmartPointer<vtkDataArray>>& steps,
  const std::vector<vtkSmartPointer<vtkImageData>>& reference, bool prefetch)
{
  scene.Volume->SetMapper(mapper);
  int worst = 0;
  for (int i = 0; i < kPlayed; ++i)
  {
    image->GetPointData()->SetScalars(steps[i % kHeld]);
    if (prefetch)
    {
      mapper->PrefetchTimeStep(steps[(i + 1) % kHeld]);
    }
    auto shot = scene.Shot();
    worst = std::max(worst, sstest::MaxDiff(reference[i % kHeld], shot));
  }
  return worst;
}
} // namespace

int TestSpaceSkippingVolumeTimeSteps(int, char*[])
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(kN, kN, kN);
  vtkNew<vtkSpaceSkippingVolumeMapper> ours;
  ours->SetInputData(image);
  ours->SetBackendToCPU(); // SPACESKIP_BACKEND=cuda on the GPU machine forces CUDA
  sstest::Scene scene(ours, 160, 160);
  sstest::SetupProperty(scene.Property, 0, 250, 0.5);
  int failures = 0;
  for (int type : { VTK_UNSIGNED_CHAR, VTK_FLOAT })
  {
    std::vector<vtkSmartPointer<vtkDataArray>> plain, api;
    for (int k = 0; k < kHeld; ++k)
    {
      plain.push_back(OrdinaryStep(type, k));
      vtkSmartPointer<vtkDataArray> a =
        vtk::TakeSmartPointer(ours->NewTimeStepArray(type, 1, vtkIdType(kN) * kN * kN));
      SS_CHECK(a && a->GetDataType() == type && a->GetNumberOfTuples() == vtkIdType(kN) * kN * kN);
      FillStep(a, k);
      a->SetName("step");
      api.push_back(a);
    }
    // The references: a fresh mapper and image per step, the same view.
    std::vector<vtkSmartPointer<vtkImageData>> reference;
    for (int k = 0; k < kHeld; ++k)
    {
      vtkNew<vtkImageData> still;
      still->SetDimensions(kN, kN, kN);
      still->GetPointData()->SetScalars(plain[k]);
      vtkNew<vtkSpaceSkippingVolumeMapper> fresh;
      fresh->SetInputData(still);
      fresh->SetBackendToCPU();
      scene.Volume->SetMapper(fresh);
      if (k == 0)
      {
        scene.View(30, 20, 1.3);
      }
      reference.push_back(scene.Shot());
    }
    const char* name = type == VTK_FLOAT ? "float" : "uint8";
    const int steps0 = ours->GetTimeStepCount(), fetched0 = ours->GetPrefetchedTimeStepCount();
    const int pageable = Play(scene, image, ours, plain, reference, false);
    const int steps1 = ours->GetTimeStepCount(), fetched1 = ours->GetPrefetchedTimeStepCount();
    const int prefetched = Play(scene, image, ours, api, reference, true);
    const int steps2 = ours->GetTimeStepCount(), fetched2 = ours->GetPrefetchedTimeStepCount();
    const std::string backend = ours->GetBackendUsed();
    std::cout << name << " (" << backend << "): ordinary arrays max |diff| " << pageable
              << "/255, time steps " << steps1 - steps0 << ", prefetched " << fetched1 - fetched0
              << "; time-step arrays + PrefetchTimeStep max |diff| " << prefetched
              << "/255, time steps " << steps2 - steps1 << ", prefetched " << fetched2 - fetched1
              << "\n";
    // Every frame its step's image; the ordinary arrays' first frame may follow another type's
    // volume (not a time step), every later one is.
    failures += pageable > 1 || prefetched > 1;
    failures += steps1 - steps0 < kPlayed - 1 || steps2 - steps1 != kPlayed;
    failures += fetched1 != fetched0; // nothing was asked to be prefetched
    // CUDA: each step after the API run's first frame was uploaded while the frame before it
    // was drawn. CPU: nothing to prefetch.
    const int expected = backend == "cuda" ? kPlayed - 1 : 0;
    if (fetched2 - fetched1 != expected)
    {
      std::cout << "  expected " << expected << " steps found on the device\n";
      ++failures;
    }
  }

  // Misuse: a type not drawn in place, then an array of another length as the next step.
  vtkNew<sstest::MessageCollector> messages;
  sstest::Observe(ours, messages);
  vtkDataArray* refused = ours->NewTimeStepArray(VTK_INT, 1, 8);
  SS_CHECK(refused == nullptr && messages->ErrorCount == 1);
  std::cout << "refused: " << messages->Errors << "\n";
  messages->Clear();
  vtkNew<vtkUnsignedCharArray> shorter;
  shorter->SetNumberOfTuples(vtkIdType(kN) * kN * (kN - 1));
  image->GetPointData()->SetScalars(OrdinaryStep(VTK_UNSIGNED_CHAR, 1));
  scene.Volume->SetMapper(ours);
  ours->PrefetchTimeStep(shorter);
  auto shot = scene.Shot();
  ours->PrefetchTimeStep(shorter);
  scene.Shot();
  std::cout << "mismatched next step: " << messages->WarningCount << " warning(s): " << messages->Warnings
            << "\n";
  SS_CHECK(messages->WarningCount == 1 && messages->Warnings.find("PrefetchTimeStep") != std::string::npos);
  SS_CHECK(messages->ErrorCount == 0);
  SS_CHECK(sstest::CountNonBackground(shot, sstest::kBlack) > 1000);
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
