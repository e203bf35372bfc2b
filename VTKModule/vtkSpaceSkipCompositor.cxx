// vtkSpaceSkipCompositor: depth readback, image upload (or CUDA-GL interop) and blending.
#include "vtkSpaceSkipCompositor.h"

#include "vtkActor2D.h"
#include "vtkCommand.h"
#include "vtkImageData.h"
#include "vtkLogger.h"
#include "vtkMath.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderUtilities.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkProp.h"
#include "vtkPropCollection.h"
#include "vtkRenderer.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"
#include "vtkVolume.h"
#include "vtkSpaceSkipOpenGL.h"

#include "spaceskip/DeviceImageCopy.h"
#include "spaceskip/Engine.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#ifdef SPACESKIP_HAVE_CUDA
// CUDA-GL interop for GPUComposite (runtime API only: no kernel here; GLEW already blocks gl.h).
#include <cuda_gl_interop.h>
#include <cuda_runtime_api.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace
{
#ifdef SPACESKIP_HAVE_CUDA
// Queues on the engine's `stream` (after its frame) the map of `resource`, `work` on its
// array (returns a cudaError_t as an int) and the unmap: the map makes CUDA wait for GL's drawing
// so far, the unmap GL's next drawing for `work`, both on the GPU. On failure `what` names the
// step (`workName` for `work`).
template <class Work>
cudaError_t OnMappedArray(void* resource, void* stream, const char* workName, Work work, const char*& what)
{
  const cudaStream_t s = static_cast<cudaStream_t>(stream);
  cudaGraphicsResource_t r = static_cast<cudaGraphicsResource_t>(resource);
  cudaError_t e = cudaGraphicsMapResources(1, &r, s);
  if (e != cudaSuccess)
  {
    what = "cudaGraphicsMapResources";
    return e;
  }
  cudaArray_t array = nullptr;
  e = cudaGraphicsSubResourceGetMappedArray(&array, r, 0, 0);
  what = "cudaGraphicsSubResourceGetMappedArray";
  if (e == cudaSuccess)
  {
    e = static_cast<cudaError_t>(work(array, static_cast<void*>(s)));
    what = workName;
  }
  const cudaError_t u = cudaGraphicsUnmapResources(1, &r, s);
  if (e == cudaSuccess && u != cudaSuccess)
  {
    what = "cudaGraphicsUnmapResources";
    return u;
  }
  return e;
}
#endif

// The window's GL vendor, or nullptr when it is not NVIDIA's: only NVIDIA's GL can share with
// CUDA, and another is not even asked (the failing call would show up as an API error in
// compute-sanitizer).
const char* NonNvidiaVendor()
{
  const char* vendor = reinterpret_cast<const char*>(glGetString(GL_VENDOR));
  return vendor && std::strstr(vendor, "NVIDIA") ? nullptr : (vendor ? vendor : "unknown");
}

// The framebuffer pixels a blend of `rect` (VisibleRect: pixels of the viewport) may write, as x,
// y, w, h: the rectangle moved to the viewport's origin `vp` and cut to the scissor box in force.
// False when that leaves none.
bool DrawBox(vtkOpenGLState* ostate, const int rect[4], int vp[4], int box[4])
{
  if (rect[2] <= 0 || rect[3] <= 0)
  {
    return false;
  }
  ostate->vtkglGetIntegerv(GL_VIEWPORT, vp);
  box[0] = rect[0] + vp[0];
  box[1] = rect[1] + vp[1];
  box[2] = rect[2];
  box[3] = rect[3];
  if (ostate->GetEnumState(GL_SCISSOR_TEST))
  {
    int cur[4];
    ostate->vtkglGetIntegerv(GL_SCISSOR_BOX, cur);
    const int x0 = std::max(box[0], cur[0]), y0 = std::max(box[1], cur[1]);
    const int x1 = std::min(box[0] + box[2], cur[0] + cur[2]);
    const int y1 = std::min(box[1] + box[3], cur[1] + cur[3]);
    if (x1 <= x0 || y1 <= y0)
    {
      return false;
    }
    box[0] = x0;
    box[1] = y0;
    box[2] = x1 - x0;
    box[3] = y1 - y0;
  }
  return true;
}

// `texture` (made on first use) in `renWin`'s context, sampled as the compositing draws it:
// nearest, clamped to the edge.
void PrepareTexture(vtkSmartPointer<vtkTextureObject>& texture, vtkOpenGLRenderWindow* renWin)
{
  if (!texture)
  {
    texture = vtkSmartPointer<vtkTextureObject>::New();
  }
  texture->SetContext(renWin);
  texture->SetMinificationFilter(vtkTextureObject::Nearest);
  texture->SetMagnificationFilter(vtkTextureObject::Nearest);
  texture->SetWrapS(vtkTextureObject::ClampToEdge);
  texture->SetWrapT(vtkTextureObject::ClampToEdge);
}
} // namespace

