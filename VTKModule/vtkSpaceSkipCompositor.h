// vtkSpaceSkipCompositor: the window side of the mapper: reads the depth of what is drawn and
// blends the engine's premultiplied RGBA image over it (from host memory, or from device memory
// through CUDA-GL interop). Internal to the module (not wrapped, not installed); needs no nvcc.
#ifndef vtkSpaceSkipCompositor_h
#define vtkSpaceSkipCompositor_h

#include "vtkSmartPointer.h" // For the textures and the framebuffer
#include "vtkWeakPointer.h"  // For the window the CUDA registrations belong to

#include <functional> // For the flat image's getter
#include <memory>     // For Quad
#include <string> // For the problem and path texts
#include <vector> // For the buffers

class vtkImageData;
class vtkOpenGLFramebufferObject;
class vtkOpenGLQuadHelper;
class vtkOpenGLRenderWindow;
class vtkRenderer;
class vtkTextureObject;
class vtkWindow;
namespace spaceskip
{
class DeviceImageCopy;
struct Camera;
struct DeviceImageView;
struct Image;
}

class vtkSpaceSkipCompositor
{
public:
  vtkSpaceSkipCompositor();
  ~vtkSpaceSkipCompositor();
  vtkSpaceSkipCompositor(const vtkSpaceSkipCompositor&) = delete;
  void operator=(const vtkSpaceSkipCompositor&) = delete;

  /**
   * The window depth of the viewport's opaque geometry already drawn, in [0, 1], row 0 at the
   * bottom (an MSAA framebuffer is resolved first), or nullptr when it could not be read.
   */
  const float* ReadDepth(vtkOpenGLRenderWindow* renWin, int x0, int y0, int width, int height);

  /**
   * False when nothing in `ren` can have written depth before the volumes: every visible view
   * prop is a volume or a 2D actor and the renderer does not keep an earlier layer's depth. The
   * depth buffer then holds the cleared far plane only, and its readback (1.2-1.5 ms at 1024^2 on
   * the H100) is skipped: the rays run to the box's far side either way.
   */
  static bool SceneHasDepth(vtkRenderer* ren);

  /// Whether CopyDeviceImage may blend into the framebuffer's texture by CUDA (Tuning::cudaBlend;
  /// default on); off: the texture path (a measurement switch of the window benchmark).
  void SetCudaBlend(bool on) { this->CudaBlend = on; }

  /**
   * Binds the calling thread to CUDA device `asked` modulo the number of devices (asked < 0:
   * leaves the thread's current device, CUDA's default 0) before the engine allocates on it;
   * `used` and `count` tell which of how many. False (and nothing changed) without CUDA or
   * without a device (`problem` says why). One rank per GPU: the representation asks for the
   * node-local MPI rank.
   */
  static bool BindCudaDevice(int asked, int& used, int& count, std::string& problem);

  /// Whether the image may stay on the device for CUDA-GL interop (GPUComposite on, not failed).
  bool CanUseDeviceImage(bool gpuComposite) const { return gpuComposite && !this->InteropFailed; }

  /**
   * The pixels of a `width` x `height` frame its rays can colour, as x, y, w, h (w or h 0: none):
   * the projection of `input`'s box grown by `pad` cells on each side, plus 2 pixels; a ray
   * through a pixel centre outside it misses the box, and its pixel is transparent black, which
   * the blend leaves unchanged. The whole frame when a corner lies behind the eye or `input` is
   * null (the mapper's Tuning::compositeFull).
   */
  static void VisibleRect(const spaceskip::Camera& camera, vtkImageData* input, double pad, int width,
    int height, int rect[4]);

  /**
   * Blends `rect` (VisibleRect) of the engine's device image (Engine::deviceImageView: the
   * float4 RGBA image, or a segmented frame's layers composited as they are blended) by CUDA straight into
   * the colour texture of the window's render framebuffer when that is the target being drawn
   * (single-sample RGBA8, draw buffer 0, all channels written), as GL's blend would (Draw() then
   * has nothing left to do); otherwise copies the flat image (`flatImage()`:
   * Engine::deviceImage, which composites pending layers) into a GL texture
   * registered with CUDA, the one Draw() then blends: float texels, or with `eightBit` RGBA8
   * rounded as the host path rounds (a quarter of the bytes for the blend to read). The map,
   * copy and unmap are queued on `stream` (the engine's, Engine::deviceImageStream()) after the
   * frame, so GL waits for the image on the GPU and the host not at all. False on
   * any failure (not NVIDIA's GL, another device, a CUDA error): said once at INFO verbosity,
   * and the host path is used from then on.
   */
  bool CopyDeviceImage(vtkOpenGLRenderWindow* renWin, const spaceskip::DeviceImageView& image,
    const std::function<const void*()>& flatImage, void* stream, int width, int height,
    const int rect[4], bool eightBit);

