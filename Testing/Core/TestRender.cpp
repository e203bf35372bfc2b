// Lossless skipping: the grid image equals the naive image on several volumes and cameras.
#include "TestUtil.h"

#include <gtest/gtest.h>

using namespace spaceskip;

namespace {
struct Case {
  const char* shape;
  int n;
  const char* tf;
};

void expectSame(const Volume& v, const TransferFunction& tf, BuilderKind k, double az, double el, bool persp) {
  Image naive = test::renderWith(v, tf, test::builder(BuilderKind::Naive), az, el, persp);
  Image other = test::renderWith(v, tf, test::builder(k), az, el, persp);
  ImageDiff d = compareImages(naive, other);
  EXPECT_LE(d.maxAbs, 1.f / 255.f) << builderName(k) << " az " << az << " el " << el << " persp " << persp
                                  << " psnr " << d.psnr;
  EXPECT_FALSE(hasNonFinite(other));
}
}  // namespace

class GridEqualsNaive : public ::testing::TestWithParam<Case> {};

TEST_P(GridEqualsNaive, SeveralCameras) {
  const Case& c = GetParam();
  Volume v = generateVolume(c.shape, vec3l{c.n, c.n + 3, c.n - 5}, 2);
  double lo, hi;
  ASSERT_TRUE(v.scalarRange(lo, hi));
  auto tf = TransferFunction::preset(c.tf, lo, hi);
  Image naive = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 30, 20);
  ASSERT_GT(test::coverage(naive), 0.001) << "test scene must not be empty";
  const double cams[][2] = {{0, 0}, {30, 20}, {90, 0}, {135, -40}, {200, 75}, {0, 90}};
  for (auto& cam : cams) {
    expectSame(v, tf, BuilderKind::Grid, cam[0], cam[1], false);
    expectSame(v, tf, BuilderKind::Grid, cam[0], cam[1], true);
    expectSame(v, tf, BuilderKind::DistanceGrid, cam[0], cam[1], false);
    expectSame(v, tf, BuilderKind::DistanceGrid, cam[0], cam[1], true);
  }
}

INSTANTIATE_TEST_SUITE_P(Volumes, GridEqualsNaive,
                         ::testing::Values(Case{"menger", 54, "ramp"}, Case{"nbody", 64, "ramp"},
                                           Case{"shell", 48, "band"}, Case{"noise", 40, "band"},
                                           Case{"vessels", 64, "coolwarm"}, Case{"shell", 40, "spike"}));

TEST(Render, GridTakesFarFewerSamplesOnSparseData) {
  // Not a timing assertion (CI machines vary): skipping must take fewer samples for the same
  // image; the speed ratio itself is printed by `spaceskip bench`.
  Volume v = generateVolume("nbody", vec3l{256, 256, 256});
  auto tf = TransferFunction::preset("ramp", 0, 255);
  const Camera cam = test::orbit(v, 10, 10);
  int64_t samples[2];
  Image img[2] = {test::renderCounting(v, tf, BuilderKind::Naive, cam, 64, samples[0]),
                  test::renderCounting(v, tf, BuilderKind::Grid, cam, 64, samples[1])};
  EXPECT_GT(samples[0], 0);
  EXPECT_LT(samples[1] * 2, samples[0]) << "naive " << samples[0] << " grid " << samples[1];
  EXPECT_LE(compareImages(img[0], img[1]).maxAbs, 1.f / 255.f);
}

TEST(Render, EarlyRayTerminationStaysCloseAndJitterIsDeterministic) {
  Volume v = generateVolume("menger", vec3l{54, 54, 54});
  auto tf = TransferFunction::preset("opaque", 0, 255);
  RenderParams ert;
  ert.ertThreshold = 0.99;
  Image full = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 20, 20);
  Image early = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 20, 20, false, 96, BackendKind::CPU, ert);
  EXPECT_LE(compareImages(full, early).maxAbs, 0.011f);
  RenderParams j;
  j.jitter = true;
  j.jitterSeed = 5;
  Image j1 = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 20, 20, false, 96, BackendKind::CPU, j);
  Image j2 = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 20, 20, false, 96, BackendKind::CPU, j);
  EXPECT_LE(compareImages(j1, j2).maxAbs, 1.f / 255.f);  // jitter keeps positions global too
}

TEST(Render, DepthBufferClipsTheVolume) {
  Volume v = generateVolume("shell", vec3l{32, 32, 32});
  auto tf = TransferFunction::preset("ramp", 0, 255);
  Engine e(BackendKind::CPU);
  e.setVolume(v);
  e.setTransferFunction(tf);
  Camera cam = test::orbit(v, 0, 0);
  Image all, none, half;
  e.render(cam, 32, 32, all);
  std::vector<float> depth(32 * 32, 0.f);  // geometry at the near plane hides everything
  e.render(cam, 32, 32, none, depth.data());
  EXPECT_EQ(test::coverage(none), 0.0);
  std::fill(depth.begin(), depth.end(), 0.5f);  // geometry through the middle hides the back
  e.render(cam, 32, 32, half, depth.data());
  EXPECT_GT(test::coverage(half), 0.0);
  EXPECT_LT(test::coverage(half), test::coverage(all));
}
