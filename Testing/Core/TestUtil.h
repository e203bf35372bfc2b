// Helpers shared by the Core tests.
#pragma once
#include "spaceskip/Engine.h"
#include "spaceskip/Generators.h"
#include "spaceskip/ImageIO.h"

#include <algorithm>
#include <random>
#include <string>
#include <vector>

namespace spaceskip::test {

/// An orbit camera around `v`'s world box (zoom 1, square view unless told).
inline Camera orbit(const Volume& v, double az, double el, bool persp = false, double aspect = 1.0) {
  double b[6];
  v.worldBounds(b);
  return orbitCamera(b, az, el, 1.0, persp, aspect);
}

/// Gives `e` a volume, a transfer function and build parameters; its log goes nowhere.
inline void load(Engine& e, const Volume& v, const TransferFunction& tf, const BuildParams& p) {
  e.setLogger([](const std::string&) {});
  e.setVolume(v);
  e.setTransferFunction(tf);
  e.setBuildParams(p);
}

/// Renders `v` with builder `b` (CPU backend unless told) from an orbit camera.
inline Image renderWith(const Volume& v, const TransferFunction& tf, BuildParams p, double az, double el,
                        bool persp = false, int size = 96, BackendKind backend = BackendKind::CPU,
                        RenderParams rp = RenderParams{}) {
  Engine e(backend);
  load(e, v, tf, p);
  e.setRenderParams(rp);
  Image img;
  e.render(orbit(v, az, el, persp), size, size, img);
  return img;
}

inline BuildParams builder(BuilderKind k, LeafCriterion leaf = LeafCriterion::Deep, int mls = 0, int bins = 4,
                           int brick = 8) {
  BuildParams p;
  p.builder = k;
  p.leaf = leaf;
  p.maxLeafSize = mls;
  p.bins = bins;
  p.brick = brick;
  return p;
}

inline double coverage(const Image& img) {
  double s = 0;
  for (const auto& p : img.rgba) s += p.w;
  return s / double(img.rgba.size());
}

/// Random piecewise-linear TF over [0, 255] (256 entries): about half its points transparent.
inline TransferFunction randomTF(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<TFPoint> pts;
  pts.push_back({0.0, u(rng), u(rng), u(rng), 0.f});
  double v = 0;
  while (v < 255) {
    v += 10 + 60 * u(rng);
    const float a = u(rng) < 0.5f ? 0.f : u(rng);
    pts.push_back({std::min(v, 255.0), u(rng), u(rng), u(rng), a});
  }
  return TransferFunction::fromPoints(pts, 0, 255, 256);
}

/// Occupancy grid of `dims` 8^3 bricks, each occupied with probability p.
inline OccupancyGrid randomBrickGrid(vec3i dims, double p, unsigned seed) {
  OccupancyGrid g;
  g.brick = 8;
  g.dims = dims;
  g.cellDims = vec3i{dims.x * 8, dims.y * 8, dims.z * 8};
  g.occ.resize(size_t(g.size()));
  std::mt19937 rng(seed);
  std::bernoulli_distribution b(p);
  for (auto& o : g.occ) g.occupied += (o = b(rng) ? 1 : 0);
  return g;
}

/// One CPU frame of builder `k` from `cam` (with render parameters `rp` and knobs `t`), with the
/// samples it took.
inline Image renderCounting(const Volume& v, const TransferFunction& tf, BuilderKind k, const Camera& cam, int size,
                            int64_t& samples, RenderParams rp = RenderParams{}, const Tuning& t = Tuning{}) {
  Engine e(BackendKind::CPU);
  e.setTuning(t);
  load(e, v, tf, builder(k));
  rp.countSamples = true;
  e.setRenderParams(rp);
  Image img;
  e.render(cam, size, size, img);
  samples = e.frameStats().samples;
  return img;
}

}  // namespace spaceskip::test
