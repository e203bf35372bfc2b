// 2-D transfer functions (value x gradient magnitude) and gradient opacity: they change the image
// as VTK's semantics say, and skipping stays lossless (every builder equals Naive).
#include "TestUtil.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

using namespace spaceskip;

namespace {

using test::setBox;

vec4f at(const Image& img, int x, int y) { return img.rgba[size_t(y) * size_t(img.width) + size_t(x)]; }

void expectBuildersEqualNaive(const Volume& v, const TransferFunction& tf, const RenderParams& rp, const char* what) {
  const Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 30, 20, true, 48, BackendKind::CPU, rp);
  ASSERT_GT(test::coverage(ref), 0.0) << what << " renders nothing";
  for (const BuildParams& bp : test::skippingBuilders(true)) {
    const Image img = test::renderWith(v, tf, bp, 30, 20, true, 48, BackendKind::CPU, rp);
    const ImageDiff d = compareImages(ref, img);
    EXPECT_LE(d.maxAbs, 1.f / 255.f) << what << " " << builderName(bp.builder) << " brick " << bp.brick;
  }
}


// The transfer functions every builder test draws `v` with: the ramp over its range (tf), the
// same with a 2-D box from 0.02 of the range, where the 1-D ramp is transparent so that a 1-D
// occupancy would lose it (tf2), and with a gradient opacity that fades flat regions out (go).
struct GradientCases {
  TransferFunction tf, tf2, go;
};
GradientCases gradientCases(const Volume& v) {
  double lo = 0, hi = 1;
  EXPECT_TRUE(v.scalarRange(lo, hi));
  GradientCases c;
  c.tf = TransferFunction::preset("ramp", lo, hi, 256);
  c.tf2 = c.tf;
  setBox(c.tf2, 48, 24, 0.02f, 0.9f, 0.05f, 0.6f, 0.7f);
  c.go = c.tf;
  c.go.gradientOpacity.resize(1024);
  for (size_t i = 0; i < c.go.gradientOpacity.size(); ++i) c.go.gradientOpacity[i] = float(i) / 1023.f;
  return c;
}
// A second array as the 2-D table's y axis (vtkGPUVolumeRayCastMapper's Transfer2DYAxisArray):
// two float components, x = a ball of value 200 fading to 0 at its rim (radius 0.45 of the box),
// y = 250 i / (w - 1), a ramp across the volume's first axis. The table is opaque for x in the
// upper 0.8 of its range and y in the upper half of [0, 250]: only the half i > w/2 is drawn.
Volume secondArrayVolume(int w, int h, int d) {
  Volume v;
  v.allocate(vec3l{w, h, d}, VoxelType::Float32, 2);
  float* p = reinterpret_cast<float*>(v.mutableData());
  for (int k = 0; k < d; ++k)
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i) {
        const float dx = (float(i) + 0.5f) / float(w) - 0.5f, dy = (float(j) + 0.5f) / float(h) - 0.5f,
                    dz = (float(k) + 0.5f) / float(d) - 0.5f;
        const float r = std::sqrt(dx * dx + dy * dy + dz * dz);
        const int64_t n = i + int64_t(w) * (j + int64_t(h) * k);
        p[2 * n] = std::max(0.f, 200.f * (1.f - r / 0.45f));
        p[2 * n + 1] = 250.f * float(i) / float(w - 1);
      }
  return v;
}
TransferFunction secondArrayTF(float y0, float y1) {
  TransferFunction tf = TransferFunction::preset("ramp", 0, 200, 256);
  tf.ownOpacityRange = true;  // the y axis spans the second array's range
  tf.opacityRangeMin = 0;
  tf.opacityRangeMax = 250;
  setBox(tf, 40, 20, 0.2f, 1.f, y0, y1, 0.3f);
  return tf;
}
int64_t occupiedBricks(const Volume& v, const TransferFunction& tf) {
  Engine e(BackendKind::CPU);
  test::load(e, v, tf, test::builder(BuilderKind::Grid));
  Image img;
  e.render(test::orbit(v, 0, 0), 16, 16, img);
  int64_t n = 0;
  for (uint8_t o : e.occupancy().occ) n += o != 0;
  return n;
}
}  // namespace