  /**
   * Blends the image over what is drawn as premultiplied RGBA (ONE, ONE_MINUS_SRC_ALPHA), within
   * `rect` of the viewport (VisibleRect; nullptr: all of it): the texture CopyDeviceImage()
   * filled this frame, else `image` uploaded from host memory (rounded to 8 bits per channel
   * when `eightBit`). False when the compositing shader does not compile.
   */
  bool Draw(vtkOpenGLRenderWindow* renWin, const spaceskip::Image& image, int width, int height,
    bool eightBit, const int rect[4] = nullptr);

  /// "gpu", "host" or "none": how the last image reached the window.
  const std::string& GetCompositePath() const { return this->CompositePath; }
  /// "cuda" (blended into the framebuffer by CUDA), "gl" (drawn from a texture) or "none".
  const std::string& GetBlendPath() const { return this->BlendPath; }
  bool GetInteropFailed() const { return this->InteropFailed; }
  const std::string& GetInteropProblem() const { return this->InteropProblem; }
  /// Whether this frame's image came through CUDA-GL interop (CopyDeviceImage succeeded).
  bool HasDeviceImage() const { return this->Interop || this->Direct; }

  void ReleaseGraphicsResources(vtkWindow* win);

private:
  void UploadHostImage(vtkOpenGLRenderWindow* renWin, const spaceskip::Image* image, int width,
    int height, bool eightBit);
  bool Blend(vtkOpenGLRenderWindow* renWin, vtkTextureObject* texture, const int rect[4]);
  void ReleaseInterop();
  void ReleaseTarget();
  // CUDA unregisters a GL resource only while a context of its share group is current (else
  // cudaErrorInvalidGraphicsContext). The window whose context registered InteropResource and
  // TargetResource is kept (weakly), made current before they are released, and observed: its
  // DeleteEvent (sent while its context still exists) releases them, whatever order the mapper
  // and the window go in.
  void TrackWindow(vtkOpenGLRenderWindow* renWin);
  bool MakeResourceContextCurrent();
  void OnWindowDeleted();
  vtkWeakPointer<vtkOpenGLRenderWindow> ResourceWindow;
  unsigned long WindowObserver = 0;
  // Defined with CUDA only.
  // Whether the window's OpenGL (current context) runs on the calling thread's CUDA device
  // (cudaGLGetDevices); false with InteropProblem set when it runs on another GPU (true when
  // CUDA cannot tell, e.g. Mesa's GL: the interop paths then fail and say so).
  bool GLOnCudaDevice();
  bool GLDeviceChecked = false;
  bool BlendIntoFramebuffer(vtkOpenGLRenderWindow* renWin, const spaceskip::DeviceImageView& image,
    void* stream, int w, int h, const int rect[4], bool eightBit);
  bool CopyToInteropTexture(vtkOpenGLRenderWindow* renWin, const void* image, void* stream, int w,
    int h, const int rect[4], bool eightBit);

  std::vector<float> Depth;
  vtkSmartPointer<vtkOpenGLFramebufferObject> Resolve; // single-sample copy of an MSAA depth
  bool ResolveStencil = false;

  std::vector<unsigned char> Image8; // the image rounded to 8 bits for upload (EightBitComposite)
  vtkSmartPointer<vtkTextureObject> Texture;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;

  // GPUComposite: a float RGBA texture registered with CUDA, filled from the engine's device image.
  vtkSmartPointer<vtkTextureObject> InteropTexture;
  void* InteropResource = nullptr; // cudaGraphicsResource_t
  int InteropSize[2] = { 0, 0 };
  bool InteropEightBit = false; // InteropTexture holds RGBA8 (else float RGBA)
  std::unique_ptr<spaceskip::DeviceImageCopy> ImageCopy; // the device image into the texture
  bool InteropFailed = false; // once failed (e.g. GL on Mesa, another GPU): host path from then on
  bool Interop = false;       // this frame's image is InteropTexture
  std::string InteropProblem;
  std::string CompositePath = "none";
  std::string BlendPath = "none";

  // GPUComposite blended by CUDA: the render framebuffer's colour texture registered with CUDA.
  void* TargetResource = nullptr;            // cudaGraphicsResource_t
  vtkTextureObject* TargetTexture = nullptr; // VTK's (not owned): registered anew when it changes
  unsigned int TargetHandle = 0;
  int TargetSize[2] = { 0, 0 };
  bool TargetFailed = false; // once failed: the texture path from then on
  bool CudaBlend = true;     // SetCudaBlend
  bool Direct = false;       // this frame's image is already blended (Draw has nothing to do)
  std::string TargetProblem;
};

#endif
