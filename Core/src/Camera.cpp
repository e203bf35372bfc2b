// Camera matrices, OpenGL conventions (right-handed view, NDC z in [-1,1]).
#include "spaceskip/Camera.h"

#include <algorithm>
#include <cmath>

namespace spaceskip {

namespace {
void norm3(double v[3]) {
  double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (l > 0) for (int i = 0; i < 3; ++i) v[i] /= l;
}
void cross3(const double a[3], const double b[3], double r[3]) {
  r[0] = a[1] * b[2] - a[2] * b[1];
  r[1] = a[2] * b[0] - a[0] * b[2];
  r[2] = a[0] * b[1] - a[1] * b[0];
}
}  // namespace

mat4 lookAt(const double eye[3], const double center[3], const double up[3]) {
  double f[3] = {center[0] - eye[0], center[1] - eye[1], center[2] - eye[2]};
  norm3(f);
  double s[3], u[3];
  cross3(f, up, s);
  norm3(s);
  cross3(s, f, u);
  mat4 m = identity4();
  for (int i = 0; i < 3; ++i) {
    m.m[i * 4 + 0] = s[i];
    m.m[i * 4 + 1] = u[i];
    m.m[i * 4 + 2] = -f[i];
  }
  // The translation rounded once (long double sums): far from the origin (1e15, where a double
  // ulp is 0.125) three rounded products would move the view by up to ~0.2 world units.
  auto dot = [&](const double* a) {
    return double((long double)a[0] * eye[0] + (long double)a[1] * eye[1] + (long double)a[2] * eye[2]);
  };
  m.m[12] = -dot(s);
  m.m[13] = -dot(u);
  m.m[14] = dot(f);
  return m;
}

mat4 orthographic(double l, double r, double b, double t, double n, double f) {
  mat4 m = identity4();
  m.m[0] = 2 / (r - l);
  m.m[5] = 2 / (t - b);
  m.m[10] = -2 / (f - n);
  m.m[12] = -(r + l) / (r - l);
  m.m[13] = -(t + b) / (t - b);
  m.m[14] = -(f + n) / (f - n);
  return m;
}

mat4 perspective(double fovyDeg, double aspect, double n, double f) {
  mat4 m{};
  double c = 1.0 / std::tan(fovyDeg * M_PI / 360.0);
  m.m[0] = c / aspect;
  m.m[5] = c;
  m.m[10] = (f + n) / (n - f);
  m.m[11] = -1;
  m.m[14] = 2 * f * n / (n - f);
  return m;
}

Camera orbitCamera(const double b[6], double az, double el, double zoom, bool persp, double aspect) {
  double c[3] = {(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2};
  double dx = b[1] - b[0], dy = b[3] - b[2], dz = b[5] - b[4];
  double radius = 0.5 * std::sqrt(dx * dx + dy * dy + dz * dz);
  if (!(radius > 0)) radius = 1;
  double a = az * M_PI / 180, e = el * M_PI / 180;
  double dir[3] = {std::sin(a) * std::cos(e), std::sin(e), std::cos(a) * std::cos(e)};
  double fov = 30.0;
  double dist = persp ? radius / std::sin(fov * M_PI / 360.0) / zoom : 3 * radius;
  double eye[3] = {c[0] + dir[0] * dist, c[1] + dir[1] * dist, c[2] + dir[2] * dist};
  double up[3] = {0, 1, 0};
  if (std::fabs(std::cos(e)) < 1e-6) { up[1] = 0; up[2] = -1; }
  Camera cam;
  cam.view = lookAt(eye, c, up);
  if (persp) {
    cam.proj = perspective(fov, aspect, std::max(dist - radius * 1.01, dist * 1e-3), dist + radius * 1.01);
  } else {
    double h = radius / zoom, w = h * aspect;
    if (aspect < 1) { w = radius / zoom; h = w / aspect; }
    cam.proj = orthographic(-w, w, -h, h, dist - radius * 1.01, dist + radius * 1.01);
  }
  return cam;
}

Camera lookAtCamera(const double eye[3], const double center[3], const double up[3], bool persp,
                    double fovyOrHeight, double aspect, double n, double f) {
  Camera cam;
  cam.view = lookAt(eye, center, up);
  if (persp) cam.proj = perspective(fovyOrHeight, aspect, n, f);
  else {
    double h = fovyOrHeight / 2;
    cam.proj = orthographic(-h * aspect, h * aspect, -h, h, n, f);
  }
  return cam;
}

}  // namespace spaceskip