TEST(GradientTF, SecondArrayAsYAxis) {
  const Volume v = secondArrayVolume(48, 40, 36);
  const TransferFunction upper = secondArrayTF(0.5f, 1.f), all = secondArrayTF(0.f, 1.f);
  // Front view: the image's x runs along the volume's first axis, one way or the other; the
  // middle row is drawn on exactly one side of the centre (where y >= 125), on both with `all`.
  const Image img = test::renderWith(v, upper, test::builder(BuilderKind::Naive), 0, 0, false, 64);
  const Image both = test::renderWith(v, all, test::builder(BuilderKind::Naive), 0, 0, false, 64);
  const float left = at(img, 20, 32).w, right = at(img, 44, 32).w;
  EXPECT_TRUE((left == 0.f) != (right == 0.f)) << "left " << left << " right " << right;
  EXPECT_GT(std::max(left, right), 0.2f);
  EXPECT_GT(at(both, 20, 32).w, 0.2f);
  EXPECT_GT(at(both, 44, 32).w, 0.2f);
  // Skipping: the bricks whose y values reach only empty rows are empty (about half), losslessly.
  const int64_t nUpper = occupiedBricks(v, upper), nAll = occupiedBricks(v, all);
  EXPECT_GT(nUpper, 0);
  EXPECT_LT(double(nUpper), 0.7 * double(nAll)) << nUpper << " of " << nAll;
  for (bool shade : {false, true}) {
    RenderParams rp;
    rp.shade = shade;
    expectBuildersEqualNaive(v, upper, rp, shade ? "second array shaded" : "second array");
  }
  // A brick's x values alone never empty it: a box over low x only (where the ball is absent)
  // keeps the x-empty bricks occupied, and the image still equals Naive's.
  TransferFunction lowX = upper;
  setBox(lowX, 40, 20, 0.f, 0.1f, 0.5f, 1.f, 0.3f);
  expectBuildersEqualNaive(v, lowX, RenderParams{}, "second array, low x");
}

TEST(GradientTF, EveryBuilderEqualsNaiveWith2DTableAndGradientOpacity) {
  for (const char* shape : {"nbody", "vessels", "rm"}) {
    Volume v = generateVolume(shape, vec3l{40, 42, 37});
    v.spacing[0] = 0.8;  // anisotropic: the gradient's per-axis normalisation matters
    v.spacing[2] = 1.3;
    const auto [tf, tf2, go] = gradientCases(v);
    for (bool shade : {false, true}) {
      RenderParams rp;
      rp.shade = shade;
      expectBuildersEqualNaive(v, tf2, rp, (std::string(shape) + " 2-D" + (shade ? " shaded" : "")).c_str());
    }
    expectBuildersEqualNaive(v, go, RenderParams{}, (std::string(shape) + " gradient opacity").c_str());
    // Both change the image (the tests above could not pass by ignoring them).
    const Image plain = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 30, 20, true, 48);
    EXPECT_GT(compareImages(plain, test::renderWith(v, tf2, test::builder(BuilderKind::Grid), 30, 20, true, 48)).maxAbs,
              0.05f) << shape;
    EXPECT_GT(compareImages(plain, test::renderWith(v, go, test::builder(BuilderKind::Grid), 30, 20, true, 48)).maxAbs,
              0.05f) << shape;
  }
}

