// vtkSpaceSkippingVolumeMapper: VTK types -> spaceskip::Engine, and the engine's image -> the window.
#include "vtkSpaceSkippingVolumeMapper.h"

#include "vtkColorTransferFunction.h"
#include "vtkContourValues.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkLogger.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLCamera.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderUtilities.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPlane.h"
#include "vtkPlaneCollection.h"
#include "vtkPointData.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkScalarsToColors.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtk_glew.h"

#include "spaceskip/Backend.h"
#include "spaceskip/Engine.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#ifdef SPACESKIP_HAVE_CUDA
// CUDA-GL interop for GPUComposite (runtime API only: no kernel here; GLEW already blocks gl.h).
#include <cuda_gl_interop.h>
#include <cuda_runtime_api.h>
#endif

#include <algorithm>
#include <array>
#include <chrono>
#include <set>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace
{
// Table resolution of the transfer function, sampled over the data's scalar range (what
// vtkGPUVolumeRayCastMapper does by default, ColorRangeType == SCALAR).
constexpr int kTableSize = 1024;
// BuilderTypes are cast to spaceskip::BuilderKind: the two enums must stay in the same order.
static_assert(static_cast<int>(spaceskip::BuilderKind::Hybrid) == vtkSpaceSkippingVolumeMapper::Hybrid &&
    static_cast<int>(spaceskip::BuilderKind::DistanceGrid) == vtkSpaceSkippingVolumeMapper::DistanceGrid,
  "vtkSpaceSkippingVolumeMapper::BuilderTypes out of step with spaceskip::BuilderKind");
// Opacity at which a ray stops when EarlyRayTermination is on (vtkGPUVolumeRayCastMapper's 0.99).
constexpr double kErtThreshold = 0.99;

static_assert(static_cast<int>(spaceskip::BlendMode::Isosurface) == vtkVolumeMapper::ISOSURFACE_BLEND &&
    static_cast<int>(spaceskip::BlendMode::MaximumIntensity) == vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND,
  "spaceskip::BlendMode out of step with vtkVolumeMapper's blend modes");

// Blend mode, iso values and shading from the mapper, the volume property and the renderer's
// lights, as vtkGPUVolumeRayCastMapper reads them. Lights: a headlight (VTK's default) or one
// directional light; anything else is lit by a headlight, said once through `warnedLight`.
void SetBlendAndShading(vtkVolumeMapper* mapper, int mode, spaceskip::RenderParams& rp,
  vtkRenderer* ren, vtkVolume* vol, const double scalarRange[2], bool& warnedLight)
{
  rp.blend = mode >= vtkVolumeMapper::COMPOSITE_BLEND && mode <= vtkVolumeMapper::ISOSURFACE_BLEND
    ? static_cast<spaceskip::BlendMode>(mode)
    : spaceskip::BlendMode::Composite; // slice: warned by the caller
  rp.isoValues.clear();
  vtkVolumeProperty* prop = vol->GetProperty();
  if (rp.blend == spaceskip::BlendMode::Isosurface)
  {
    vtkContourValues* iso = prop->GetIsoSurfaceValues();
    for (int i = 0; i < iso->GetNumberOfContours(); ++i)
    {
      rp.isoValues.push_back(iso->GetValue(i));
    }
  }
  rp.scalarRange[0] = scalarRange[0];
  rp.scalarRange[1] = scalarRange[1];
  const double* avg = mapper->GetAverageIPScalarRange();
  rp.averageRange[0] = avg[0];
  rp.averageRange[1] = avg[1];

  rp.shade = prop->GetShade(0) != 0;
  rp.ambient = prop->GetAmbient(0);
  rp.diffuse = prop->GetDiffuse(0);
  rp.specular = prop->GetSpecular(0);
  rp.specularPower = prop->GetSpecularPower(0);
  rp.lightDirection[0] = rp.lightDirection[1] = rp.lightDirection[2] = 0; // headlight
  if (!rp.shade)
  {
    return;
  }
  vtkLight* only = nullptr;
  int on = 0;
  vtkLightCollection* lights = ren->GetLights();
  vtkCollectionSimpleIterator it;
  lights->InitTraversal(it);
  while (vtkLight* l = lights->GetNextLight(it))
  {
    if (l->GetSwitch())
    {
      ++on;
      only = l;
    }
  }
  if (on == 1 && !only->LightTypeIsHeadlight() && !only->GetPositional())
  {
    // A directional light, from world into the volume's physical space (its matrix's inverse).
    double p[3], f[3];
    only->GetTransformedPosition(p);
    only->GetTransformedFocalPoint(f);
    vtkNew<vtkMatrix4x4> inv;
    vtkMatrix4x4::Invert(vol->GetMatrix(), inv);
    const double w[4] = { p[0] - f[0], p[1] - f[1], p[2] - f[2], 0.0 };
    double o[4];
    inv->MultiplyPoint(w, o);
    std::copy(o, o + 3, rp.lightDirection);
  }
  else if (on != 1 && !warnedLight)
  {
    vtkWarningWithObjectMacro(mapper,
      << "shading with " << on << " lights: only a headlight or a single directional light is "
      << "supported; shading with a headlight");
    warnedLight = true;
  }
  else if (on == 1 && only->GetPositional() && !warnedLight)
  {
    vtkWarningWithObjectMacro(
      mapper, << "positional lights are not supported; shading with a headlight");
    warnedLight = true;
  }
}

// Core voxel types by VTK type; int/unsigned int/long become float (see ConvertScalars).
bool CoreTypeOf(int vtkType, spaceskip::VoxelType& out)
{
  switch (vtkType)
  {
    case VTK_UNSIGNED_CHAR:
      out = spaceskip::VoxelType::UInt8;
      return true;
    case VTK_CHAR:
    case VTK_SIGNED_CHAR:
      out = spaceskip::VoxelType::Int8;
      return true;
    case VTK_UNSIGNED_SHORT:
      out = spaceskip::VoxelType::UInt16;
      return true;
    case VTK_SHORT:
      out = spaceskip::VoxelType::Int16;
      return true;
    case VTK_FLOAT:
      out = spaceskip::VoxelType::Float32;
      return true;
    case VTK_DOUBLE:
      out = spaceskip::VoxelType::Float64;
      return true;
    default:
      return false;
  }
}

bool ConvertibleToFloat(int vtkType)
{
  switch (vtkType)
  {
    case VTK_INT:
    case VTK_UNSIGNED_INT:
    case VTK_LONG:
    case VTK_UNSIGNED_LONG:
    case VTK_LONG_LONG:
    case VTK_UNSIGNED_LONG_LONG:
    case VTK_ID_TYPE:
      return true;
    default:
      return false;
  }
}

// SPACESKIP_BACKEND=cpu|cuda|auto forces the backend of every mapper in the process, whatever
// its Backend property says (tests and benchmarks on a GPU machine); -1 when unset or unknown.
int BackendFromEnvironment()
{
  const char* e = std::getenv("SPACESKIP_BACKEND");
  const std::string v = e ? e : "";
  if (v == "cpu" || v == "CPU")
  {
    return vtkSpaceSkippingVolumeMapper::CPU;
  }
  if (v == "cuda" || v == "CUDA")
  {
    return vtkSpaceSkippingVolumeMapper::CUDA;
  }
  if (v == "auto" || v == "Auto")
  {
    return vtkSpaceSkippingVolumeMapper::Auto;
  }
  return -1;
}

double SecondsSince(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Core's column-major mat4 from a row-major vtkMatrix4x4.
spaceskip::mat4 ToCore(const vtkMatrix4x4* m)
{
  spaceskip::mat4 out;
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      out.m[c * 4 + r] = m->GetElement(r, c);
    }
  }
  return out;
}
} // namespace

