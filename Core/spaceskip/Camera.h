// Camera matrices (column-major, OpenGL conventions) and the benchmark's orbit camera.
#pragma once
#include "Math.h"

namespace spaceskip {

struct Camera {
  mat4 view;
  mat4 proj;
};

mat4 lookAt(const double eye[3], const double center[3], const double up[3]);
mat4 orthographic(double l, double r, double b, double t, double n, double f);
mat4 perspective(double fovyDeg, double aspect, double n, double f);

/// Camera orbiting the box `bounds` (xmin,xmax,ymin,ymax,zmin,zmax): azimuth around +y,
/// elevation towards +y, in degrees. Orthographic (the paper's protocol) fits the box's bounding
/// sphere to the view; `zoom` > 1 magnifies. Perspective uses a 30 degree field of view.
Camera orbitCamera(const double bounds[6], double azimuthDeg, double elevationDeg, double zoom,
                   bool perspectiveProj, double aspect);

/// Camera at `eye` looking at `center` (for cameras inside the volume and grazing views).
Camera lookAtCamera(const double eye[3], const double center[3], const double up[3],
                    bool perspectiveProj, double fovyOrHeight, double aspect, double n, double f);

}  // namespace spaceskip
