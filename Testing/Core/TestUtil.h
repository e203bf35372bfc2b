// Helpers shared by the Core tests.
#pragma once
#include "spaceskip/Backend.h"
#include "spaceskip/Engine.h"
#include "spaceskip/Generators.h"
#include "spaceskip/ImageIO.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

/// Skips the test (GTEST_SKIP, saying why) where no CUDA device is usable.
#define SKIP_WITHOUT_CUDA()                                               \
  do {                                                                    \
    std::string whyNoCuda;                                                \
    if (!spaceskip::cudaAvailable(&whyNoCuda)) GTEST_SKIP() << whyNoCuda; \
  } while (0)

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

/// The CPU backend's skipping builders (test defaults), then Grid on bricks of 4 cells (many
/// bricks, each with its own range) and, with `shallowMls`, a shallow k-d tree of MLS 32.
inline std::vector<BuildParams> skippingBuilders(bool shallowMls = false) {
  std::vector<BuildParams> v;
  for (BuilderKind k : {BuilderKind::Grid, BuilderKind::DistanceGrid, BuilderKind::LBVHCPU, BuilderKind::KdTreeCPU,
                        BuilderKind::Hybrid})
    v.push_back(builder(k));
  if (shallowMls) v.push_back(builder(BuilderKind::KdTreeCPU, LeafCriterion::Shallow, 32));
  v.push_back(builder(BuilderKind::Grid, LeafCriterion::Deep, 0, 4, 4));
  return v;
}

/// N-body 40x36x44 away from the origin with anisotropic spacing: index and world space differ.
inline Volume offsetNbody() {
  Volume v = generateVolume("nbody", vec3l{40, 36, 44});
  v.origin[0] = -7.5;
  v.origin[1] = 120;
  v.origin[2] = 3;
  v.spacing[0] = 0.5;
  v.spacing[1] = 1.0;
  v.spacing[2] = 0.75;
  return v;
}

/// A w x h x d volume of T (voxel type `type`) filled by f(i, j, k), unit spacing.
template <class T, class F>
Volume makeVolume(int w, int h, int d, VoxelType type, F f) {
  Volume v;
  v.allocate(vec3l{w, h, d}, type);
  T* p = reinterpret_cast<T*>(v.mutableData());
  for (int k = 0; k < d; ++k)
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i) p[i + int64_t(w) * (j + int64_t(h) * k)] = T(f(i, j, k));
  v.data = p;
  return v;
}

inline double coverage(const Image& img) {
  double s = 0;
  for (const auto& p : img.rgba) s += p.w;
  return s / double(img.rgba.size());
}

/// CUDA Naive draws the CPU Naive image of `v` (perspective orbit 30, 20; 64^2) within 2/255
/// under `tf` and `rp` (the two executors round differently), and every CUDA builder draws CUDA
/// Naive's image within 1/255 (skipping is lossless on the GPU too); `name` labels the failures.
inline void expectCudaBuildersEqualNaive(const Volume& v, const TransferFunction& tf, const RenderParams& rp,
                                         const std::string& name) {
  const Image ref = renderWith(v, tf, builder(BuilderKind::Naive), 30, 20, true, 64, BackendKind::CPU, rp);
  ASSERT_GT(coverage(ref), 0.0) << name;
  const Image cudaNaive = renderWith(v, tf, builder(BuilderKind::Naive), 30, 20, true, 64, BackendKind::CUDA, rp);
  EXPECT_LE(compareImages(ref, cudaNaive).maxAbs, 2.f / 255.f) << name << " CUDA Naive vs CPU Naive";
  for (BuilderKind k : {BuilderKind::Grid, BuilderKind::DistanceGrid, BuilderKind::LBVH, BuilderKind::KdTreeGPUFast,
                        BuilderKind::Hybrid}) {
    const Image img = renderWith(v, tf, builder(k), 30, 20, true, 64, BackendKind::CUDA, rp);
    EXPECT_LE(compareImages(cudaNaive, img).maxAbs, 1.f / 255.f) << name << " " << builderName(k) << " vs CUDA Naive";
  }
}

/// A 2-D table over [lo, hi] x gradient magnitude: opaque (alpha `a`) in a box of normalised
/// value [x0, x1] and normalised gradient magnitude [y0, y1], colour varying over both axes.
inline void setBox(TransferFunction& tf, int w, int h, float x0, float x1, float y0, float y1, float a) {
  tf.width2D = w;
  tf.height2D = h;
  tf.table2D.assign(size_t(w) * size_t(h), vec4f{0, 0, 0, 0});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float u = (float(x) + 0.5f) / float(w), g = (float(y) + 0.5f) / float(h);
      const bool in = u >= x0 && u <= x1 && g >= y0 && g <= y1;
      tf.table2D[size_t(y) * size_t(w) + size_t(x)] = vec4f{u, 1.f - g, 0.5f, in ? a : 0.f};
    }
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