struct vtkSpaceSkippingVolumeMapper::vtkInternals
{
  std::unique_ptr<spaceskip::Engine> Engine;
  int EngineBackend = -1;
  spaceskip::Counters CountOffset; // stages run by engines replaced after a Backend change

  // What the engine was last given; compared by identity and MTime to redo only what changed.
  const void* InputKey = nullptr;
  const void* ScalarsKey = nullptr;
  vtkMTimeType InputMTime = 0;
  vtkMTimeType ScalarsMTime = 0;
  bool HaveVolume = false;
  std::vector<float> Converted; // int/long scalars converted to float
  // The array whose voxels the engine borrows: held so it outlives the engine's use of it.
  vtkSmartPointer<vtkDataArray> Borrowed;
  double ScalarRange[2] = { 0, 1 };

  const void* PropertyKey = nullptr;
  const void* ColorKey = nullptr;
  const void* OpacityKey = nullptr;
  vtkMTimeType PropertyMTime = 0;
  vtkMTimeType ColorMTime = 0;
  vtkMTimeType OpacityMTime = 0;
  double TableRange[2] = { 0, 0 };
  bool HaveTF = false;

  // One message per distinct problem, not one per frame.
  std::string LastProblem;
  // Warnings (engine fallbacks, clamps) already said by this mapper: each cause once, also
  // across the engines that backend switches create.
  std::set<std::string> Said;
  double SampleDistanceUsed = 0;
  std::string BuilderChoice;
  int Selection = 0; // the component the volume was made from; -1: the magnitude

  std::string BackendUsed = "none";
  std::string BuilderUsed = "none";
  // SPACESKIP_REPORT set: one stdout line per mapper whenever backend or builder changes.
  bool Report = std::getenv("SPACESKIP_REPORT") != nullptr;
  std::string Reported;

  // Where the last Render() spent its time (seconds; see the getters).
  double RangeSeconds = 0;
  double UpdateSeconds = 0;
  double DepthSeconds = 0;
  double EngineSeconds = 0;
  double CompositeSeconds = 0;
  double MapperSeconds = 0;

  spaceskip::Image Image;
  std::vector<unsigned char> Image8; // the image rounded to 8 bits for upload (EightBitComposite)
  // GPUComposite: a float RGBA texture registered with CUDA, filled from the engine's device image.
  vtkSmartPointer<vtkTextureObject> InteropTexture;
  void* InteropResource = nullptr; // cudaGraphicsResource_t
  int InteropSize[2] = { 0, 0 };
  bool InteropFailed = false; // once failed (e.g. GL on Mesa, another GPU): host path from then on
  std::string InteropProblem;
  std::string CompositePath = "none";
  std::vector<float> Depth;
  vtkSmartPointer<vtkTextureObject> Texture;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;
  vtkSmartPointer<vtkOpenGLFramebufferObject> Resolve; // single-sample copy of an MSAA depth
  bool ResolveStencil = false;
  bool WarnedNearest = false;
  bool WarnedLight = false;
  bool WarnedBlend = false;
  bool WarnedDepthRead = false;

  void ReleaseInterop()
  {
#ifdef SPACESKIP_HAVE_CUDA
    if (this->InteropResource)
    {
      cudaGraphicsUnregisterResource(static_cast<cudaGraphicsResource_t>(this->InteropResource));
      cudaGetLastError(); // a failure here (context gone) must not reach the engine's checks
    }
#endif
    this->InteropResource = nullptr;
    this->InteropSize[0] = this->InteropSize[1] = 0;
  }

