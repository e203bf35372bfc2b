// Shared scene pieces of the vtkSpaceSkippingVolumeMapper tests: a procedural volume, a transfer
// function with empty space, window capture, image metrics and a message-collecting observer.
#ifndef SpaceSkipTestHelpers_h
#define SpaceSkipTestHelpers_h

#include "vtkColorTransferFunction.h"
#include "vtkCommand.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkRTAnalyticSource.h"
#include "vtkRenderWindow.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWindowToImageFilter.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>

namespace sstest
{

// The wavelet (float, range about [37, 277]) on n^3 points: smooth, with an opacity threshold
// it leaves large empty regions in the corners.
inline vtkSmartPointer<vtkImageData> MakeWavelet(int n = 64)
{
  vtkNew<vtkRTAnalyticSource> src;
  const int h = n / 2;
  src->SetWholeExtent(-h, n - 1 - h, -h, n - 1 - h, -h, n - 1 - h);
  src->SetCenter(0, 0, 0);
  src->Update();
  vtkSmartPointer<vtkImageData> img = vtkSmartPointer<vtkImageData>::New();
  img->DeepCopy(src->GetOutput());
  return img;
}

// Colour ramp over [lo, hi]; opacity 0 below 55% of the range (empty space), rising to `top`.
inline void SetupProperty(vtkVolumeProperty* prop, double lo, double hi, double top = 0.6)
{
  vtkNew<vtkColorTransferFunction> ctf;
  ctf->AddRGBPoint(lo, 0.1, 0.2, 0.9);
  ctf->AddRGBPoint(lo + 0.6 * (hi - lo), 0.9, 0.9, 0.9);
  ctf->AddRGBPoint(hi, 0.9, 0.3, 0.1);
  vtkNew<vtkPiecewiseFunction> pwf;
  pwf->AddPoint(lo, 0.0);
  pwf->AddPoint(lo + 0.55 * (hi - lo), 0.0);
  pwf->AddPoint(hi, top);
  prop->SetColor(ctf);
  prop->SetScalarOpacity(pwf);
  prop->SetInterpolationTypeToLinear();
  prop->ShadeOff();
  prop->SetScalarOpacityUnitDistance(1.0);
}

// The window's current RGB image (back buffer, after Render()).
inline vtkSmartPointer<vtkImageData> Capture(vtkRenderWindow* win)
{
  vtkNew<vtkWindowToImageFilter> w2i;
  w2i->SetInput(win);
  w2i->SetInputBufferTypeToRGB();
  w2i->ReadFrontBufferOff();
  w2i->ShouldRerenderOff();
  w2i->Update();
  vtkSmartPointer<vtkImageData> img = vtkSmartPointer<vtkImageData>::New();
  img->DeepCopy(w2i->GetOutput());
  return img;
}

// Points `volume` at `mapper`, renders the window and captures it.
inline vtkSmartPointer<vtkImageData> RenderWith(
  vtkRenderWindow* win, vtkVolume* volume, vtkAbstractVolumeMapper* mapper)
{
  volume->SetMapper(mapper);
  win->Render();
  return Capture(win);
}

// VTK's own GPU ray caster at a fixed sample distance, without jitter: the reference of the
// comparison tests.
inline vtkSmartPointer<vtkGPUVolumeRayCastMapper> ReferenceGPUMapper(
  vtkImageData* image, double sampleDistance)
{
  auto gpu = vtkSmartPointer<vtkGPUVolumeRayCastMapper>::New();
  gpu->SetInputData(image);
  gpu->AutoAdjustSampleDistancesOff();
  gpu->LockSampleDistanceToInputSpacingOff();
  gpu->SetSampleDistance(sampleDistance);
  gpu->UseJitteringOff();
  return gpu;
}

inline unsigned char* Pixels(vtkImageData* img)
{
  return static_cast<unsigned char*>(img->GetPointData()->GetScalars()->GetVoidPointer(0));
}

inline vtkIdType ByteCount(vtkImageData* img)
{
  return img->GetPointData()->GetScalars()->GetNumberOfValues();
}

// PSNR in dB over 8-bit RGB (infinity for identical images).
inline double PSNR(vtkImageData* a, vtkImageData* b)
{
  const vtkIdType n = ByteCount(a);
  if (n != ByteCount(b) || n == 0)
  {
    return -1;
  }
  const unsigned char* pa = Pixels(a);
  const unsigned char* pb = Pixels(b);
  double se = 0;
  for (vtkIdType i = 0; i < n; ++i)
  {
    const double d = double(pa[i]) - double(pb[i]);
    se += d * d;
  }
  if (se == 0)
  {
    return std::numeric_limits<double>::infinity();
  }
  return 10.0 * std::log10(255.0 * 255.0 / (se / double(n)));
}

inline int MaxDiff(vtkImageData* a, vtkImageData* b)
{
  const vtkIdType n = std::min(ByteCount(a), ByteCount(b));
  const unsigned char* pa = Pixels(a);
  const unsigned char* pb = Pixels(b);
  int m = 0;
  for (vtkIdType i = 0; i < n; ++i)
  {
    m = std::max(m, std::abs(int(pa[i]) - int(pb[i])));
  }
  return m;
}

// Pixels whose RGB differs from `bg` (0..1) by more than 2/255 in some channel.
inline vtkIdType CountNonBackground(vtkImageData* img, const double bg[3])
{
  const vtkIdType n = ByteCount(img) / 3;
  const unsigned char* p = Pixels(img);
  vtkIdType count = 0;
  for (vtkIdType i = 0; i < n; ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      if (std::abs(int(p[3 * i + c]) - int(std::lround(bg[c] * 255))) > 2)
      {
        ++count;
        break;
      }
    }
  }
  return count;
}

// Collects error and warning messages (an observed vtkErrorMacro is not printed, so expected
// messages do not trip ctest's "ERROR:" failure pattern).
class MessageCollector : public vtkCommand
{
public:
  static MessageCollector* New() { return new MessageCollector; }
  void Execute(vtkObject*, unsigned long event, void* data) override
  {
    const char* msg = static_cast<const char*>(data);
    if (event == vtkCommand::ErrorEvent)
    {
      this->Errors += msg ? msg : "";
      ++this->ErrorCount;
    }
    else if (event == vtkCommand::WarningEvent)
    {
      this->Warnings += msg ? msg : "";
      ++this->WarningCount;
    }
  }
  void Clear()
  {
    this->Errors.clear();
    this->Warnings.clear();
    this->ErrorCount = this->WarningCount = 0;
  }
  std::string Errors, Warnings;
  int ErrorCount = 0, WarningCount = 0;
};

#define SS_CHECK(cond)                                                                            \
  do                                                                                              \
  {                                                                                               \
    if (!(cond))                                                                                  \
    {                                                                                             \
      std::cerr << __FILE__ << ":" << __LINE__ << ": check failed: " #cond << std::endl;        \
      return EXIT_FAILURE;                                                                        \
    }                                                                                             \
  } while (0)

} // namespace sstest

#endif