TEST(GradientTF, FlatRegionTransparentIn2DOpaqueIn1D) {
  // A cube of constant value 200 inside a background of 0: inside, the gradient is 0. The 1-D TF
  // makes 200 opaque; the 2-D TF makes 200 opaque only where the gradient is large (the cube's
  // faces), so a ray through the cube's middle along z, which meets a face only where the
  // gradient is large, sees far less than with the 1-D TF; the background stays empty in both.
  Volume v = test::makeVolume<float>(40, 40, 40, VoxelType::Float32, [](int i, int j, int k) {
    return (i >= 8 && i < 32 && j >= 8 && j < 32 && k >= 8 && k < 32) ? 200.f : 0.f;
  });
  TransferFunction tf = TransferFunction::fromPoints({{0, 1.f, 1.f, 1.f, 0.f}, {100, 1.f, 1.f, 1.f, 0.f},
                                                      {150, 1.f, 1.f, 1.f, 0.5f}, {200, 1.f, 1.f, 1.f, 0.5f}},
                                                     0, 200, 256);
  TransferFunction tf2 = tf;
  // Value >= 140, gradient magnitude >= range/16; opacity 0.1 per sample (2-D opacity is raw).
  setBox(tf2, 32, 16, 0.7f, 1.f, 0.25f, 1.f, 0.1f);
  const Image one = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 0, 0, false, 64);
  const Image two = test::renderWith(v, tf2, test::builder(BuilderKind::Grid), 0, 0, false, 64);
  EXPECT_GT(at(one, 32, 32).w, 0.99f);  // 24 cells of opacity 0.5 per unit
  EXPECT_LT(at(two, 32, 32).w, 0.8f);   // only the samples near the two faces
  EXPECT_GT(at(two, 32, 32).w, 0.1f);
  // Lossless with the flat inside transparent.
  expectBuildersEqualNaive(v, tf2, RenderParams{}, "cube 2-D");
  // A 2-D table that gives no value in the data opacity at any gradient: every brick empty.
  TransferFunction none = tf;
  setBox(none, 32, 16, 0.1f, 0.3f, 0.f, 1.f, 1.f);  // values 20..60: none in the data (0 and 200)
  // (voxel values 0 and 200 blend to 20..60 only at the cube's faces: those bricks stay occupied)
  Engine e(BackendKind::CPU);
  test::load(e, v, none, test::builder(BuilderKind::Grid));
  Image img;
  e.render(test::orbit(v, 0, 0), 32, 32, img);
  const OccupancyGrid& occ = e.occupancy();
  int64_t occupied = 0;
  for (uint8_t o : occ.occ) occupied += o != 0;
  Engine e1(BackendKind::CPU);
  test::load(e1, v, tf, test::builder(BuilderKind::Grid));
  e1.render(test::orbit(v, 0, 0), 32, 32, img);
  int64_t occupied1 = 0;
  for (uint8_t o : e1.occupancy().occ) occupied1 += o != 0;
  EXPECT_LT(occupied, occupied1);  // the cube's inner bricks (value 200 only) are empty with `none`
}