  // Copies the engine's device image into InteropTexture; false (with the reason) on any failure.
  bool CopyToInteropTexture(vtkOpenGLRenderWindow* renWin, const void* image, int w, int h)
  {
#ifdef SPACESKIP_HAVE_CUDA
    auto failed = [this](const char* what, cudaError_t e) {
      this->InteropProblem = std::string(what) + ": " + cudaGetErrorString(e);
      cudaGetLastError();
      return false;
    };
    if (!this->InteropTexture || this->InteropSize[0] != w || this->InteropSize[1] != h)
    {
      this->ReleaseInterop();
      // Only NVIDIA's GL can share with CUDA: do not even ask another (the failing call would
      // show up as an API error in compute-sanitizer).
      const char* vendor = reinterpret_cast<const char*>(glGetString(GL_VENDOR));
      if (!vendor || !std::strstr(vendor, "NVIDIA"))
      {
        this->InteropProblem = std::string("the window's OpenGL is ") +
          (vendor ? vendor : "unknown") + "'s, not NVIDIA's";
        return false;
      }
      if (!this->InteropTexture)
      {
        this->InteropTexture = vtkSmartPointer<vtkTextureObject>::New();
      }
      this->InteropTexture->SetContext(renWin);
      this->InteropTexture->SetMinificationFilter(vtkTextureObject::Nearest);
      this->InteropTexture->SetMagnificationFilter(vtkTextureObject::Nearest);
      this->InteropTexture->SetWrapS(vtkTextureObject::ClampToEdge);
      this->InteropTexture->SetWrapT(vtkTextureObject::ClampToEdge);
      if (!this->InteropTexture->Allocate2D(
            static_cast<unsigned>(w), static_cast<unsigned>(h), 4, VTK_FLOAT))
      {
        this->InteropProblem = "could not allocate the float texture";
        return false;
      }
      cudaGraphicsResource_t r = nullptr;
      const cudaError_t e = cudaGraphicsGLRegisterImage(&r, this->InteropTexture->GetHandle(),
        GL_TEXTURE_2D, cudaGraphicsRegisterFlagsWriteDiscard);
      if (e != cudaSuccess)
      {
        return failed("cudaGraphicsGLRegisterImage", e);
      }
      this->InteropResource = r;
      this->InteropSize[0] = w;
      this->InteropSize[1] = h;
    }
    cudaGraphicsResource_t r = static_cast<cudaGraphicsResource_t>(this->InteropResource);
    cudaError_t e = cudaGraphicsMapResources(1, &r, nullptr);
    if (e != cudaSuccess)
    {
      return failed("cudaGraphicsMapResources", e);
    }
    cudaArray_t array = nullptr;
    e = cudaGraphicsSubResourceGetMappedArray(&array, r, 0, 0);
    if (e == cudaSuccess)
    {
      const size_t row = static_cast<size_t>(w) * 4 * sizeof(float);
      e = cudaMemcpy2DToArray(array, 0, 0, image, row, row, static_cast<size_t>(h),
        cudaMemcpyDeviceToDevice);
    }
    const cudaError_t u = cudaGraphicsUnmapResources(1, &r, nullptr);
    if (e != cudaSuccess)
    {
      return failed("copy into the GL texture", e);
    }
    if (u != cudaSuccess)
    {
      return failed("cudaGraphicsUnmapResources", u);
    }
    return true;
#else
    (void)renWin;
    (void)image;
    (void)w;
    (void)h;
    this->InteropProblem = "built without CUDA";
    return false;
#endif
  }

  void ResetVolume()
  {
    this->InputKey = this->ScalarsKey = nullptr;
    this->InputMTime = this->ScalarsMTime = 0;
    this->HaveVolume = false;
    this->Borrowed = nullptr;
  }
  void ResetTF()
  {
    this->PropertyKey = this->ColorKey = this->OpacityKey = nullptr;
    this->PropertyMTime = this->ColorMTime = this->OpacityMTime = 0;
    this->HaveTF = false;
  }
  spaceskip::Counters Counts() const
  {
    spaceskip::Counters c = this->CountOffset;
    if (this->Engine)
    {
      const spaceskip::Counters& e = this->Engine->counters();
      c.rangeGrids += e.rangeGrids;
      c.classifications += e.classifications;
      c.builds += e.builds;
      c.colorUpdates += e.colorUpdates;
      c.frames += e.frames;
    }
    return c;
  }
};

vtkStandardNewMacro(vtkSpaceSkippingVolumeMapper);

//------------------------------------------------------------------------------
vtkSpaceSkippingVolumeMapper::vtkSpaceSkippingVolumeMapper()
  : Internals(new vtkInternals)
{
}

//------------------------------------------------------------------------------
vtkSpaceSkippingVolumeMapper::~vtkSpaceSkippingVolumeMapper()
{
  this->Internals->ReleaseInterop();
}

//------------------------------------------------------------------------------
const char* vtkSpaceSkippingVolumeMapper::GetBuilderAsString()
{
  return spaceskip::builderName(static_cast<spaceskip::BuilderKind>(this->Builder));
}

