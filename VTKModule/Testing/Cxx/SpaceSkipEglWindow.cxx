// See SpaceSkipEglWindow.h.
#include "SpaceSkipEglWindow.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkGenericOpenGLRenderWindow.h"
#include "vtkNew.h"

#include <dlfcn.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

// GLEW's glewInit() ends with its GLX part, which fails without a current GLX context's display
// (an EGL context has none). This definition, exported from the executable, interposes libGLX's
// and hands GLEW a plain X connection in --egl mode; otherwise it forwards to libGLX.
// (Xlib is dlopen()ed too, so no X11 headers are needed: a Display* is a void* here.)
static void* gEglModeDisplay = nullptr;
extern "C" __attribute__((visibility("default"))) void* glXGetCurrentDisplay()
{
  if (gEglModeDisplay)
  {
    return gEglModeDisplay;
  }
  using Fn = void* (*)();
  static Fn real = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, "glXGetCurrentDisplay"));
  return real ? real() : nullptr;
}
// GLEW loads glXGetCurrentDisplay through glXGetProcAddressARB: hand it the one above.
extern "C" __attribute__((visibility("default"))) void* glXGetProcAddressARB(const unsigned char* name)
{
  if (gEglModeDisplay && std::strcmp(reinterpret_cast<const char*>(name), "glXGetCurrentDisplay") == 0)
  {
    return reinterpret_cast<void*>(&glXGetCurrentDisplay);
  }
  using Fn = void* (*)(const unsigned char*);
  static Fn real = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, "glXGetProcAddressARB"));
  return real ? real(name) : nullptr;
}

namespace
{
// EGL through dlopen (no EGL headers or link dependency for CI): an OpenGL 3.2+ context on a
// pbuffer, made current for good.
bool MakeEglContext(int w, int h, std::string& why)
{
  void* lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_GLOBAL);
  if (!lib)
  {
    why = "no libEGL.so.1";
    return false;
  }
  using Ptr = void*;
  using Int = int32_t;
  auto sym = [&](const char* n) { return dlsym(lib, n); };
  auto getProc = reinterpret_cast<void* (*)(const char*)>(sym("eglGetProcAddress"));
  auto getDisplay = reinterpret_cast<Ptr (*)(Ptr)>(sym("eglGetDisplay"));
  auto initialize = reinterpret_cast<unsigned (*)(Ptr, Int*, Int*)>(sym("eglInitialize"));
  auto chooseConfig = reinterpret_cast<unsigned (*)(Ptr, const Int*, Ptr*, Int, Int*)>(sym("eglChooseConfig"));
  auto createPbuffer = reinterpret_cast<Ptr (*)(Ptr, Ptr, const Int*)>(sym("eglCreatePbufferSurface"));
  auto bindApi = reinterpret_cast<unsigned (*)(unsigned)>(sym("eglBindAPI"));
  auto createContext = reinterpret_cast<Ptr (*)(Ptr, Ptr, Ptr, const Int*)>(sym("eglCreateContext"));
  auto makeCurrent = reinterpret_cast<unsigned (*)(Ptr, Ptr, Ptr, Ptr)>(sym("eglMakeCurrent"));
  auto getError = reinterpret_cast<Int (*)()>(sym("eglGetError"));
  if (!getDisplay || !initialize || !chooseConfig || !createPbuffer || !bindApi || !createContext ||
    !makeCurrent || !getError || !getProc)
  {
    why = "libEGL.so.1 lacks EGL 1.4 entry points";
    return false;
  }
  Ptr dpy = nullptr;
  Int major = 0, minor = 0;
  // The first device (EGL_EXT_platform_device), else the default display.
  auto queryDevices = reinterpret_cast<unsigned (*)(Int, Ptr*, Int*)>(getProc("eglQueryDevicesEXT"));
  auto platformDisplay = reinterpret_cast<Ptr (*)(unsigned, Ptr, const Int*)>(getProc("eglGetPlatformDisplayEXT"));
  Ptr devices[8];
  Int nDevices = 0;
  if (queryDevices && platformDisplay && queryDevices(8, devices, &nDevices) && nDevices > 0)
  {
    dpy = platformDisplay(0x313F /* EGL_PLATFORM_DEVICE_EXT */, devices[0], nullptr);
  }
  if (!dpy || !initialize(dpy, &major, &minor))
  {
    dpy = getDisplay(nullptr /* EGL_DEFAULT_DISPLAY */);
    if (!dpy || !initialize(dpy, &major, &minor))
    {
      why = "eglInitialize failed, error 0x" + std::to_string(getError());
      return false;
    }
  }
  const Int cfgAttribs[] = { 0x3033 /* SURFACE_TYPE */, 0x0001 /* PBUFFER_BIT */, 0x3024, 8, 0x3023, 8,
    0x3022, 8, 0x3021, 8, 0x3025 /* DEPTH */, 24, 0x3040 /* RENDERABLE_TYPE */, 0x0008 /* OPENGL_BIT */,
    0x3038 /* NONE */ };
  Ptr cfg = nullptr;
  Int n = 0;
  if (!chooseConfig(dpy, cfgAttribs, &cfg, 1, &n) || n < 1)
  {
    why = "eglChooseConfig found no OpenGL pbuffer config";
    return false;
  }
  const Int pbAttribs[] = { 0x3057 /* WIDTH */, w, 0x3056 /* HEIGHT */, h, 0x3038 };
  Ptr surf = createPbuffer(dpy, cfg, pbAttribs);
  bindApi(0x30A2 /* EGL_OPENGL_API */);
  const Int ctxAttribs[] = { 0x3098 /* MAJOR */, 3, 0x30FB /* MINOR */, 2, 0x30FD /* PROFILE_MASK */,
    0x1 /* CORE */, 0x3038 };
  Ptr ctx = createContext(dpy, cfg, nullptr, ctxAttribs);
  if (!surf || !ctx || !makeCurrent(dpy, surf, surf, ctx))
  {
    why = "EGL pbuffer/context/make-current failed, error 0x" + std::to_string(getError());
    return false;
  }
  return true;
}

}  // namespace

