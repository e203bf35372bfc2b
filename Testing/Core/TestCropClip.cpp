// Cropping (vtkVolumeMapper's 27 regions) and clipping planes in the shared integrator: planes
// cut samples exactly, every builder stays lossless, and the sample lattice never moves.
#include "TestUtil.h"

#include <gtest/gtest.h>

using namespace spaceskip;

namespace {
const BuilderKind kBuilders[] = {BuilderKind::Naive,  BuilderKind::Grid,   BuilderKind::LBVHCPU,
                                 BuilderKind::KdTreeCPU, BuilderKind::Hybrid, BuilderKind::DistanceGrid};

Image render(const Volume& v, BuilderKind k, const RenderParams& rp, double az = 35, double el = 25,
             bool persp = false) {
  TransferFunction tf = TransferFunction::preset("ramp", 0, 255);
  return test::renderWith(v, tf, test::builder(k), az, el, persp, 64, BackendKind::CPU, rp);
}

Volume scene() {
  Volume v = generateVolume("nbody", vec3l{40, 36, 44});
  v.origin[0] = -7.5;
  v.origin[1] = 120;
  v.origin[2] = 3;
  v.spacing[0] = 0.5;
  v.spacing[1] = 1.0;
  v.spacing[2] = 0.75;
  return v;
}

// Cropping planes at fractions of the box along each axis, in the volume's coordinates.
RenderParams cropped(const Volume& v, int flags, double f0 = 0.3, double f1 = 0.7) {
  RenderParams rp;
  rp.cropping = true;
  rp.croppingFlags = flags;
  vec3i cd = v.cellDims();
  const int n[3] = {cd.x, cd.y, cd.z};
  for (int a = 0; a < 3; ++a) {
    rp.croppingPlanes[2 * a] = v.origin[a] + f0 * n[a] * v.spacing[a];
    rp.croppingPlanes[2 * a + 1] = v.origin[a] + f1 * n[a] * v.spacing[a];
  }
  return rp;
}
}  // namespace

TEST(CropClip, EveryBuilderEqualsNaiveForEveryCroppingPreset) {
  Volume v = scene();
  // VTK's presets: sub-volume, fence, inverted fence, cross, inverted cross.
  for (int flags : {0x0002000, 0x2ebfeba, 0x5140145, 0x0417410, 0x7be8bef}) {
    for (bool persp : {false, true}) {
      RenderParams rp = cropped(v, flags);
      Image naive = render(v, BuilderKind::Naive, rp, 35, 25, persp);
      EXPECT_GT(test::coverage(naive), 0.001) << std::hex << flags;
      for (BuilderKind k : kBuilders) {
        Image img = render(v, k, rp, 35, 25, persp);
        EXPECT_LE(compareImages(naive, img).maxAbs, 1.f / 255.f) << builderName(k) << " flags " << std::hex << flags;
      }
    }
  }
}

TEST(CropClip, CroppingRemovesWhatItShouldAndNothingElse) {
  Volume v = scene();
  Image full = render(v, BuilderKind::Grid, RenderParams{});
  // All 27 regions drawn, or planes beyond the box: the uncropped image, sample for sample.
  EXPECT_EQ(compareImages(full, render(v, BuilderKind::Grid, cropped(v, 0x7ffffff))).maxAbs, 0.f);
  EXPECT_EQ(compareImages(full, render(v, BuilderKind::Grid, cropped(v, 0x2000, -1.0, 2.0))).maxAbs, 0.f);
  // No region drawn: nothing.
  EXPECT_EQ(test::coverage(render(v, BuilderKind::Grid, cropped(v, 0))), 0.0);
  // The sub-volume is a strict part of the image; sub-volume + inverted sub-volume = all regions,
  // so their opacities cannot both be below the full image's (the volume is partly translucent).
  const double sub = test::coverage(render(v, BuilderKind::Grid, cropped(v, 0x2000)));
  const double rest = test::coverage(render(v, BuilderKind::Grid, cropped(v, 0x7ffffff & ~0x2000)));
  EXPECT_GT(sub, 0.0);
  EXPECT_LT(sub, test::coverage(full));
  EXPECT_LT(rest, test::coverage(full) + 1e-9);
  EXPECT_GT(rest, 0.0);
}

TEST(CropClip, ClippingPlanesCutExactlyAndStayLossless) {
  Volume v = scene();
  double b[6];
  v.worldBounds(b);
  const double mid = 0.5 * (b[0] + b[1]);
  // Keep x >= mid: the same region as cropping to the sub-volume [mid, +inf) along x.
  RenderParams clip;
  clip.clipPlanes.push_back({1, 0, 0, -mid});
  RenderParams crop;
  crop.cropping = true;
  crop.croppingFlags = 0x2000;
  const double planes[6] = {mid, 1e9, -1e9, 1e9, -1e9, 1e9};
  std::copy(planes, planes + 6, crop.croppingPlanes);
  for (bool persp : {false, true}) {
    Image byClip = render(v, BuilderKind::Naive, clip, 35, 25, persp);
    Image byCrop = render(v, BuilderKind::Naive, crop, 35, 25, persp);
    EXPECT_GT(test::coverage(byClip), 0.001);
    EXPECT_LT(test::coverage(byClip), test::coverage(render(v, BuilderKind::Naive, RenderParams{}, 35, 25, persp)));
    // Both cut at the same plane: at most the one sample that straddles it differs per ray.
    EXPECT_GT(compareImages(byClip, byCrop).psnr, 40.0);
    for (BuilderKind k : kBuilders)
      EXPECT_LE(compareImages(byClip, render(v, k, clip, 35, 25, persp)).maxAbs, 1.f / 255.f) << builderName(k);
  }
  // Two opposite planes that leave nothing; a plane through the box at an angle, all builders.
  RenderParams none;
  none.clipPlanes = {{1, 0, 0, -mid}, {-1, 0, 0, mid - 1}};
  EXPECT_EQ(test::coverage(render(v, BuilderKind::Grid, none)), 0.0);
  RenderParams oblique;
  oblique.clipPlanes = {{0.6, -0.48, 0.64, -(0.6 * mid - 0.48 * 0.5 * (b[2] + b[3]) + 0.64 * 0.5 * (b[4] + b[5]))}};
  Image naive = render(v, BuilderKind::Naive, oblique);
  for (BuilderKind k : kBuilders)
    EXPECT_LE(compareImages(naive, render(v, k, oblique)).maxAbs, 1.f / 255.f) << builderName(k);
}

TEST(CropClip, BadPlanesAreReportedNotFatal) {
  Volume v = scene();
  RenderParams rp;
  for (int i = 0; i < 8; ++i) rp.clipPlanes.push_back({0, 0, 1, 1e6});  // eight harmless planes
  rp.clipPlanes.push_back({NAN, 0, 1, 0});
  std::vector<std::string> log;
  Engine e(BackendKind::CPU, [&](const std::string& m) { log.push_back(m); });
  e.setVolume(v);
  e.setTransferFunction(TransferFunction::preset("ramp", 0, 255));
  e.setRenderParams(rp);
  double b[6];
  v.worldBounds(b);
  Image img;
  for (int i = 0; i < 2; ++i) e.render(orbitCamera(b, 35, 25, 1, false, 1), 32, 32, img);
  EXPECT_FALSE(hasNonFinite(img));
  EXPECT_GT(test::coverage(img), 0.001);
  ASSERT_EQ(log.size(), 1u);  // "more than 6 planes", once; the NaN plane is beyond the first six
  EXPECT_NE(log[0].find("clipping planes"), std::string::npos) << log[0];
}