TEST(GradientTF, GradientBoundEmptiesFlatBricks) {
  // Three flat slabs along z (values 60, 140, 220) with steps two voxels wide at z = 20 and 44
  // (normalised gradient up to about 0.49): a 2-D box over every value at gradients from 0.15
  // only is transparent inside the slabs, whose bricks' 3x3x3 neighbourhoods hold one value (10
  // of the 16 bricks along z); the 1-D rule (any gradient) keeps them all.
  auto slabs = [](int, int, int k) {
    return 60.f + 80.f * std::min(std::max(float(k - 20) / 2.f, 0.f), 1.f) +
           80.f * std::min(std::max(float(k - 44) / 2.f, 0.f), 1.f);
  };
  Volume v = test::makeVolume<float>(40, 36, 128, VoxelType::Float32, slabs);
  v.spacing[2] = 1.5;  // anisotropic: the bound's per-axis factors matter
  TransferFunction tf = TransferFunction::preset("ramp", 0, 255, 256);
  TransferFunction high = tf, all = tf;
  setBox(high, 32, 16, 0.f, 1.f, 0.15f, 1.f, 0.5f);
  setBox(all, 32, 16, 0.f, 1.f, 0.f, 1.f, 0.5f);
  auto occupied = [&](const TransferFunction& t, BackendKind kind) {
    Engine e(kind);
    test::load(e, v, t, test::builder(BuilderKind::Grid));
    Image img;
    e.render(test::orbit(v, 0, 0), 16, 16, img);
    return e.occupancy().occupied;
  };
  const int64_t nHigh = occupied(high, BackendKind::CPU), nAll = occupied(all, BackendKind::CPU);
  std::cout << "occupied bricks: box at gradients >= 0.15 " << nHigh << ", over every gradient " << nAll << "\n";
  EXPECT_GT(nHigh, 0);
  EXPECT_LT(double(nHigh), 0.6 * double(nAll)) << nHigh << " of " << nAll;
  // Lossless: every builder draws Naive's image (Naive marches every brick).
  expectBuildersEqualNaive(v, high, RenderParams{}, "slabs, high gradients");
  RenderParams shaded;
  shaded.shade = true;
  expectBuildersEqualNaive(v, high, shaded, "slabs, high gradients, shaded");
  // (A box above the steps' gradients keeps their bricks: the bound R |k| takes the
  // neighbourhood's whole range R along every axis at once, 1.14 here against 0.49.)
  if (cudaAvailable()) {  // the CUDA classification applies the same rule
    EXPECT_EQ(occupied(high, BackendKind::CUDA), nHigh);
    EXPECT_EQ(occupied(all, BackendKind::CUDA), nAll);
  }
}

TEST(GradientTF, ZeroGradientOpacityEmptiesEverything) {
  Volume v = generateVolume("menger", vec3l{27, 27, 27});
  double lo, hi;
  ASSERT_TRUE(v.scalarRange(lo, hi));
  TransferFunction tf = TransferFunction::preset("opaque", lo, hi, 256);
  tf.gradientOpacity.assign(64, 0.f);
  Engine e(BackendKind::CPU);
  test::load(e, v, tf, test::builder(BuilderKind::KdTreeCPU));
  Image img;
  e.render(test::orbit(v, 30, 20), 32, 32, img);
  EXPECT_EQ(test::coverage(img), 0.0);
  int64_t occupied = 0;
  for (uint8_t o : e.occupancy().occ) occupied += o != 0;
  EXPECT_EQ(occupied, 0);
  // An edit of the gradient opacity alone re-classifies: now everything is drawn again.
  tf.gradientOpacity.assign(64, 1.f);
  e.setTransferFunction(tf);
  e.render(test::orbit(v, 30, 20), 32, 32, img);
  EXPECT_GT(test::coverage(img), 0.1);
}

TEST(GradientTF, CudaBuildersEqualNaive) {
  SKIP_WITHOUT_CUDA();
  for (const char* shape : {"vessels", "nbody"}) {
    Volume v = generateVolume(shape, vec3l{64, 61, 67});
    v.spacing[1] = 0.7;
    const auto [tf, tf2, go] = gradientCases(v);
    RenderParams rp, shaded;
    shaded.shade = true;
    test::expectCudaBuildersEqualNaive(v, tf2, rp, std::string(shape) + " 2-D");
    test::expectCudaBuildersEqualNaive(v, tf2, shaded, std::string(shape) + " 2-D shaded");
    test::expectCudaBuildersEqualNaive(v, go, rp, std::string(shape) + " gradient opacity");
  }
  const Volume two = secondArrayVolume(64, 58, 61);
  RenderParams rp, shaded;
  shaded.shade = true;
  test::expectCudaBuildersEqualNaive(two, secondArrayTF(0.5f, 1.f), rp, "second array");
  test::expectCudaBuildersEqualNaive(two, secondArrayTF(0.5f, 1.f), shaded, "second array shaded");
}
