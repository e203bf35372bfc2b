// Rectilinear grids drawn through their coordinates (AxisWarp.h): the warp's reads, a linear
// field drawn exactly, and skipping lossless on the virtual lattice (CPU; CUDA on a GPU machine).
#include "TestUtil.h"

#include "spaceskip/AxisWarp.h"
#include "spaceskip/Classification.h"

#include <cmath>
#include <random>

using namespace spaceskip;

namespace {

/// Coordinates of n points on [0, len]: coordinate i at len * s(i / (n - 1)).
template <class S>
std::vector<double> axisCoords(int64_t n, double len, S s) {
  std::vector<double> x(static_cast<size_t>(n));
  for (int64_t i = 0; i < n; ++i) x[size_t(i)] = n > 1 ? len * s(double(i) / double(n - 1)) : 0.0;
  return x;
}

/// Strongly non-uniform axes: x quadratic (cells 1:3 from one end to the other), y uniform, z fine
/// in the middle and coarse at the ends (cells about 1:6).
std::vector<double> coordsOf(int a, int64_t n) {
  if (a == 0) return axisCoords(n, double(n - 1), [](double t) { return 0.5 * t + 0.5 * t * t; });
  if (a == 1) return axisCoords(n, double(n - 1), [](double t) { return t; });
  return axisCoords(n, 0.8 * double(n - 1), [](double t) { return t + 0.35 * std::sin(2.0 * M_PI * t) / M_PI; });
}

/// `v` as a rectilinear grid of its points at `coords` (ascending): the virtual lattice over the
/// grid's bounds.
Volume warped(Volume v, const std::vector<double> coords[3]) {
  const double* c[3] = {coords[0].data(), coords[1].data(), coords[2].data()};
  const int64_t n[3] = {v.dims.x, v.dims.y, v.dims.z};
  auto w = AxisWarp::fromCoordinates(c, n);
  for (int a = 0; a < 3; ++a) {
    v.spacing[a] = w->spacing(a);
    v.origin[a] = w->first[a];
  }
  v.warp = w;
  return v;
}

Volume warped(Volume v) {
  const std::vector<double> c[3] = {coordsOf(0, v.dims.x), coordsOf(1, v.dims.y), coordsOf(2, v.dims.z)};
  return warped(std::move(v), c);
}

/// The grid index of world coordinate x on an ascending axis `c`, in double.
double gridIndex(const std::vector<double>& c, double x) {
  size_t i = 0;
  while (i + 2 < c.size() && c[i + 1] <= x) ++i;
  return double(i) + (x - c[i]) / (c[i + 1] - c[i]);
}

}  // namespace

