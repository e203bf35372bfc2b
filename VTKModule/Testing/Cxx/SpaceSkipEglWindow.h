// Render windows for the VTK tests and the window benchmark: an X window (vtkRenderWindow's
// factory) or, on machines whose GL is headless (NVIDIA's EGL on a GPU server), a
// vtkGenericOpenGLRenderWindow on an EGL pbuffer context. Debian's VTK 9.2 has no EGL window of
// its own; libEGL.so.1 and libX11.so.6 are dlopen()ed, so nothing here is a link dependency.
#ifndef SpaceSkipEglWindow_h
#define SpaceSkipEglWindow_h

#include "vtkRenderWindow.h"
#include "vtkSmartPointer.h"

#include <string>

namespace sstest
{
/// A vtkGenericOpenGLRenderWindow of `width` x `height` drawing on the process's EGL context
/// (made on the first call: an OpenGL 3.2 core context of the first EGL device, on a 2048^2
/// pbuffer, current for good); against VTK >= 9.4 (glad) VTK's own vtkEGLRenderWindow, chosen
/// through VTK_DEFAULT_OPENGL_WINDOW. nullptr, with the reason in `why`, when EGL is not at hand.
/// Executables using it must export the GLX interposers defined with it (ENABLE_EXPORTS).
vtkSmartPointer<vtkRenderWindow> NewEglWindow(int width, int height, std::string& why);

/// The window a test draws into: with SPACESKIP_TEST_WINDOW=egl an EGL window (the process
/// exits with a message when there is none: a silent X fallback would hide what was asked for),
/// else vtkRenderWindow's own (X on Linux).
vtkSmartPointer<vtkRenderWindow> NewTestWindow();
}

#endif