namespace sstest
{
vtkSmartPointer<vtkRenderWindow> NewEglWindow(int width, int height, std::string& why)
{
#ifdef SPACESKIP_VTK_GLAD
  // VTK >= 9.4 (glad) has its own EGL window, picked by its object factory at run time
  // (VTK_DEFAULT_OPENGL_WINDOW): a vtkGenericOpenGLRenderWindow on our own EGL context crashes
  // there, as glad loads GL through VTK's window and not through the current context.
  setenv("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow", 1);
  auto w = vtkSmartPointer<vtkRenderWindow>::New();
  if (!w || std::strcmp(w->GetClassName(), "vtkEGLRenderWindow") != 0)
  {
    why = std::string("this VTK made a ") + (w ? w->GetClassName() : "null") +
      " for VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow (built without EGL?)";
    return nullptr;
  }
  w->SetSize(width, height);
  return w;
#else
  static bool made = false;
  static std::string failure;
  if (!made && failure.empty())
  {
    void* xlib = dlopen("libX11.so.6", RTLD_NOW | RTLD_GLOBAL);
    auto openDisplay = xlib ? reinterpret_cast<void* (*)(const char*)>(dlsym(xlib, "XOpenDisplay")) : nullptr;
    gEglModeDisplay = openDisplay ? openDisplay(nullptr) : nullptr;
    if (!gEglModeDisplay)
    {
      failure = "no X display for GLEW's GLX part";
    }
    else if (!MakeEglContext(2048, 2048, failure))
    {
      gEglModeDisplay = nullptr;
    }
    made = failure.empty();
  }
  if (!made)
  {
    why = failure;
    return nullptr;
  }
  auto gw = vtkSmartPointer<vtkGenericOpenGLRenderWindow>::New();
  // The context is always current: answer the window's questions so.
  vtkNew<vtkCallbackCommand> answer;
  answer->SetCallback([](vtkObject*, unsigned long event, void*, void* data) {
    if (event == vtkCommand::WindowIsCurrentEvent)
      *static_cast<bool*>(data) = true;
    else if (event == vtkCommand::WindowSupportsOpenGLEvent || event == vtkCommand::WindowIsDirectEvent)
      *static_cast<int*>(data) = 1;
  });
  gw->AddObserver(vtkCommand::WindowIsCurrentEvent, answer);
  gw->AddObserver(vtkCommand::WindowSupportsOpenGLEvent, answer);
  gw->AddObserver(vtkCommand::WindowIsDirectEvent, answer);
  gw->SetSize(width, height);
  gw->SetReadyForRendering(true);
  if (!gw->InitializeFromCurrentContext())
  {
    why = "VTK could not initialize from the EGL context";
    return nullptr;
  }
  return gw;
#endif
}

vtkSmartPointer<vtkRenderWindow> NewTestWindow()
{
  const char* kind = std::getenv("SPACESKIP_TEST_WINDOW");
  if (kind && std::strcmp(kind, "egl") == 0)
  {
    std::string why;
    vtkSmartPointer<vtkRenderWindow> w = NewEglWindow(300, 300, why);
    if (!w)
    {
      std::fprintf(stderr, "SPACESKIP_TEST_WINDOW=egl: %s\n", why.c_str());
      std::exit(EXIT_FAILURE);
    }
    std::fprintf(stderr, "SPACESKIP_TEST_WINDOW=egl: %s\n", w->GetClassName());
    return w;
  }
  return vtkSmartPointer<vtkRenderWindow>::New();
}
}