TEST(Rectilinear, WarpReadsTheGridThroughItsCoordinates) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> step(0.05, 3.0);
  for (int64_t n : {2, 3, 17, 200}) {
    std::vector<double> x(static_cast<size_t>(n));
    x[0] = -4.0;
    for (int64_t i = 1; i < n; ++i) x[size_t(i)] = x[size_t(i - 1)] + step(rng);
    const std::vector<double> uni = axisCoords(n, 2.5 * double(n - 1), [](double t) { return t; });
    const double* c[3] = {x.data(), uni.data(), x.data()};
    const int64_t dims[3] = {n, n, n};
    auto w = AxisWarp::fromCoordinates(c, dims);
    const AxisWarpView view = w->view();
    const double h = w->spacing(0);
    std::uniform_real_distribution<float> at(0.f, float(n - 1));
    for (int s = 0; s < 2000; ++s) {
      const float u = s == 0 ? 0.f : (s == 1 ? float(n - 1) : at(rng));
      const vec3f g = view.apply(vec3f{u, u, u});
      const double expect = gridIndex(x, x[0] + double(u) * h);
      EXPECT_NEAR(g.x, expect, 2e-4 * double(n)) << "n " << n << " u " << u;
      EXPECT_EQ(g.y, u) << "a uniform axis reads the lattice itself, bit for bit";
    }
    // Outside the grid and NaN: unchanged (the sampler clamps as for an image).
    EXPECT_EQ(view.apply(vec3f{-3.f, 0, 0}).x, -3.f);
    EXPECT_EQ(view.apply(vec3f{float(n) + 2.f, 0, 0}).x, float(n) + 2.f);
    EXPECT_TRUE(std::isnan(view.apply(vec3f{NAN, 0, 0}).x));
  }
  // A descending axis reads as an ascending one from its first coordinate.
  const std::vector<double> down = {10, 9, 7, 4, 0}, up = {0, 1, 3, 6, 10};
  const double* cd[3] = {down.data(), up.data(), up.data()};
  const int64_t n5[3] = {5, 5, 5};
  const auto dw = AxisWarp::fromCoordinates(cd, n5);
  const AxisWarpView dv = dw->view();
  for (float u : {0.3f, 1.f, 2.5f, 3.9f}) EXPECT_NEAR(dv.apply(vec3f{u, u, u}).x, dv.apply(vec3f{u, u, u}).y, 1e-6f);
  // Bad coordinates: an error naming the axis and the index.
  for (double bad : {double(NAN), double(INFINITY), 3.0 /* not increasing */}) {
    std::vector<double> b = up;
    b[3] = bad;
    const double* cb[3] = {up.data(), b.data(), up.data()};
    try {
      (void)AxisWarp::fromCoordinates(cb, n5);
      ADD_FAILURE() << "accepted y coordinate " << bad;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("y coordinate"), std::string::npos) << e.what();
    }
  }
}

TEST(Rectilinear, LinearFieldDrawsAsTheUniformImageOfTheSameFunction) {
  // A field linear in world space is linear within every cell of the grid, so trilinear
  // interpolation through the coordinates reproduces it exactly: the grid's picture is the one of
  // a uniform image of the same function over the same bounds.
  const vec3l d{33, 29, 31};
  const std::vector<double> c[3] = {coordsOf(0, d.x), coordsOf(1, d.y), coordsOf(2, d.z)};
  auto field = [](double x, double y, double z) { return 2.0 * x + 0.5 * y - 1.5 * z + 80.0; };
  Volume grid = warped(test::makeVolume<float>(int(d.x), int(d.y), int(d.z), VoxelType::Float32, [&](int i, int j, int k) {
                         return field(c[0][size_t(i)], c[1][size_t(j)], c[2][size_t(k)]);
                       }),
                       c);
  Volume image = test::makeVolume<float>(int(d.x), int(d.y), int(d.z), VoxelType::Float32, [&](int i, int j, int k) {
    return field(grid.origin[0] + i * grid.spacing[0], grid.origin[1] + j * grid.spacing[1],
                 grid.origin[2] + k * grid.spacing[2]);
  });
  std::copy(grid.spacing, grid.spacing + 3, image.spacing);
  std::copy(grid.origin, grid.origin + 3, image.origin);
  Volume ignored = grid;  // the grid's voxels taken as a uniform image: what the warp corrects
  ignored.warp.reset();
  double lo = 0, hi = 0;
  ASSERT_TRUE(image.scalarRange(lo, hi));
  auto tf = TransferFunction::fromPoints(
      {{lo, 0.2f, 0.4f, 1.f, 0.f}, {0.5 * (lo + hi), 1.f, 0.8f, 0.1f, 0.05f}, {hi, 1.f, 0.1f, 0.1f, 0.3f}}, lo, hi);
  for (bool shade : {false, true}) {
    RenderParams rp;
    rp.shade = shade;
    const Image ref = test::renderWith(image, tf, test::builder(BuilderKind::Naive), 30, 20, true, 64, BackendKind::CPU, rp);
    const Image img = test::renderWith(grid, tf, test::builder(BuilderKind::Naive), 30, 20, true, 64, BackendKind::CPU, rp);
    const Image off = test::renderWith(ignored, tf, test::builder(BuilderKind::Naive), 30, 20, true, 64, BackendKind::CPU, rp);
    ASSERT_GT(test::coverage(ref), 0.1);
    EXPECT_LE(compareImages(ref, img).maxAbs, 1.f / 255.f) << (shade ? "shaded" : "unshaded");
    EXPECT_GT(compareImages(ref, off).maxAbs, 0.05f) << "the coordinates change the picture";
  }
}

