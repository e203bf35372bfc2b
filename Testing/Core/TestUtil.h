// Helpers shared by the Core tests.
#pragma once
#include "spaceskip/Engine.h"
#include "spaceskip/Generators.h"
#include "spaceskip/ImageIO.h"

#include <string>

namespace spaceskip::test {

/// Renders `v` with builder `b` (CPU backend unless told) from an orbit camera.
inline Image renderWith(const Volume& v, const TransferFunction& tf, BuildParams p, double az, double el,
                        bool persp = false, int size = 96, BackendKind backend = BackendKind::CPU,
                        RenderParams rp = RenderParams{}) {
  Engine e(backend);
  e.setLogger([](const std::string&) {});
  e.setVolume(v);
  e.setTransferFunction(tf);
  e.setBuildParams(p);
  e.setRenderParams(rp);
  double b[6];
  v.worldBounds(b);
  Image img;
  e.render(orbitCamera(b, az, el, 1.0, persp, 1.0), size, size, img);
  return img;
}

inline BuildParams builder(BuilderKind k) {
  BuildParams p;
  p.builder = k;
  return p;
}

inline double coverage(const Image& img) {
  double s = 0;
  for (const auto& p : img.rgba) s += p.w;
  return s / double(img.rgba.size());
}

}  // namespace spaceskip::test