//------------------------------------------------------------------------------
double vtkSpaceSkippingVolumeMapper::GetLastBuildSeconds()
{
  return this->Internals->Engine ? this->Internals->Engine->buildStats().seconds : 0.0;
}
double vtkSpaceSkippingVolumeMapper::GetLastClassifySeconds()
{
  return this->Internals->Engine ? this->Internals->Engine->buildStats().classifySeconds : 0.0;
}
double vtkSpaceSkippingVolumeMapper::GetLastRenderSeconds()
{
  return this->Internals->Engine ? this->Internals->Engine->frameStats().seconds : 0.0;
}
double vtkSpaceSkippingVolumeMapper::GetLastKernelSeconds()
{
  if (!this->Internals->Engine)
  {
    return 0.0;
  }
  const spaceskip::FrameStats& f = this->Internals->Engine->frameStats();
  return f.deviceSeconds >= 0 ? f.deviceSeconds : f.seconds;
}
double vtkSpaceSkippingVolumeMapper::GetLastScalarRangeSeconds()
{
  return this->Internals->RangeSeconds;
}
double vtkSpaceSkippingVolumeMapper::GetLastUpdateSeconds()
{
  return this->Internals->UpdateSeconds;
}
double vtkSpaceSkippingVolumeMapper::GetLastDepthReadSeconds()
{
  return this->Internals->DepthSeconds;
}
double vtkSpaceSkippingVolumeMapper::GetLastEngineRenderSeconds()
{
  return this->Internals->EngineSeconds;
}
double vtkSpaceSkippingVolumeMapper::GetLastCompositeSeconds()
{
  return this->Internals->CompositeSeconds;
}
double vtkSpaceSkippingVolumeMapper::GetLastMapperSeconds()
{
  return this->Internals->MapperSeconds;
}
vtkIdType vtkSpaceSkippingVolumeMapper::GetNodeCount()
{
  return this->Internals->Engine ? this->Internals->Engine->buildStats().nodes : 0;
}
int vtkSpaceSkippingVolumeMapper::GetTreeHeight()
{
  return this->Internals->Engine ? this->Internals->Engine->buildStats().height : 0;
}
vtkIdType vtkSpaceSkippingVolumeMapper::GetLeafCount()
{
  return this->Internals->Engine ? this->Internals->Engine->buildStats().leaves : 0;
}
double vtkSpaceSkippingVolumeMapper::GetOccupancy()
{
  return this->Internals->Engine ? this->Internals->Engine->buildStats().occupancy : 0.0;
}
const char* vtkSpaceSkippingVolumeMapper::GetBackendUsed()
{
  return this->Internals->BackendUsed.c_str();
}
const char* vtkSpaceSkippingVolumeMapper::GetBuilderUsed()
{
  return this->Internals->BuilderUsed.c_str();
}
const char* vtkSpaceSkippingVolumeMapper::GetCompositePathUsed()
{
  return this->Internals->CompositePath.c_str();
}
const char* vtkSpaceSkippingVolumeMapper::GetBuilderChoice()
{
  return this->Internals->BuilderChoice.c_str();
}
double vtkSpaceSkippingVolumeMapper::GetSampleDistanceUsed()
{
  return this->Internals->SampleDistanceUsed;
}
vtkIdType vtkSpaceSkippingVolumeMapper::GetDeviceBytesInUse()
{
  return static_cast<vtkIdType>(spaceskip::cudaDeviceBytesInUse());
}
void vtkSpaceSkippingVolumeMapper::WarnOnce(const std::string& message)
{
  if (this->Internals->Said.insert(message).second)
  {
    vtkWarningMacro(<< message);
  }
}
int vtkSpaceSkippingVolumeMapper::GetBuildCount()
{
  return this->Internals->Counts().builds;
}
int vtkSpaceSkippingVolumeMapper::GetClassifyCount()
{
  return this->Internals->Counts().classifications;
}
int vtkSpaceSkippingVolumeMapper::GetColorUpdateCount()
{
  return this->Internals->Counts().colorUpdates;
}
int vtkSpaceSkippingVolumeMapper::GetFrameCount()
{
  return this->Internals->Counts().frames;
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::ReleaseGraphicsResources(vtkWindow* win)
{
  vtkInternals& d = *this->Internals;
  if (d.Texture)
  {
    d.Texture->ReleaseGraphicsResources(win);
    d.Texture = nullptr;
  }
  if (d.Quad)
  {
    d.Quad->ReleaseGraphicsResources(win);
    d.Quad.reset();
  }
  if (d.Resolve)
  {
    d.Resolve->ReleaseGraphicsResources(win);
    d.Resolve = nullptr;
  }
  d.ReleaseInterop();
  if (d.InteropTexture)
  {
    d.InteropTexture->ReleaseGraphicsResources(win);
    d.InteropTexture = nullptr;
  }
  this->Superclass::ReleaseGraphicsResources(win);
}

//------------------------------------------------------------------------------
bool vtkSpaceSkippingVolumeMapper::ReadDepth(
  vtkOpenGLRenderWindow* renWin, int x0, int y0, int width, int height)
{
  vtkInternals& d = *this->Internals;
  vtkOpenGLState* ostate = renWin->GetState();
  while (glGetError() != GL_NO_ERROR)
  {
  }
  ostate->vtkglPixelStorei(GL_PACK_ALIGNMENT, 1);
  GLint sampleBuffers = 0;
  glGetIntegerv(GL_SAMPLE_BUFFERS, &sampleBuffers);
  if (sampleBuffers <= 0)
  {
    glReadPixels(x0, y0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, d.Depth.data());
    return glGetError() == GL_NO_ERROR;
  }

  // Multisampled framebuffer: resolve its depth into a single-sample framebuffer of the same
  // depth format (what vtkOpenGLRenderWindow allocates: 32 bits, stencil when the window has
  // one), over the same rectangle (a multisample blit cannot move pixels), then read that.
  GLint source = 0;
  glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &source);
  const int needW = x0 + width, needH = y0 + height;
  const bool stencil = renWin->GetStencilCapable() != 0;
  ostate->PushFramebufferBindings();
  if (!d.Resolve || d.ResolveStencil != stencil)
  {
    d.Resolve = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    d.Resolve->SetContext(renWin);
    d.Resolve->Bind();
    d.Resolve->PopulateFramebuffer(needW, needH, true, 1, VTK_UNSIGNED_CHAR, true, 32, 0, stencil);
    d.ResolveStencil = stencil;
  }
  else
  {
    int* size = d.Resolve->GetLastSize();
    if (size[0] != needW || size[1] != needH)
    {
      d.Resolve->Bind();
      d.Resolve->Resize(needW, needH);
    }
  }
  ostate->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<unsigned int>(source));
  d.Resolve->Bind(GL_DRAW_FRAMEBUFFER);
  glBlitFramebuffer(x0, y0, x0 + width, y0 + height, x0, y0, x0 + width, y0 + height,
    GL_DEPTH_BUFFER_BIT, GL_NEAREST);
  d.Resolve->Bind(GL_READ_FRAMEBUFFER);
  glReadPixels(x0, y0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, d.Depth.data());
  const bool ok = glGetError() == GL_NO_ERROR;
  ostate->PopFramebufferBindings();
  return ok;
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  vtkInternals& d = *this->Internals;
  // Reports a problem once (until the next different one), draws nothing.
  auto fail = [&](const std::string& msg) {
    if (msg != d.LastProblem)
    {
      vtkErrorMacro(<< msg);
      d.LastProblem = msg;
    }
  };

  vtkOpenGLRenderWindow* renWin = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  vtkOpenGLCamera* cam = vtkOpenGLCamera::SafeDownCast(ren->GetActiveCamera());
  if (!renWin || !cam || !vol || !vol->GetProperty())
  {
    fail("needs an OpenGL render window, an OpenGL camera and a volume with a property");
    return;
  }

  // Input.
  if (this->GetNumberOfInputConnections(0) > 0 && this->GetInputAlgorithm())
  {
    this->GetInputAlgorithm()->Update();
  }
  vtkImageData* input = vtkImageData::SafeDownCast(this->GetInput());
  if (!input)
  {
    fail("no vtkImageData input: nothing drawn");
    return;
  }
  int ext[6];
  input->GetExtent(ext);
  if (ext[1] < ext[0] || ext[3] < ext[2] || ext[5] < ext[4])
  {
    fail("input has an empty extent: nothing drawn");
    return;
  }
  int cellFlag = 0;
  vtkDataArray* scalars = vtkAbstractMapper::GetScalars(input, this->ScalarMode,
    this->ArrayAccessMode, this->ArrayId, this->ArrayName, cellFlag);
  if (!scalars)
  {
    fail("input has no point scalars (or the selected array does not exist): nothing drawn");
    return;
  }
  if (cellFlag)
  {
    fail(std::string("scalars '") + (scalars->GetName() ? scalars->GetName() : "") +
      "' are cell data; only point scalars are supported (apply vtkCellDataToPointData): "
      "nothing drawn");
    return;
  }
  // Several components: the one selected by VectorMode/VectorComponent (ParaView's colour
  // array component, or Magnitude) is rendered, as vtkSmartVolumeMapper does.
  const int ncomp = scalars->GetNumberOfComponents();
  const bool magnitude = ncomp > 1 && this->VectorMode == vtkScalarsToColors::MAGNITUDE;
  const int component = ncomp > 1 && !magnitude ? std::min(std::max(this->VectorComponent, 0), ncomp - 1) : 0;
  if (ncomp > 1 && vol->GetProperty() && !vol->GetProperty()->GetIndependentComponents())
  {
    this->WarnOnce("dependent components (direct RGBA, or value + opacity: Multi Components "
                   "Mapping) are not supported; rendering " +
      std::string(magnitude ? "the magnitude" : "component " + std::to_string(component)) +
      " through the transfer functions");
  }
  const vtkIdType npts = input->GetNumberOfPoints();
  if (scalars->GetNumberOfTuples() != npts)
  {
    fail("scalar array length does not match the number of points: nothing drawn");
    return;
  }
  spaceskip::VoxelType vtype = spaceskip::VoxelType::Float32;
  const int stype = scalars->GetDataType();
  const bool native = CoreTypeOf(stype, vtype);
  if (!native && !ConvertibleToFloat(stype))
  {
    fail(std::string("scalar type ") + scalars->GetDataTypeAsString() +
      " is not supported (uint8, int8, uint16, int16, float, double; int/long are converted "
      "to float): nothing drawn");
    return;
  }

  const auto tRender = std::chrono::steady_clock::now();
  d.RangeSeconds = d.UpdateSeconds = d.DepthSeconds = d.EngineSeconds = d.CompositeSeconds = 0;
  const int forced = BackendFromEnvironment();
  const int backend = forced >= 0 ? forced : this->Backend;

  // Engine (re)created when the backend changes; counts are carried over.
  if (!d.Engine || d.EngineBackend != backend)
  {
    d.CountOffset = d.Counts();
    d.Engine.reset();
    try
    {
      // Engine(CUDA) would report a missing device before setLogger() can route the message to
      // VTK; Auto makes the same choice silently and the mapper reports it below.
      const spaceskip::BackendKind kind = backend == CPU ? spaceskip::BackendKind::CPU
                                                               : spaceskip::BackendKind::Auto;
      d.Engine.reset(new spaceskip::Engine(kind));
    }
    catch (const std::exception& e)
    {
      fail(std::string("cannot create the SpaceSkip engine: ") + e.what());
      return;
    }
    d.Engine->setLogger([this](const std::string& m) { this->WarnOnce(m); });
    d.EngineBackend = backend;
    if (backend == CUDA && d.Engine->backendKind() != spaceskip::BackendKind::CUDA)
    {
      this->WarnOnce("CUDA backend unavailable (no usable CUDA device, or SpaceSkip built "
                     "without CUDA); using the CPU backend");
    }
    d.ResetVolume();
    d.ResetTF();
  }
  spaceskip::Engine& engine = *d.Engine;

  try
  {
    // Volume: only when the data changed (the engine then recomputes its value ranges).
    const int selection = magnitude ? -1 : component;
    if (!d.HaveVolume || d.InputKey != input || d.InputMTime != input->GetMTime() ||
      d.ScalarsKey != scalars || d.ScalarsMTime != scalars->GetMTime() ||
      d.Selection != selection)
    {
      d.Selection = selection;
      spaceskip::Volume v;
      int dims[3];
      input->GetDimensions(dims);
      v.dims = spaceskip::vec3l{ dims[0], dims[1], dims[2] };
      const double* sp = input->GetSpacing();
      std::copy(sp, sp + 3, v.spacing);
      input->TransformIndexToPhysicalPoint(ext[0], ext[2], ext[4], v.origin);
      const double* dir = input->GetDirectionMatrix()->GetData();
      std::copy(dir, dir + 9, v.direction);
      if (native && ncomp == 1 && scalars->HasStandardMemoryLayout())
      {
        v.type = vtype;
        v.data = scalars->GetVoidPointer(0);
        d.Borrowed = scalars;
        d.Converted.clear();
        d.Converted.shrink_to_fit();
      }
      else
      {
        if (!native)
        {
          this->WarnOnce(std::string("scalar type ") + scalars->GetDataTypeAsString() +
            " converted to float (values beyond 2^24 lose precision)");
        }
        d.Converted.resize(static_cast<size_t>(npts));
        float* out = d.Converted.data();
        vtkSMPTools::For(0, npts, [&](vtkIdType begin, vtkIdType end) {
          std::vector<double> tuple(static_cast<size_t>(ncomp));
          for (vtkIdType i = begin; i < end; ++i)
          {
            if (magnitude)
            {
              scalars->GetTuple(i, tuple.data());
              double m = 0;
              for (double c : tuple)
              {
                m += c * c;
              }
              out[i] = static_cast<float>(std::sqrt(m));
            }
            else
            {
              out[i] = static_cast<float>(scalars->GetComponent(i, component));
            }
          }
        });
        v.type = spaceskip::VoxelType::Float32;
        v.data = d.Converted.data();
        d.Borrowed = nullptr;
      }
      engine.setVolume(v);
      // One parallel pass over the voxels the engine reads (vtkDataArray::GetFiniteRange was
      // serial here: 267 s for the first frame of a 2048^3 uint8 volume).
      const auto tRange = std::chrono::steady_clock::now();
      if (!v.scalarRange(d.ScalarRange[0], d.ScalarRange[1]))
      {
        d.ScalarRange[0] = 0; // no finite value at all: an empty table range
        d.ScalarRange[1] = 1;
      }
      d.RangeSeconds = SecondsSince(tRange);
      d.InputKey = input;
      d.InputMTime = input->GetMTime();
      d.ScalarsKey = scalars;
      d.ScalarsMTime = scalars->GetMTime();
      d.HaveVolume = true;
    }

    // Transfer function: resampled only when the property or one of its functions changed;
    // the engine itself tells a colour-only edit from an opacity edit.
    vtkVolumeProperty* prop = vol->GetProperty();
    const bool gray = prop->GetColorChannels(0) == 1;
    vtkObject* color = gray ? static_cast<vtkObject*>(prop->GetGrayTransferFunction(0))
                            : static_cast<vtkObject*>(prop->GetRGBTransferFunction(0));
    vtkPiecewiseFunction* opacity = prop->GetScalarOpacity(0);
    double lo = d.ScalarRange[0], hi = d.ScalarRange[1];
    if (!(hi > lo))
    {
      hi = lo + 1.0; // constant volume: any non-empty range samples its one value
    }
    if (!d.HaveTF || d.PropertyKey != prop || d.PropertyMTime != prop->GetMTime() ||
      d.ColorKey != color || d.ColorMTime != color->GetMTime() || d.OpacityKey != opacity ||
      d.OpacityMTime != opacity->GetMTime() || d.TableRange[0] != lo || d.TableRange[1] != hi)
    {
      spaceskip::TransferFunction tf;
      tf.rangeMin = lo;
      tf.rangeMax = hi;
      tf.unitDistance = std::max(prop->GetScalarOpacityUnitDistance(0), 1e-12);
      std::vector<float> rgb(3 * kTableSize), alpha(kTableSize);
      if (gray)
      {
        std::vector<float> g(kTableSize);
        static_cast<vtkPiecewiseFunction*>(color)->GetTable(lo, hi, kTableSize, g.data());
        for (int i = 0; i < kTableSize; ++i)
        {
          rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = g[i];
        }
      }
      else
      {
        static_cast<vtkColorTransferFunction*>(color)->GetTable(lo, hi, kTableSize, rgb.data());
      }
      opacity->GetTable(lo, hi, kTableSize, alpha.data());
      tf.table.resize(kTableSize);
      for (int i = 0; i < kTableSize; ++i)
      {
        tf.table[i] = spaceskip::vec4f{ rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2],
          std::min(std::max(alpha[i], 0.f), 1.f) };
      }
      engine.setTransferFunction(tf);
      d.PropertyKey = prop;
      d.PropertyMTime = prop->GetMTime();
      d.ColorKey = color;
      d.ColorMTime = color->GetMTime();
      d.OpacityKey = opacity;
      d.OpacityMTime = opacity->GetMTime();
      d.TableRange[0] = lo;
      d.TableRange[1] = hi;
      d.HaveTF = true;
    }
    // Features of vtkVolumeProperty/vtkVolumeMapper the engine does not have: said once each.
    auto unsupported = [&](bool used, bool& warned, const char* what) {
      if (used && !warned)
      {
        vtkWarningMacro(<< what);
      }
      warned = warned || used;
    };
    unsupported(prop->GetInterpolationType() == VTK_NEAREST_INTERPOLATION, d.WarnedNearest,
      "nearest interpolation is not supported; rendering with trilinear interpolation");
    const int blend = this->EffectiveBlendMode();
    unsupported(blend == vtkVolumeMapper::SLICE_BLEND || blend < vtkVolumeMapper::COMPOSITE_BLEND ||
        blend > vtkVolumeMapper::SLICE_BLEND,
      d.WarnedBlend, "the slice blend mode is not supported; rendering with composite blending");

    spaceskip::BuildParams bp;
    bp.builder = static_cast<spaceskip::BuilderKind>(this->Builder);
    bp.leaf = static_cast<spaceskip::LeafCriterion>(this->LeafCriterion);
    bp.maxLeafSize = this->MaxLeafSize;
    bp.bins = this->BinCount;
    // A new size makes the engine recompute the value ranges, re-classify and rebuild.
    bp.brick = this->MacroCellSize;
    engine.setBuildParams(bp);
    spaceskip::RenderParams rp = engine.renderParams();
    rp.sampleDistance = this->SampleDistance;
    rp.ertThreshold = this->EarlyRayTermination ? kErtThreshold : 2.0;
    rp.jitter = this->UseJittering != 0;
    // Cropping: the planes are in the data's coordinates, as the engine's.
    rp.cropping = this->Cropping != 0;
    std::copy(this->CroppingRegionPlanes, this->CroppingRegionPlanes + 6, rp.croppingPlanes);
    rp.croppingFlags = this->CroppingRegionFlags;
    // Clipping planes are in world coordinates; the engine works in the data's, so each plane
    // n.X + d >= 0 becomes (A^T n).x + (n.t + d) >= 0 for X = A x + t, A the volume's matrix.
    rp.clipPlanes.clear();
    if (this->ClippingPlanes)
    {
      vtkMatrix4x4* A = vol->GetMatrix();
      this->ClippingPlanes->InitTraversal();
      while (vtkPlane* plane = this->ClippingPlanes->GetNextItem())
      {
        double n[3], p[3];
        plane->GetNormal(n);
        plane->GetOrigin(p);
        std::array<double, 4> c{};
        for (int k = 0; k < 3; ++k)
        {
          c[k] = n[0] * A->GetElement(0, k) + n[1] * A->GetElement(1, k) + n[2] * A->GetElement(2, k);
        }
        c[3] = n[0] * (A->GetElement(0, 3) - p[0]) + n[1] * (A->GetElement(1, 3) - p[1]) +
          n[2] * (A->GetElement(2, 3) - p[2]);
        rp.clipPlanes.push_back(c);
      }
    }
    // Where vtkGPUVolumeRayCastMapper samples first: one step in, or the jitter alone.
    rp.firstSampleOffset = this->UseJittering ? 0.0 : 1.0;
    SetBlendAndShading(this, this->EffectiveBlendMode(), rp, ren, vol, d.ScalarRange, d.WarnedLight);
    engine.setRenderParams(rp);

    // Camera: the volume's matrix is folded into the view, so the engine marches in the
    // image's physical space and the projected depth matches what OpenGL drew.
    vtkMatrix4x4* wcvc;
    vtkMatrix3x3* norms;
    vtkMatrix4x4* vcdc;
    vtkMatrix4x4* wcdc;
    cam->GetKeyMatrices(ren, wcvc, norms, vcdc, wcdc);
    vtkNew<vtkMatrix4x4> view, proj, viewModel;
    vtkMatrix4x4::Transpose(wcvc, view); // key matrices are stored transposed for OpenGL
    vtkMatrix4x4::Transpose(vcdc, proj);
    vtkMatrix4x4::Multiply4x4(view, vol->GetMatrix(), viewModel);
    spaceskip::Camera camera;
    camera.view = ToCore(viewModel);
    camera.proj = ToCore(proj);

    int width, height, x0, y0;
    ren->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
    if (width <= 0 || height <= 0)
    {
      return;
    }

    // Ranges, upload, classification, build: whatever the changes above left to do.
    auto t0 = std::chrono::steady_clock::now();
    engine.update();
    d.UpdateSeconds = SecondsSince(t0);

    // Depth of the opaque geometry already drawn, read from the framebuffer being rendered.
    t0 = std::chrono::steady_clock::now();
    vtkOpenGLState* ostate = renWin->GetState();
    const float* depth = nullptr;
    d.Depth.resize(static_cast<size_t>(width) * static_cast<size_t>(height));
    if (this->ReadDepth(renWin, x0, y0, width, height))
    {
      depth = d.Depth.data();
    }
    else if (!d.WarnedDepthRead)
    {
      vtkWarningMacro(<< "could not read the depth buffer: the volume ignores opaque geometry");
      d.WarnedDepthRead = true;
    }

    d.DepthSeconds = SecondsSince(t0);

    const int buildsBefore = engine.counters().builds;
    // GPUComposite: the CUDA backend leaves the image on the device for the interop copy below.
    const bool wantInterop = this->GPUComposite && !d.InteropFailed &&
      engine.backendKind() == spaceskip::BackendKind::CUDA;
    engine.setImageOnDevice(wantInterop);
    t0 = std::chrono::steady_clock::now();
    engine.render(camera, width, height, d.Image, depth);
    d.EngineSeconds = SecondsSince(t0);
    if (engine.counters().builds != buildsBefore)
    {
      const spaceskip::BuildStats& bs = engine.buildStats();
      vtkVLogF(vtkLogger::VERBOSITY_TRACE,
        "vtkSpaceSkippingVolumeMapper: built %s on %s in %.6f s (classify %.6f s): %lld nodes, "
        "height %d, %lld leaves, occupancy %.4f",
        spaceskip::builderName(bs.builder), bs.builtOn.c_str(), bs.seconds, bs.classifySeconds,
        static_cast<long long>(bs.nodes), bs.height, static_cast<long long>(bs.leaves),
        bs.occupancy);
    }
    vtkVLogF(vtkLogger::VERBOSITY_TRACE, "vtkSpaceSkippingVolumeMapper: %dx%d frame in %.6f s on %s",
      width, height, engine.frameStats().seconds, engine.frameStats().backend.c_str());
    d.BackendUsed = engine.frameStats().backend;
    d.BuilderUsed = spaceskip::builderName(engine.buildStats().builder);
    d.SampleDistanceUsed = engine.sampleDistance();
    d.BuilderChoice = engine.buildStats().choice;
    t0 = std::chrono::steady_clock::now();
    vtkTextureObject* image = nullptr;
    if (const void* deviceImage = engine.deviceImage())
    {
      if (d.CopyToInteropTexture(renWin, deviceImage, width, height))
      {
        image = d.InteropTexture;
        d.CompositePath = "gpu";
      }
      else
      {
        // Not this GL (Mesa, another device) or a CUDA error: the host path from now on, and
        // this frame again through host memory.
        vtkVLogF(vtkLogger::VERBOSITY_INFO,
          "vtkSpaceSkippingVolumeMapper: CUDA-GL interop unavailable (%s); the image goes "
          "through host memory", d.InteropProblem.c_str());
        d.InteropFailed = true;
        d.ReleaseInterop();
        engine.setImageOnDevice(false);
        engine.render(camera, width, height, d.Image, depth);
      }
    }
    if (d.Report && d.Reported != d.BackendUsed + d.BuilderUsed + d.CompositePath)
    {
      // What actually ran, for logs of test and benchmark runs on other machines.
      const GLubyte* glRenderer = glGetString(GL_RENDERER);
      const GLubyte* glVendor = glGetString(GL_VENDOR);
      std::cout << "SpaceSkip: backend " << d.BackendUsed << ", builder " << d.BuilderUsed
                << ", GL_RENDERER " << (glRenderer ? reinterpret_cast<const char*>(glRenderer) : "?")
                << ", GL_VENDOR " << (glVendor ? reinterpret_cast<const char*>(glVendor) : "?")
                << ", image " << (image ? "on the GPU (CUDA-GL interop)" : "through host memory")
                << (d.InteropFailed ? " (interop: " + d.InteropProblem + ")" : std::string())
                << std::endl;
      d.Reported = d.BackendUsed + d.BuilderUsed + d.CompositePath;
    }

    // Composite: premultiplied RGBA over what is drawn, (ONE, ONE_MINUS_SRC_ALPHA).
    if (!d.Texture)
    {
      d.Texture = vtkSmartPointer<vtkTextureObject>::New();
    }
    d.Texture->SetContext(renWin);
    d.Texture->SetMinificationFilter(vtkTextureObject::Nearest);
    d.Texture->SetMagnificationFilter(vtkTextureObject::Nearest);
    d.Texture->SetWrapS(vtkTextureObject::ClampToEdge);
    d.Texture->SetWrapT(vtkTextureObject::ClampToEdge);
    if (image)
    {
      // Drawn below from the interop texture.
    }
    else if (this->EightBitComposite)
    {
      // The window holds 8 bits per channel: round the premultiplied image to 8 bits here (a
      // quarter of the float image's upload, which cost ~5 ms per 1024^2 frame on an H100).
      const size_t n = d.Image.rgba.size();
      d.Image8.resize(4 * n);
      const float* src = &d.Image.rgba[0].x;
      unsigned char* dst = d.Image8.data();
      tbb::parallel_for(tbb::blocked_range<size_t>(0, 4 * n, size_t(1) << 16),
        [src, dst](const tbb::blocked_range<size_t>& r) {
          for (size_t i = r.begin(); i < r.end(); ++i)
          {
            const float v = std::min(std::max(src[i], 0.f), 1.f);
            dst[i] = static_cast<unsigned char>(v * 255.f + 0.5f);
          }
        });
      d.Texture->Create2DFromRaw(static_cast<unsigned>(width), static_cast<unsigned>(height), 4,
        VTK_UNSIGNED_CHAR, d.Image8.data());
    }
    else
    {
      d.Texture->Create2DFromRaw(static_cast<unsigned>(width), static_cast<unsigned>(height), 4,
        VTK_FLOAT, d.Image.rgba.data());
    }
    if (!image)
    {
      image = d.Texture;
      d.CompositePath = "host";
    }

    if (!d.Quad)
    {
      std::string fs = vtkOpenGLRenderUtilities::GetFullScreenQuadFragmentShaderTemplate();
      vtkShaderProgram::Substitute(fs, "//VTK::FSQ::Decl", "uniform sampler2D ssImage;");
      vtkShaderProgram::Substitute(
        fs, "//VTK::FSQ::Impl", "  gl_FragData[0] = texture(ssImage, texCoord);");
      d.Quad.reset(new vtkOpenGLQuadHelper(renWin,
        vtkOpenGLRenderUtilities::GetFullScreenQuadVertexShader().c_str(), fs.c_str(), ""));
    }
    else
    {
      renWin->GetShaderCache()->ReadyShaderProgram(d.Quad->Program);
    }
    if (!d.Quad->Program || !d.Quad->Program->GetCompiled())
    {
      fail("could not compile the compositing shader: nothing drawn");
      return;
    }

    vtkOpenGLState::ScopedglEnableDisable blendSaver(ostate, GL_BLEND);
    vtkOpenGLState::ScopedglEnableDisable depthSaver(ostate, GL_DEPTH_TEST);
    vtkOpenGLState::ScopedglBlendFuncSeparate blendFuncSaver(ostate);
    vtkOpenGLState::ScopedglDepthMask depthMaskSaver(ostate);
    ostate->vtkglEnable(GL_BLEND);
    ostate->vtkglBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    ostate->vtkglDisable(GL_DEPTH_TEST);
    ostate->vtkglDepthMask(GL_FALSE);
    image->Activate();
    d.Quad->Program->SetUniformi("ssImage", image->GetTextureUnit());
    d.Quad->Render();
    image->Deactivate();
    d.CompositeSeconds = SecondsSince(t0);
    d.MapperSeconds = SecondsSince(tRender);
    d.LastProblem.clear();
  }
  catch (const std::exception& e)
  {
    fail(std::string("SpaceSkip engine error: ") + e.what() + ": nothing drawn");
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::SetBinCount(int bins)
{
  // 0 is the sweep; 1 (no candidate plane) would make the engine throw, so it clamps to 2.
  const int v = bins <= 0 ? 0 : std::min(std::max(bins, 2), 64);
  if (v != this->BinCount)
  {
    this->BinCount = v;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
void vtkSpaceSkippingVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Builder: " << this->GetBuilderAsString() << "\n";
  os << indent << "LeafCriterion: " << (this->LeafCriterion == Shallow ? "Shallow" : "Deep")
     << "\n";
  os << indent << "MaxLeafSize: " << this->MaxLeafSize << "\n";
  os << indent << "BinCount: " << this->BinCount << "\n";
  os << indent << "MacroCellSize: " << this->MacroCellSize << "\n";
  os << indent << "SampleDistance: " << this->SampleDistance << "\n";
  os << indent << "Backend: "
     << (this->Backend == Auto ? "Auto" : (this->Backend == CPU ? "CPU" : "CUDA")) << "\n";
  os << indent << "EarlyRayTermination: " << (this->EarlyRayTermination ? "On" : "Off") << "\n";
  os << indent << "EightBitComposite: " << (this->EightBitComposite ? "On" : "Off") << "\n";
  os << indent << "GPUComposite: " << (this->GPUComposite ? "On" : "Off") << "\n";
  os << indent << "CompositePathUsed: " << this->Internals->CompositePath << "\n";
  os << indent << "UseJittering: " << (this->UseJittering ? "On" : "Off") << "\n";
  os << indent << "VectorMode: " << this->VectorMode << "\n";
  os << indent << "VectorComponent: " << this->VectorComponent << "\n";
  os << indent << "BlendModeOverride: " << this->BlendModeOverride << "\n";
  os << indent << "BackendUsed: " << this->Internals->BackendUsed << "\n";
  os << indent << "BuilderUsed: " << this->Internals->BuilderUsed << "\n";
  os << indent << "LastBuildSeconds: " << this->GetLastBuildSeconds() << "\n";
  os << indent << "LastRenderSeconds: " << this->GetLastRenderSeconds() << "\n";
  os << indent << "NodeCount: " << this->GetNodeCount() << "\n";
  os << indent << "TreeHeight: " << this->GetTreeHeight() << "\n";
  os << indent << "LeafCount: " << this->GetLeafCount() << "\n";
  os << indent << "BuildCount: " << this->GetBuildCount() << "\n";
  os << indent << "ClassifyCount: " << this->GetClassifyCount() << "\n";
  os << indent << "ColorUpdateCount: " << this->GetColorUpdateCount() << "\n";
}