TEST(Rectilinear, VirtualBrickRangesBoundTheirSamples) {
  Volume v = warped(generateVolume("vessels", vec3l{37, 30, 41}));
  const RangeGrid r = computeRangeGrid(v, 4);
  const AxisWarpView w = v.warp->view();
  const WarpedSampler s{v.data, v.type, v.dims.x, v.dims.y, v.dims.z, w};
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  const vec3i cd = v.cellDims();
  for (int q = 0; q < 20000; ++q) {
    const vec3f p{U(rng) * float(cd.x), U(rng) * float(cd.y), U(rng) * float(cd.z)};
    const int bx = std::min(int(p.x) / r.brick, r.dims.x - 1), by = std::min(int(p.y) / r.brick, r.dims.y - 1),
              bz = std::min(int(p.z) / r.brick, r.dims.z - 1);
    const float val = s.sample(p);
    const int64_t i = r.index(bx, by, bz);
    ASSERT_GE(val, r.vmin[size_t(i)]) << p.x << " " << p.y << " " << p.z;
    ASSERT_LE(val, r.vmax[size_t(i)]) << p.x << " " << p.y << " " << p.z;
  }
}

TEST(Rectilinear, EveryBuilderEqualsNaive) {
  for (const char* shape : {"nbody", "vessels", "rm"}) {
    Volume v = warped(generateVolume(shape, vec3l{40, 42, 37}));
    double lo = 0, hi = 0;
    ASSERT_TRUE(v.scalarRange(lo, hi));
    const auto tf = TransferFunction::preset("ramp", lo, hi);
    for (int mode = 0; mode < 3; ++mode) {  // unshaded, shaded, maximum intensity
      RenderParams rp;
      rp.shade = mode == 1;
      if (mode == 2) rp.blend = BlendMode::MaximumIntensity;
      const std::string name = std::string(shape) + (mode == 0 ? "" : mode == 1 ? " shaded" : " MIP");
      const Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 30, 20, true, 64, BackendKind::CPU, rp);
      ASSERT_GT(test::coverage(ref), 0.0) << name;
      for (const BuildParams& p : test::skippingBuilders(true)) {
        const Image img = test::renderWith(v, tf, p, 30, 20, true, 64, BackendKind::CPU, rp);
        EXPECT_LE(compareImages(ref, img).maxAbs, 1.f / 255.f) << name << " " << builderName(p.builder);
      }
    }
  }
}

TEST(Rectilinear, CudaBuildersEqualNaive) {
  SKIP_WITHOUT_CUDA();
  for (const char* shape : {"nbody", "vessels"}) {
    Volume v = warped(generateVolume(shape, vec3l{40, 42, 37}));
    double lo = 0, hi = 0;
    ASSERT_TRUE(v.scalarRange(lo, hi));
    const auto tf = TransferFunction::preset("ramp", lo, hi);
    for (bool shade : {false, true}) {
      RenderParams rp;
      rp.shade = shade;
      test::expectCudaBuildersEqualNaive(v, tf, rp, std::string(shape) + (shade ? " shaded" : ""));
    }
  }
}

TEST(Rectilinear, WhatAWarpCannotTakeIsRefused) {
  Volume v = warped(generateVolume("nbody", vec3l{20, 20, 20}));
  Volume two = v;
  two.components = 2;
  EXPECT_THROW(validate(two), std::runtime_error);
  Volume shortWarp = v;
  shortWarp.dims.x = 19;
  EXPECT_THROW(validate(shortWarp), std::runtime_error);
}
