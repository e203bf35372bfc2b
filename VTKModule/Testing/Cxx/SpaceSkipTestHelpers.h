// Shared scene pieces of the vtkSpaceSkippingVolumeMapper tests: a procedural volume, a transfer
// function with empty space, the window/renderer/camera scene, window capture, image metrics and
// a message-collecting observer.
#ifndef SpaceSkipTestHelpers_h
#define SpaceSkipTestHelpers_h

#include "SpaceSkipEglWindow.h"
#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkColorTransferFunction.h"
#include "vtkFloatArray.h"
#include "vtkCommand.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkPolyDataAlgorithm.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRTAnalyticSource.h"
#include "vtkRegressionTestImage.h"
#include "vtkRenderWindow.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkSphereSource.h"
#include "vtkTestUtilities.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWindowToImageFilter.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <iostream>
#include <limits>
#include <string>

namespace sstest
{

// A w x h RGBA float image as ParaView's vtkPVTransferFunction2D builds it: x over the scalar
// range, y over the normalised gradient magnitude; a box of opacity `a` over normalised value
// [x0, x1] and gradient magnitude [y0, y1], its colour varying along both axes.
inline vtkSmartPointer<vtkImageData> MakeBox2D(int w, int h, double x0, double x1, double y0, double y1, double a)
{
  auto img = vtkSmartPointer<vtkImageData>::New();
  img->SetDimensions(w, h, 1);
  img->AllocateScalars(VTK_FLOAT, 4);
  auto* s = vtkFloatArray::SafeDownCast(img->GetPointData()->GetScalars());
  for (int y = 0; y < h; ++y)
  {
    for (int x = 0; x < w; ++x)
    {
      const double u = (x + 0.5) / w, g = (y + 0.5) / h;
      const bool in = u >= x0 && u <= x1 && g >= y0 && g <= y1;
      const vtkIdType i = vtkIdType(y) * w + x;
      s->SetTypedComponent(i, 0, static_cast<float>(u));
      s->SetTypedComponent(i, 1, static_cast<float>(1.0 - g));
      s->SetTypedComponent(i, 2, 0.4f);
      s->SetTypedComponent(i, 3, in ? static_cast<float>(a) : 0.f);
    }
  }
  return img;
}

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

// Replaces `prop`'s colour function by the points {x, r, g, b} and its opacity function by the
// points {x, a}, in the order given.
inline void SetFunctions(vtkVolumeProperty* prop, std::initializer_list<std::array<double, 4>> rgb,
  std::initializer_list<std::array<double, 2>> opacity)
{
  vtkNew<vtkColorTransferFunction> ctf;
  for (const auto& p : rgb)
  {
    ctf->AddRGBPoint(p[0], p[1], p[2], p[3]);
  }
  vtkNew<vtkPiecewiseFunction> pwf;
  for (const auto& p : opacity)
  {
    pwf->AddPoint(p[0], p[1]);
  }
  prop->SetColor(ctf);
  prop->SetScalarOpacity(pwf);
}

// Colour ramp over [lo, hi]; opacity 0 below 55% of the range (empty space), rising to `top`.
inline void SetupProperty(vtkVolumeProperty* prop, double lo, double hi, double top = 0.6)
{
  SetFunctions(prop,
    { { lo, 0.1, 0.2, 0.9 }, { lo + 0.6 * (hi - lo), 0.9, 0.9, 0.9 }, { hi, 0.9, 0.3, 0.1 } },
    { { lo, 0.0 }, { lo + 0.55 * (hi - lo), 0.0 }, { hi, top } });
  prop->SetInterpolationTypeToLinear();
  prop->ShadeOff();
  prop->SetScalarOpacityUnitDistance(1.0);
}

// The same over `image`'s scalar range.
inline void SetupProperty(vtkVolumeProperty* prop, vtkImageData* image, double top = 0.6)
{
  double range[2];
  image->GetScalarRange(range);
  SetupProperty(prop, range[0], range[1], top);
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

// nx x ny x nz points whose scalars (array type A, named `name`) are value(x, y, z) at point
// indices (x, y, z).
template <class A, class F>
inline vtkSmartPointer<vtkImageData> MakePointField(int nx, int ny, int nz, const char* name, F value)
{
  auto img = vtkSmartPointer<vtkImageData>::New();
  img->SetDimensions(nx, ny, nz);
  vtkNew<A> a;
  a->SetName(name);
  a->SetNumberOfTuples(vtkIdType(nx) * ny * nz);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
      {
        a->SetValue((vtkIdType(z) * ny + y) * nx + x, value(x, y, z));
      }
  img->GetPointData()->SetScalars(a);
  return img;
}

// Gaussian blobs in uint8 ("blobs") on nx x ny x nz points: the largest of `peak` *
// exp(-d^2 / (2 s^2)) over the blobs {x, y, z, s} (point indices), values below `cut` set to 0.
inline vtkSmartPointer<vtkImageData> MakeBlobs(
  int nx, int ny, int nz, std::initializer_list<std::array<double, 4>> blobs, double peak, double cut = 0)
{
  return MakePointField<vtkUnsignedCharArray>(nx, ny, nz, "blobs", [&](int x, int y, int z) {
    double v = 0;
    for (const auto& b : blobs)
    {
      const double d2 = (x - b[0]) * (x - b[0]) + (y - b[1]) * (y - b[1]) + (z - b[2]) * (z - b[2]);
      v = std::max(v, peak * std::exp(-d2 / (2 * b[3] * b[3])));
    }
    return static_cast<unsigned char>(v < cut ? 0 : v);
  });
}

// `mapper` on the CUDA backend renders `win`; false (printing "no usable CUDA device (backend used:
// ..): <skipped>") where the frame was not drawn by CUDA.
inline bool RenderOnCUDA(vtkSpaceSkippingVolumeMapper* mapper, vtkRenderWindow* win, const char* skipped)
{
  mapper->SetBackendToCUDA();
  win->Render();
  if (std::string(mapper->GetBackendUsed()) != "cuda")
  {
    std::cout << "no usable CUDA device (backend used: " << mapper->GetBackendUsed()
              << "): " << skipped << "\n";
    return false;
  }
  return true;
}

// Points `volume` at `mapper`, renders the window and captures it.
inline vtkSmartPointer<vtkImageData> RenderWith(
  vtkRenderWindow* win, vtkVolume* volume, vtkAbstractVolumeMapper* mapper)
{
  volume->SetMapper(mapper);
  win->Render();
  return Capture(win);
}

// vtkSpaceSkippingVolumeMapper on `image` with `builder`, at `sampleDistance` (0: the mapper's
// own), with or without early ray termination.
inline vtkSmartPointer<vtkSpaceSkippingVolumeMapper> NewMapper(vtkImageData* image,
  int builder = vtkSpaceSkippingVolumeMapper::AutoBuilder, double sampleDistance = 0.0,
  bool earlyRayTermination = true)
{
  auto mapper = vtkSmartPointer<vtkSpaceSkippingVolumeMapper>::New();
  mapper->SetInputData(image);
  mapper->SetBuilder(builder);
  mapper->SetSampleDistance(sampleDistance);
  mapper->SetEarlyRayTermination(earlyRayTermination);
  return mapper;
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

// Observes `object`'s warnings and errors with `messages`.
inline void Observe(vtkObject* object, MessageCollector* messages)
{
  object->AddObserver(vtkCommand::WarningEvent, messages);
  object->AddObserver(vtkCommand::ErrorEvent, messages);
}

// An opaque actor of `source`'s output in colour (r, g, b).
inline vtkSmartPointer<vtkActor> MakeActor(vtkPolyDataAlgorithm* source, double r, double g, double b)
{
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(source->GetOutputPort());
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(r, g, b);
  return actor;
}

// A green sphere through the middle of the wavelet's box (part inside, part outside): opaque
// geometry the rays must stop at.
inline vtkSmartPointer<vtkActor> MakeSphereActor()
{
  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(8, 4, 6);
  sphere->SetRadius(11);
  sphere->SetThetaResolution(48);
  sphere->SetPhiResolution(48);
  return MakeActor(sphere, 0.2, 0.8, 0.3);
}

// The test's temporary directory (-T or VTK_TEMP_DIR), where the comparison tests leave images.
inline std::string TempDir(int argc, char* argv[])
{
  char* tempDir =
    vtkTestUtilities::GetArgOrEnvOrDefault("-T", argc, argv, "VTK_TEMP_DIR", "Testing/Temporary");
  const std::string dir = tempDir;
  delete[] tempDir;
  return dir;
}

inline void WritePNG(vtkImageData* img, const std::string& path)
{
  vtkNew<vtkPNGWriter> png;
  png->SetFileName(path.c_str());
  png->SetInputData(img);
  png->Write();
}

// Prints "case <name>: PSNR(<reference>, ours) = .. dB, max |diff| = ../255, drawn pixels <ref>
// .. ours .." (no newline: callers add their own details) and returns the PSNR.
inline double PrintComparison(const std::string& name, vtkImageData* reference, vtkImageData* ours,
  const char* referenceName = "vtkGPUVolumeRayCastMapper", const char* shortName = "gpu")
{
  const double bg[3] = { 0, 0, 0 };
  const double psnr = PSNR(reference, ours);
  std::cout << "case " << name << ": PSNR(" << referenceName << ", ours) = " << psnr
            << " dB, max |diff| = " << MaxDiff(reference, ours) << "/255, drawn pixels "
            << shortName << " " << CountNonBackground(reference, bg) << " ours "
            << CountNonBackground(ours, bg);
  return psnr;
}

// The image tests' background.
constexpr double kNavy[3] = { 0.1, 0.1, 0.2 };
constexpr double kBlack[3] = { 0, 0, 0 };

// One case of a test against vtkGPUVolumeRayCastMapper on kNavy: `volume` drawn by `gpu`, then by
// `ours`; prints the comparison, writes both images as <dir>/<test>-<name>-gpu.png and -ours.png,
// and counts a failure (printing FAILED) where the PSNR is below `minPSNR` or ours drew fewer
// than 5000 pixels. Returns ours' image.
inline vtkSmartPointer<vtkImageData> CompareWithGPU(vtkRenderWindow* win, vtkVolume* volume,
  vtkAbstractVolumeMapper* gpu, vtkAbstractVolumeMapper* ours, const std::string& dir,
  const std::string& test, const std::string& name, double minPSNR, int& failures)
{
  auto a = RenderWith(win, volume, gpu);
  auto b = RenderWith(win, volume, ours);
  const double psnr = PrintComparison(name, a, b);
  std::cout << "\n";
  WritePNG(a, dir + "/" + test + "-" + name + "-gpu.png");
  WritePNG(b, dir + "/" + test + "-" + name + "-ours.png");
  if (psnr < minPSNR || CountNonBackground(b, kNavy) < 5000)
  {
    std::cout << "  FAILED (threshold " << minPSNR << " dB)\n";
    ++failures;
  }
  return b;
}


// What every test draws in: `mapper` with `Property` as `Volume`, in one renderer with background
// `bg`, in a `width` x `height` window without multisampling (the baselines are made without).
// `interactive` gives the window an interactor before its first frame (the image tests: their -I
// option starts it).
class Scene
{
public:
  Scene(vtkAbstractVolumeMapper* mapper, int width, int height, const double bg[3] = kBlack,
    bool interactive = false)
  {
    this->Volume->SetMapper(mapper);
    // Trilinear, as ParaView's Volume and SetupProperty (vtkVolumeProperty's own default, nearest,
    // is honoured by the mapper and samples differently).
    this->Property->SetInterpolationTypeToLinear();
    this->Volume->SetProperty(this->Property);
    this->Renderer->SetBackground(bg[0], bg[1], bg[2]);
    this->Renderer->AddVolume(this->Volume);
    this->Window->SetMultiSamples(0);
    this->Window->SetSize(width, height);
    this->Window->AddRenderer(this->Renderer);
    if (interactive)
    {
      this->Interactor = vtkSmartPointer<vtkRenderWindowInteractor>::New();
      this->Interactor->SetRenderWindow(this->Window);
    }
  }

  vtkCamera* Camera() { return this->Renderer->GetActiveCamera(); }

  // The camera reset on everything shown (or on `bounds`), turned by `azimuth` then `elevation`
  // degrees (0: not turned), its view-up orthogonalized if asked, zoomed, clipping range reset.
  void View(double azimuth, double elevation, double zoom = 1.0, bool orthogonalize = false,
    const double* bounds = nullptr)
  {
    if (bounds)
    {
      this->Renderer->ResetCamera(bounds);
    }
    else
    {
      this->Renderer->ResetCamera();
    }
    vtkCamera* cam = this->Camera();
    if (azimuth != 0)
    {
      cam->Azimuth(azimuth);
    }
    if (elevation != 0)
    {
      cam->Elevation(elevation);
    }
    if (orthogonalize)
    {
      cam->OrthogonalizeViewUp();
    }
    if (zoom != 1.0)
    {
      cam->Zoom(zoom);
    }
    this->Renderer->ResetCameraClippingRange();
  }

  // Renders a frame and captures it.
  vtkSmartPointer<vtkImageData> Shot()
  {
    this->Window->Render();
    return Capture(this->Window);
  }

  // The last frame against the test's baseline (vtkRegressionTestImage); the test's exit code.
  int Regression(int argc, char* argv[])
  {
    const int retVal = vtkRegressionTestImage(this->Window);
    if (retVal == vtkRegressionTester::DO_INTERACTOR && this->Interactor)
    {
      this->Interactor->Start();
    }
    return !retVal;
  }

  vtkNew<vtkVolumeProperty> Property;
  vtkNew<vtkVolume> Volume;
  vtkNew<vtkRenderer> Renderer;
  vtkSmartPointer<vtkRenderWindow> Window = NewTestWindow(); // SpaceSkipEglWindow.h
  vtkSmartPointer<vtkRenderWindowInteractor> Interactor;
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


// The scene of the tests that compare with vtkGPUVolumeRayCastMapper case by case: the wavelet on
// 64^3 points (scalar range Lo..Hi) through the reference GPU mapper and ours (Grid, no
// warnings expected) at sample distance 0.5, 256 x 256, turned 35 and 25 degrees, zoomed 1.6.
struct VsGPUScene
{
  VsGPUScene()
    : Image(MakeWavelet(64))
    , Gpu(ReferenceGPUMapper(this->Image, kSampleDistance))
    , Ours(NewMapper(this->Image, vtkSpaceSkippingVolumeMapper::Grid, kSampleDistance, false))
    , Stage(this->Ours, 256, 256)
  {
    double range[2];
    this->Image->GetScalarRange(range);
    this->Lo = range[0];
    this->Hi = range[1];
    // Zoom (the view angle) and the turns commute: the order of the calls does not matter.
    this->Stage.View(35, 25, 1.6, true);
  }
  // One case's images (reference a, ours b): prints the PSNR, writes both under `dir` as
  // TEST-NAME-gpu.png / -ours.png, and counts a failure when ours draws fewer than 1000 pixels or
  // is below `minPSNR` of the reference (Worst: the lowest PSNR so far).
  void Judge(const std::string& dir, const char* test, const std::string& name, vtkImageData* a,
    vtkImageData* b, double minPSNR)
  {
    const double psnr = PrintComparison(name, a, b);
    std::cout << "\n";
    const vtkIdType drawn = CountNonBackground(b, kBlack);
    const std::string prefix = dir + "/" + test + "-" + name;
    WritePNG(a, prefix + "-gpu.png");
    WritePNG(b, prefix + "-ours.png");
    this->Worst = std::min(this->Worst, psnr);
    if (drawn < 1000 || psnr < minPSNR)
    {
      std::cout << "  FAILED\n";
      ++this->Failures;
    }
  }
  static constexpr double kSampleDistance = 0.5;
  double Worst = std::numeric_limits<double>::infinity();
  int Failures = 0;
  vtkSmartPointer<vtkImageData> Image;
  vtkSmartPointer<vtkGPUVolumeRayCastMapper> Gpu;
  vtkSmartPointer<vtkSpaceSkippingVolumeMapper> Ours;
  Scene Stage;
  double Lo = 0, Hi = 1;
};

// The image tests' scene: the wavelet on n^3 points through `Mapper` on the CPU backend (the
// baselines are CPU images; CUDA, forced by run-gpu-vtk.sh, equals them up to rounding) with
// SetupProperty's transfer function, 300 x 300 on kNavy, the camera turned 30 degrees in azimuth
// and 20 in elevation.
struct ImageTest
{
  explicit ImageTest(int n = 64)
    : Image(MakeWavelet(n))
  {
    this->Mapper->SetInputData(this->Image);
    this->Mapper->SetBackendToCPU();
    SetupProperty(this->Stage.Property, this->Image);
    this->Stage.View(30, 20);
  }

  // Renders and prints what was drawn (non-background pixels), by which backend and builder.
  vtkIdType Render()
  {
    const vtkIdType drawn = CountNonBackground(this->Stage.Shot(), kNavy);
    std::cout << "non-background pixels: " << drawn << " of " << 300 * 300 << ", backend "
              << this->Mapper->GetBackendUsed() << ", builder " << this->Mapper->GetBuilderUsed()
              << ", frame " << this->Mapper->GetLastRenderSeconds() << " s\n";
    return drawn;
  }

  // The checks of every image test, then the baseline: the volume drew something, and only
  // where its box projects; a backend ran (CPU here, CUDA where run-gpu-vtk.sh forces it: the
  // same baseline holds for both).
  int Check(int argc, char* argv[], vtkIdType drawn)
  {
    SS_CHECK(drawn > 5000 && drawn < 300 * 300);
    SS_CHECK(std::string(this->Mapper->GetBackendUsed()) != "none");
    return this->Stage.Regression(argc, argv);
  }

  // Every builder's image (Naive to DistanceGrid) against Naive's, each printed as "<label>builder
  // .. -> ..: max |diff| vs Naive ../255"; how many differ by more than 1/255.
  int BuildersAgainstNaive(const std::string& label)
  {
    int failures = 0;
    vtkSmartPointer<vtkImageData> naive;
    for (int b = vtkSpaceSkippingVolumeMapper::Naive; b <= vtkSpaceSkippingVolumeMapper::DistanceGrid; ++b)
    {
      this->Mapper->SetBuilder(b);
      auto shot = this->Stage.Shot();
      if (!naive)
      {
        naive = shot;
      }
      const int d = MaxDiff(naive, shot);
      std::cout << label << "builder " << this->Mapper->GetBuilderAsString() << " -> "
                << this->Mapper->GetBuilderUsed() << ": max |diff| vs Naive " << d << "/255\n";
      if (d > 1)
      {
        ++failures;
      }
    }
    return failures;
  }

  vtkSmartPointer<vtkImageData> Image;
  vtkNew<vtkSpaceSkippingVolumeMapper> Mapper;
  Scene Stage{ this->Mapper, 300, 300, kNavy, true };
};

} // namespace sstest

#endif