//------------------------------------------------------------------------------
vtkSpaceSkipCompositor::vtkSpaceSkipCompositor() = default;

//------------------------------------------------------------------------------
vtkSpaceSkipCompositor::~vtkSpaceSkipCompositor()
{
  this->ReleaseTarget();
  this->ReleaseInterop();
  this->TrackWindow(nullptr);
}

//------------------------------------------------------------------------------
void vtkSpaceSkipCompositor::TrackWindow(vtkOpenGLRenderWindow* renWin)
{
  vtkOpenGLRenderWindow* old = this->ResourceWindow;
  if (old == renWin)
  {
    return;
  }
  if (old)
  {
    // Registrations of another window's context go with that context current.
    this->ReleaseTarget();
    this->ReleaseInterop();
    if (this->WindowObserver)
    {
      old->RemoveObserver(this->WindowObserver);
    }
    if (renWin)
    {
      renWin->MakeCurrent();
    }
  }
  this->WindowObserver = 0;
  this->ResourceWindow = renWin;
  if (renWin)
  {
    this->WindowObserver =
      renWin->AddObserver(vtkCommand::DeleteEvent, this, &vtkSpaceSkipCompositor::OnWindowDeleted);
  }
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipCompositor::MakeResourceContextCurrent()
{
  vtkOpenGLRenderWindow* w = this->ResourceWindow;
  if (!w)
  {
    return false;
  }
  w->MakeCurrent(); // a no-op when it already is
  return true;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipCompositor::OnWindowDeleted()
{
  // Sent from the window's last UnRegister, before its destructor: its context still exists.
  vtkOpenGLRenderWindow* w = this->ResourceWindow;
  this->ReleaseGraphicsResources(w);
  this->WindowObserver = 0; // the window drops its observers itself
  this->ResourceWindow = nullptr;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipCompositor::ReleaseGraphicsResources(vtkWindow* win)
{
  if (this->Texture)
  {
    this->Texture->ReleaseGraphicsResources(win);
    this->Texture = nullptr;
  }
  if (this->Quad)
  {
    this->Quad->ReleaseGraphicsResources(win);
    this->Quad.reset();
  }
  if (this->Resolve)
  {
    this->Resolve->ReleaseGraphicsResources(win);
    this->Resolve = nullptr;
  }
  this->ReleaseTarget();
  this->ReleaseInterop();
  if (this->InteropTexture)
  {
    this->InteropTexture->ReleaseGraphicsResources(win);
    this->InteropTexture = nullptr;
  }
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipCompositor::SceneHasDepth(vtkRenderer* ren)
{
  if (!ren || ren->GetPreserveDepthBuffer())
  {
    return true;
  }
  vtkPropCollection* props = ren->GetViewProps();
  vtkCollectionSimpleIterator it;
  props->InitTraversal(it);
  while (vtkProp* p = props->GetNextProp(it))
  {
    if (!p->GetVisibility() || vtkVolume::SafeDownCast(p) || vtkActor2D::SafeDownCast(p))
    {
      continue;
    }
    // A prop with no geometry writes no depth: ParaView's render view keeps a visible actor of
    // empty bounds in every view, whose depth read cost 2.1-2.7 ms of each 1024^2 frame on the
    // H200. Bounds it cannot say (null) count as geometry.
    const double* bounds = p->GetBounds();
    if (!bounds || vtkMath::AreBoundsInitialized(bounds))
    {
      return true;
    }
  }
  return false;
}

//------------------------------------------------------------------------------
const float* vtkSpaceSkipCompositor::ReadDepth(
  vtkOpenGLRenderWindow* renWin, int x0, int y0, int width, int height)
{
  this->Depth.resize(static_cast<size_t>(width) * static_cast<size_t>(height));
  vtkOpenGLState* ostate = renWin->GetState();
  while (glGetError() != GL_NO_ERROR)
  {
  }
  ostate->vtkglPixelStorei(GL_PACK_ALIGNMENT, 1);
  GLint sampleBuffers = 0;
  glGetIntegerv(GL_SAMPLE_BUFFERS, &sampleBuffers);
  if (sampleBuffers <= 0)
  {
    glReadPixels(x0, y0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, this->Depth.data());
    return glGetError() == GL_NO_ERROR ? this->Depth.data() : nullptr;
  }

  // Multisampled framebuffer: resolve its depth into a single-sample framebuffer of the same
  // depth format (what vtkOpenGLRenderWindow allocates: 32 bits, stencil when the window has
  // one), over the same rectangle (a multisample blit cannot move pixels), then read that.
  GLint source = 0;
  glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &source);
  const int needW = x0 + width, needH = y0 + height;
  const bool stencil = renWin->GetStencilCapable() != 0;
  ostate->PushFramebufferBindings();
  if (!this->Resolve || this->ResolveStencil != stencil)
  {
    this->Resolve = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    this->Resolve->SetContext(renWin);
    this->Resolve->Bind();
    this->Resolve->PopulateFramebuffer(
      needW, needH, true, 1, VTK_UNSIGNED_CHAR, true, 32, 0, stencil);
    this->ResolveStencil = stencil;
  }
  else
  {
    int* size = this->Resolve->GetLastSize();
    if (size[0] != needW || size[1] != needH)
    {
      this->Resolve->Bind();
      this->Resolve->Resize(needW, needH);
    }
  }
  ostate->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<unsigned int>(source));
  this->Resolve->Bind(GL_DRAW_FRAMEBUFFER);
  glBlitFramebuffer(x0, y0, x0 + width, y0 + height, x0, y0, x0 + width, y0 + height,
    GL_DEPTH_BUFFER_BIT, GL_NEAREST);
  this->Resolve->Bind(GL_READ_FRAMEBUFFER);
  glReadPixels(x0, y0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, this->Depth.data());
  const bool ok = glGetError() == GL_NO_ERROR;
  ostate->PopFramebufferBindings();
  return ok ? this->Depth.data() : nullptr;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipCompositor::VisibleRect(const spaceskip::Camera& camera, vtkImageData* input,
  double pad, int width, int height, int rect[4])
{
  rect[0] = rect[1] = 0;
  rect[2] = width;
  rect[3] = height;
  if (!input)
  {
    return;
  }
  int ext[6];
  input->GetExtent(ext);
  // clip = proj * view * (x, y, z, 1): Core's matrices are column-major, m[c * 4 + r].
  const spaceskip::mat4 projView = spaceskip::multiply(camera.proj, camera.view);
  const double* pv = projView.m;
  double lo[2] = { 1e300, 1e300 }, hi[2] = { -1e300, -1e300 };
  for (int corner = 0; corner < 8; ++corner)
  {
    const double i = (corner & 1) ? ext[1] + pad : ext[0] - pad;
    const double j = (corner & 2) ? ext[3] + pad : ext[2] - pad;
    const double k = (corner & 4) ? ext[5] + pad : ext[4] - pad;
    double x[3];
    input->TransformContinuousIndexToPhysicalPoint(i, j, k, x);
    double clip[4];
    for (int r = 0; r < 4; ++r)
    {
      clip[r] = pv[r] * x[0] + pv[4 + r] * x[1] + pv[8 + r] * x[2] + pv[12 + r];
    }
    if (!(clip[3] > 1e-9) || !std::isfinite(clip[0] + clip[1] + clip[3]))
    {
      return; // behind the eye (or not finite): the whole frame
    }
    for (int a = 0; a < 2; ++a)
    {
      const double ndc = clip[a] / clip[3];
      lo[a] = std::min(lo[a], ndc);
      hi[a] = std::max(hi[a], ndc);
    }
  }
  // Pixel p's centre is at ndc (p + 0.5) / n * 2 - 1 (render/RayGen.h).
  const int n[2] = { width, height };
  for (int a = 0; a < 2; ++a)
  {
    const double p0 = std::floor((lo[a] + 1) * 0.5 * n[a] - 0.5) - 2;
    const double p1 = std::ceil((hi[a] + 1) * 0.5 * n[a] - 0.5) + 2;
    const int first = static_cast<int>(std::max(0.0, std::min(p0, double(n[a]))));
    const int last = static_cast<int>(std::max(-1.0, std::min(p1, double(n[a] - 1))));
    rect[a] = first;
    rect[2 + a] = std::max(0, last - first + 1);
  }
  if (rect[2] == 0 || rect[3] == 0)
  {
    rect[2] = rect[3] = 0;
  }
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipCompositor::CopyDeviceImage(vtkOpenGLRenderWindow* renWin,
  const spaceskip::DeviceImageView& image, const std::function<const void*()>& flatImage,
  void* stream, int width, int height, const int rect[4], bool eightBit)
{
#ifdef SPACESKIP_HAVE_CUDA
  // Interop only where the window's GL and the engine's CUDA device are one GPU (one rank per
  // GPU may bind a CUDA device other than the one the X screen's GL runs on): checked once.
  if (!this->GLDeviceChecked)
  {
    this->GLDeviceChecked = true;
    if (!this->GLOnCudaDevice())
    {
      vtkVLogF(vtkLogger::VERBOSITY_INFO,
        "vtkSpaceSkippingVolumeMapper: CUDA-GL interop unavailable (%s); the image goes "
        "through host memory",
        this->InteropProblem.c_str());
      this->InteropFailed = true;
      return false;
    }
  }
  if (this->BlendIntoFramebuffer(renWin, image, stream, width, height, rect, eightBit))
  {
    this->Direct = true;
    this->CompositePath = "gpu";
    this->BlendPath = "cuda";
    return true;
  }
#endif
  const void* flat = flatImage ? flatImage() : image.image;
  if (flat && this->CopyToInteropTexture(renWin, flat, stream, width, height, rect, eightBit))
  {
    this->Interop = true;
    this->CompositePath = "gpu";
    this->BlendPath = "gl";
    return true;
  }
  // Not this GL (Mesa, another device) or a CUDA error: the host path from now on.
  vtkVLogF(vtkLogger::VERBOSITY_INFO,
    "vtkSpaceSkippingVolumeMapper: CUDA-GL interop unavailable (%s); the image goes "
    "through host memory",
    this->InteropProblem.c_str());
  this->InteropFailed = true;
  this->ReleaseTarget();
  this->ReleaseInterop();
  return false;
}

//------------------------------------------------------------------------------
bool vtkSpaceSkipCompositor::BindCudaDevice(int asked, int& used, int& count, std::string& problem)
{
  used = -1;
  count = 0;
#ifdef SPACESKIP_HAVE_CUDA
  int n = 0;
  cudaError_t e = cudaGetDeviceCount(&n);
  if (e != cudaSuccess || n < 1)
  {
    cudaGetLastError(); // not the engine's error to find
    problem = e != cudaSuccess ? std::string("no CUDA device (") + cudaGetErrorString(e) + ")"
                               : std::string("no CUDA device");
    return false;
  }
  int current = 0;
  if (cudaGetDevice(&current) != cudaSuccess)
  {
    cudaGetLastError();
    current = 0;
  }
  const int want = asked < 0 ? current : asked % n;
  if (want != current && (e = cudaSetDevice(want)) != cudaSuccess)
  {
    cudaGetLastError();
    problem = std::string("cudaSetDevice(") + std::to_string(want) + "): " + cudaGetErrorString(e);
    return false;
  }
  used = want;
  count = n;
  problem.clear();
  return true;
#else
  (void)asked;
  problem = "built without CUDA";
  return false;
#endif
}

//------------------------------------------------------------------------------
#ifdef SPACESKIP_HAVE_CUDA
bool vtkSpaceSkipCompositor::GLOnCudaDevice()
{
  int cudaDevice = 0;
  if (cudaGetDevice(&cudaDevice) != cudaSuccess)
  {
    cudaGetLastError();
    this->InteropProblem = "no current CUDA device";
    return false;
  }
  unsigned int n = 0;
  int devices[16];
  const cudaError_t e = cudaGLGetDevices(&n, devices, 16, cudaGLDeviceListAll);
  if (e != cudaSuccess || n == 0)
  {
    // Not NVIDIA's GL (Mesa) or no answer: the interop paths find out and say which.
    cudaGetLastError();
    return true;
  }
  for (unsigned int i = 0; i < n && i < 16; ++i)
  {
    if (devices[i] == cudaDevice)
    {
      return true;
    }
  }
  this->InteropProblem = "the window's OpenGL runs on CUDA device " + std::to_string(devices[0]) +
    ", the engine on CUDA device " + std::to_string(cudaDevice);
  return false;
}
#endif

//------------------------------------------------------------------------------
bool vtkSpaceSkipCompositor::Draw(vtkOpenGLRenderWindow* renWin, const spaceskip::Image& image,
  int width, int height, bool eightBit, const int rect[4])
{
  if (this->Direct)
  {
    this->Direct = false;
    return true; // CopyDeviceImage blended this frame into the framebuffer
  }
  vtkTextureObject* texture = this->Interop ? this->InteropTexture.GetPointer() : nullptr;
  this->Interop = false;
  this->UploadHostImage(renWin, texture ? nullptr : &image, width, height, eightBit);
  if (!texture)
  {
    texture = this->Texture;
    this->CompositePath = "host";
    this->BlendPath = "gl";
  }
  const int whole[4] = { 0, 0, width, height };
  return this->Blend(renWin, texture, rect ? rect : whole);
}

//------------------------------------------------------------------------------
// The host texture, set up every frame; `image` (when given) uploaded into it.
void vtkSpaceSkipCompositor::UploadHostImage(vtkOpenGLRenderWindow* renWin,
  const spaceskip::Image* image, int width, int height, bool eightBit)
{
  PrepareTexture(this->Texture, renWin);
  if (!image)
  {
    return; // this frame is drawn from the interop texture
  }
  // vtkTextureObject keeps the first internal format it chose (EightBitComposite may change).
  this->Texture->ResetFormatAndType();
  if (eightBit)
  {
    // The window holds 8 bits per channel: round the premultiplied image to 8 bits here (a
    // quarter of the float image's upload, which cost ~5 ms per 1024^2 frame on an H100).
    const size_t n = image->rgba.size();
    this->Image8.resize(4 * n);
    const float* src = &image->rgba[0].x;
    unsigned char* dst = this->Image8.data();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, 4 * n, size_t(1) << 16),
      [src, dst](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i < r.end(); ++i)
        {
          const float v = std::min(std::max(src[i], 0.f), 1.f);
          dst[i] = static_cast<unsigned char>(v * 255.f + 0.5f);
        }
      });
    this->Texture->Create2DFromRaw(static_cast<unsigned>(width), static_cast<unsigned>(height), 4,
      VTK_UNSIGNED_CHAR, this->Image8.data());
  }
  else
  {
    this->Texture->Create2DFromRaw(static_cast<unsigned>(width), static_cast<unsigned>(height), 4,
      VTK_FLOAT, const_cast<spaceskip::vec4f*>(image->rgba.data())); // only read
  }
}

//------------------------------------------------------------------------------
// A full-screen quad drawing `texture` as premultiplied RGBA over what is drawn,
// (ONE, ONE_MINUS_SRC_ALPHA), depth untouched; false when the shader does not compile.
bool vtkSpaceSkipCompositor::Blend(
  vtkOpenGLRenderWindow* renWin, vtkTextureObject* texture, const int rect[4])
{
  if (rect[2] <= 0 || rect[3] <= 0)
  {
    return true; // no pixel of the frame can be coloured
  }
  if (!this->Quad)
  {
    std::string fs = vtkOpenGLRenderUtilities::GetFullScreenQuadFragmentShaderTemplate();
    vtkShaderProgram::Substitute(fs, "//VTK::FSQ::Decl", "uniform sampler2D ssImage;");
    vtkShaderProgram::Substitute(
      fs, "//VTK::FSQ::Impl", "  gl_FragData[0] = texture(ssImage, texCoord);");
    this->Quad.reset(new vtkOpenGLQuadHelper(renWin,
      vtkOpenGLRenderUtilities::GetFullScreenQuadVertexShader().c_str(), fs.c_str(), ""));
  }
  else
  {
    renWin->GetShaderCache()->ReadyShaderProgram(this->Quad->Program);
  }
  if (!this->Quad->Program || !this->Quad->Program->GetCompiled())
  {
    return false;
  }

  vtkOpenGLState* ostate = renWin->GetState();
  // Only the pixels the rays can colour (VisibleRect, in the viewport), within the scissor box
  // in force (VTK's viewport).
  int vp[4], box[4];
  if (!DrawBox(ostate, rect, vp, box))
  {
    return true;
  }
  vtkOpenGLState::ScopedglEnableDisable blendSaver(ostate, GL_BLEND);
  vtkOpenGLState::ScopedglEnableDisable depthSaver(ostate, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglBlendFuncSeparate blendFuncSaver(ostate);
  vtkOpenGLState::ScopedglDepthMask depthMaskSaver(ostate);
  vtkOpenGLState::ScopedglEnableDisable scissorTestSaver(ostate, GL_SCISSOR_TEST);
  vtkOpenGLState::ScopedglScissor scissorSaver(ostate);
  ostate->vtkglEnable(GL_SCISSOR_TEST);
  ostate->vtkglScissor(box[0], box[1], box[2], box[3]);
  ostate->vtkglEnable(GL_BLEND);
  ostate->vtkglBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  ostate->vtkglDisable(GL_DEPTH_TEST);
  ostate->vtkglDepthMask(GL_FALSE);
  texture->Activate();
  this->Quad->Program->SetUniformi("ssImage", texture->GetTextureUnit());
  this->Quad->Render();
  texture->Deactivate();
  return true;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipCompositor::ReleaseInterop()
{
#ifdef SPACESKIP_HAVE_CUDA
  if (this->InteropResource)
  {
    // A copy into the texture may still be queued on the engine's stream.
    cudaDeviceSynchronize();
    // Unregistered in its own context (TrackWindow); without a window the context is gone and
    // the registration with it: unregistering would only fail.
    if (this->MakeResourceContextCurrent())
    {
      cudaGraphicsUnregisterResource(static_cast<cudaGraphicsResource_t>(this->InteropResource));
    }
    cudaGetLastError(); // a failure here must not reach the engine's checks
  }
#endif
  this->InteropResource = nullptr;
  this->InteropSize[0] = this->InteropSize[1] = 0;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipCompositor::ReleaseTarget()
{
#ifdef SPACESKIP_HAVE_CUDA
  if (this->TargetResource)
  {
    if (this->ImageCopy)
    {
      this->ImageCopy->releaseSurface(); // waits for the blends still queued
    }
    if (this->MakeResourceContextCurrent()) // as in ReleaseInterop
    {
      cudaGraphicsUnregisterResource(static_cast<cudaGraphicsResource_t>(this->TargetResource));
    }
    cudaGetLastError();
  }
#endif
  this->TargetResource = nullptr;
  this->TargetTexture = nullptr;
  this->TargetHandle = 0;
  this->TargetSize[0] = this->TargetSize[1] = 0;
}

//------------------------------------------------------------------------------
// GPUComposite's first choice: the image blended by CUDA straight into the colour texture of the
// framebuffer being drawn, when that is the window's render framebuffer with a single-sample
// RGBA8 texture written through draw buffer 0 with every channel enabled (VTK's default). No
// texture copy and no GL draw: a draw over the whole window costs the H100's few graphics
// units more than the blend kernel costs its SMs. False (the texture path then draws this
// frame) for any other target, with SetCudaBlend(false) (Tuning::cudaBlend), and from a
// CUDA failure on (said once at INFO verbosity).
#ifdef SPACESKIP_HAVE_CUDA
bool vtkSpaceSkipCompositor::BlendIntoFramebuffer(vtkOpenGLRenderWindow* renWin,
  const spaceskip::DeviceImageView& image, void* stream, int w, int h, const int rect[4],
  bool eightBit)
{
  if (this->TargetFailed || !this->CudaBlend)
  {
    return false;
  }
  vtkOpenGLFramebufferObject* fbo = renWin->GetRenderFramebuffer();
  GLint bound = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
  if (!fbo || bound <= 0 || static_cast<unsigned>(bound) != fbo->GetFBOIndex())
  {
    return false;
  }
  vtkTextureObject* tex = fbo->GetColorAttachmentAsTextureObject(0);
  if (!tex || tex->GetTarget() != GL_TEXTURE_2D || tex->GetHandle() == 0)
  {
    return false;
  }
  // Per frame: the draw state (draw buffers, colour mask) the blend must honour.
  GLint buffer0 = 0, buffer1 = 0;
  glGetIntegerv(GL_DRAW_BUFFER0, &buffer0);
  glGetIntegerv(GL_DRAW_BUFFER1, &buffer1);
  GLboolean mask[4] = { GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE };
  glGetBooleanv(GL_COLOR_WRITEMASK, mask);
  if (buffer0 != GL_COLOR_ATTACHMENT0 || buffer1 != GL_NONE || !(mask[0] && mask[1] && mask[2] && mask[3]))
  {
    return false;
  }
  int vp[4], box[4];
  if (!DrawBox(renWin->GetState(), rect, vp, box))
  {
    return true; // no pixel to blend
  }
  const int tw = static_cast<int>(tex->GetWidth()), th = static_cast<int>(tex->GetHeight());
  // The image is the viewport's: image pixel (x, y) is framebuffer pixel (vp[0] + x, vp[1] + y).
  if (vp[2] != w || vp[3] != h || box[0] < 0 || box[1] < 0 || box[0] + box[2] > tw || box[1] + box[3] > th)
  {
    return false;
  }
  auto failed = [this](const char* what, cudaError_t e) {
    this->TargetProblem = std::string(what) + ": " + cudaGetErrorString(e);
    cudaGetLastError();
    this->TargetFailed = true;
    this->ReleaseTarget();
    vtkVLogF(vtkLogger::VERBOSITY_INFO,
      "vtkSpaceSkippingVolumeMapper: the image cannot be blended by CUDA into the framebuffer "
      "(%s); it goes through a texture drawn by GL",
      this->TargetProblem.c_str());
    return false;
  };
  // A texture VTK reallocated (the window resized) or replaced: its format checked and the
  // texture registered anew, once; one that does not fit stays unregistered until it changes.
  if (this->TargetTexture != tex || this->TargetHandle != tex->GetHandle() || this->TargetSize[0] != tw ||
    this->TargetSize[1] != th)
  {
    this->ReleaseTarget();
    this->TargetTexture = tex;
    this->TargetHandle = tex->GetHandle();
    this->TargetSize[0] = tw;
    this->TargetSize[1] = th;
    auto attachment = [](GLenum what) {
      GLint v = 0;
      glGetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, what, &v);
      return v;
    };
    const bool rgba8 = attachment(GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE) == GL_TEXTURE &&
      static_cast<unsigned>(attachment(GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME)) == tex->GetHandle() &&
      attachment(GL_FRAMEBUFFER_ATTACHMENT_TEXTURE_LEVEL) == 0 &&
      attachment(GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE) == GL_UNSIGNED_NORMALIZED &&
      attachment(GL_FRAMEBUFFER_ATTACHMENT_COLOR_ENCODING) == GL_LINEAR &&
      attachment(GL_FRAMEBUFFER_ATTACHMENT_RED_SIZE) == 8 &&
      attachment(GL_FRAMEBUFFER_ATTACHMENT_GREEN_SIZE) == 8 &&
      attachment(GL_FRAMEBUFFER_ATTACHMENT_BLUE_SIZE) == 8 &&
      attachment(GL_FRAMEBUFFER_ATTACHMENT_ALPHA_SIZE) == 8;
    while (glGetError() != GL_NO_ERROR)
    {
    }
    if (!rgba8 || NonNvidiaVendor())
    {
      return false;
    }
    this->TrackWindow(renWin);
    cudaGraphicsResource_t r = nullptr;
    const cudaError_t e = cudaGraphicsGLRegisterImage(
      &r, tex->GetHandle(), GL_TEXTURE_2D, cudaGraphicsRegisterFlagsSurfaceLoadStore);
    if (e != cudaSuccess)
    {
      return failed("cudaGraphicsGLRegisterImage", e);
    }
    this->TargetResource = r;
  }
  if (!this->TargetResource)
  {
    return false; // this texture does not fit (checked when it appeared)
  }
  if (!this->ImageCopy)
  {
    this->ImageCopy.reset(new spaceskip::DeviceImageCopy);
  }
  const char* what = "";
  const cudaError_t e = OnMappedArray(this->TargetResource, stream, "blend into the framebuffer texture",
    [&](cudaArray_t array, void* s) {
      return this->ImageCopy->blendOver(image, w, h, array, tw, th, box[0] - vp[0], box[1] - vp[1],
        box[2], box[3], vp[0], vp[1], eightBit, s);
    },
    what);
  return e == cudaSuccess || failed(what, e);
}
#endif

//------------------------------------------------------------------------------
// Copies the engine's device image into InteropTexture; false (with the reason) on any failure.
bool vtkSpaceSkipCompositor::CopyToInteropTexture(vtkOpenGLRenderWindow* renWin,
  const void* image, void* stream, int w, int h, const int rect[4], bool eightBit)
{
#ifdef SPACESKIP_HAVE_CUDA
  auto failed = [this](const char* what, cudaError_t e) {
    this->InteropProblem = std::string(what) + ": " + cudaGetErrorString(e);
    cudaGetLastError();
    return false;
  };
  if (!this->InteropTexture || this->InteropSize[0] != w || this->InteropSize[1] != h ||
    this->InteropEightBit != eightBit)
  {
    this->ReleaseInterop();
    if (const char* other = NonNvidiaVendor())
    {
      this->InteropProblem = std::string("the window's OpenGL is ") + other + "'s, not NVIDIA's";
      return false;
    }
    PrepareTexture(this->InteropTexture, renWin);
    // vtkTextureObject keeps the first internal format it chose: RGBA8 <-> RGBA32F needs a reset.
    this->InteropTexture->ResetFormatAndType();
    if (!this->InteropTexture->Allocate2D(static_cast<unsigned>(w), static_cast<unsigned>(h), 4,
          eightBit ? VTK_UNSIGNED_CHAR : VTK_FLOAT))
    {
      this->InteropProblem = "could not allocate the texture";
      return false;
    }
    this->TrackWindow(renWin);
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
    this->InteropEightBit = eightBit;
  }
  if (rect[2] <= 0 || rect[3] <= 0)
  {
    return true; // nothing to copy (Blend draws nothing either)
  }
  if (!this->ImageCopy)
  {
    this->ImageCopy.reset(new spaceskip::DeviceImageCopy);
  }
  const char* what = "";
  const cudaError_t e = OnMappedArray(this->InteropResource, stream, "copy into the GL texture",
    [&](cudaArray_t array, void* s) {
      return this->ImageCopy->copy(image, w, h, array, rect[0], rect[1], rect[2], rect[3], eightBit, s);
    },
    what);
  return e == cudaSuccess || failed(what, e);
#else
  (void)renWin;
  (void)image;
  (void)stream;
  (void)w;
  (void)h;
  (void)rect;
  (void)eightBit;
  this->InteropProblem = "built without CUDA";
  return false;
#endif
}
