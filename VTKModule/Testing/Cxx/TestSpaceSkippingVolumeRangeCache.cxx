// vtkSpaceSkippingVolumeMapper::FillRangeCaches: the ranges it leaves in an array's caches are
// the ones VTK computes itself (GetRange skips NaN, GetFiniteRange +-Inf too), per component, for
// every type it fills; VTK reads them from there (an array whose values change behind VTK's back
// still answers the cached range); arrays it does not fill are left to VTK.
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkShortArray.h"
#include "vtkSmartPointer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnsignedShortArray.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>

namespace
{
int failures = 0;

void Check(bool ok, const std::string& what)
{
  std::printf("%s %s\n", ok ? "ok  " : "FAIL", what.c_str());
  failures += ok ? 0 : 1;
}

// Fills `a` (n tuples, nc components) with random values; floats get NaN and +-Inf here and there.
void Randomise(vtkDataArray* a, vtkIdType n, int nc, std::mt19937& rng)
{
  a->SetNumberOfComponents(nc);
  a->SetNumberOfTuples(n);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double lo = vtkDataArray::GetDataTypeMin(a->GetDataType());
  double hi = vtkDataArray::GetDataTypeMax(a->GetDataType());
  const bool real = a->GetDataType() == VTK_FLOAT || a->GetDataType() == VTK_DOUBLE;
  if (real)
  {
    lo = -1e6;
    hi = 1e6;
  }
  for (vtkIdType i = 0; i < n * nc; ++i)
  {
    double v = lo + u(rng) * (hi - lo);
    if (real && i % 997 == 5)
      v = std::numeric_limits<double>::quiet_NaN();
    else if (real && i % 1009 == 7)
      v = std::numeric_limits<double>::infinity();
    else if (real && i % 1013 == 11)
      v = -std::numeric_limits<double>::infinity();
    a->SetComponent(i / nc, static_cast<int>(i % nc), v);
  }
}

void Compare(vtkDataArray* a, const std::string& name)
{
  // VTK's own answer: a copy without caches.
  vtkSmartPointer<vtkDataArray> b = vtkSmartPointer<vtkDataArray>::Take(a->NewInstance());
  b->DeepCopy(a);
  Check(vtkSpaceSkippingVolumeMapper::FillRangeCaches(a), name + ": filled");
  Check(!vtkSpaceSkippingVolumeMapper::FillRangeCaches(a), name + ": filled once only");
  for (int c = 0; c < a->GetNumberOfComponents(); ++c)
  {
    double r[2], s[2], fr[2], fs[2];
    a->GetRange(r, c);
    b->GetRange(s, c);
    a->GetFiniteRange(fr, c);
    b->GetFiniteRange(fs, c);
    char line[256];
    std::snprintf(line, sizeof(line), "%s component %d: range [%g, %g] == VTK's [%g, %g], finite [%g, %g] == [%g, %g]",
      name.c_str(), c, r[0], r[1], s[0], s[1], fr[0], fr[1], fs[0], fs[1]);
    Check(r[0] == s[0] && r[1] == s[1] && fr[0] == fs[0] && fr[1] == fs[1], line);
  }
}

// One array of type A with random values, filled and compared with VTK's own ranges.
template <class A>
void Case(vtkIdType n, int nc, std::mt19937& rng, const std::string& name)
{
  vtkNew<A> a;
  Randomise(a, n, nc, rng);
  Compare(a, name);
}
}

int TestSpaceSkippingVolumeRangeCache(int, char*[])
{
  std::mt19937 rng(35);
  const vtkIdType n = 300007;
  Case<vtkUnsignedCharArray>(n, 1, rng, "uint8");
  Case<vtkShortArray>(n, 1, rng, "int16");
  Case<vtkUnsignedShortArray>(n, 2, rng, "uint16 x2");
  Case<vtkFloatArray>(4 * n, 1, rng, "float with NaN and +-Inf"); // more than one parallel chunk (2^20 values)
  Case<vtkDoubleArray>(n, 4, rng, "double x4 with NaN and +-Inf");
  {
    // VTK answers from the filled cache: values changed without Modified() are not seen.
    vtkNew<vtkFloatArray> a;
    Randomise(a, n, 1, rng);
    double before[2], after[2];
    vtkSpaceSkippingVolumeMapper::FillRangeCaches(a);
    a->GetFiniteRange(before, 0);
    a->GetPointer(0)[0] = 1e9f; // behind VTK's back
    a->GetFiniteRange(after, 0);
    Check(before[1] < 1e9 && after[1] == before[1], "GetFiniteRange reads the filled cache");
    a->Modified();
    a->GetFiniteRange(after, 0);
    Check(after[1] == 1e9, "after Modified() VTK computes again (1e9 seen)");
  }
  {
    vtkNew<vtkFloatArray> nan;
    nan->SetNumberOfTuples(1000);
    nan->FillValue(std::numeric_limits<float>::quiet_NaN());
    Check(!vtkSpaceSkippingVolumeMapper::FillRangeCaches(nan), "an array of NaN only is left to VTK");
    vtkNew<vtkIntArray> ints;
    Randomise(ints, 1000, 1, rng);
    Check(!vtkSpaceSkippingVolumeMapper::FillRangeCaches(ints), "an int32 array is left to VTK");
    vtkNew<vtkFloatArray> empty;
    Check(!vtkSpaceSkippingVolumeMapper::FillRangeCaches(empty), "an empty array is left to VTK");
    Check(!vtkSpaceSkippingVolumeMapper::FillRangeCaches(nullptr), "no array: nothing");
  }
  return failures == 0 ? 0 : 1;
}
