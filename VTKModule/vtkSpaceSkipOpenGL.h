// vtkSpaceSkipOpenGL: VTK's OpenGL loader header, whichever one the VTK at hand has.
// VTK up to 9.3 loads OpenGL through GLEW ("vtk_glew.h", modules VTK::glew and VTK::opengl);
// VTK 9.4 and later through glad ("vtk_glad.h", module VTK::glad). VTKModule/CMakeLists.txt
// links the one present and defines SPACESKIP_VTK_GLAD when it is glad; the window benchmark
// (VTKModule/Testing/Cxx) does the same. Internal to the module (not installed).
#ifndef vtkSpaceSkipOpenGL_h
#define vtkSpaceSkipOpenGL_h

#if defined(SPACESKIP_VTK_GLAD)
#include "vtk_glad.h" // IWYU pragma: export
#else
#include "vtk_glew.h" // IWYU pragma: export
#endif

#endif
