// Cropping (vtkVolumeMapper's 27 regions) and clipping planes in the shared integrator: planes
// cut samples exactly, every builder stays lossless, and the sample lattice never moves.
#include "TestUtil.h"

#include "spaceskip/Backend.h"
#include "spaceskip/CropClip.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

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
  return test::offsetNbody();
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

// ---- Classification: bricks no drawn sample can reach count as empty (issue 12) ----

namespace {
// 64^3 cells, unit spacing at the origin: 8^3 bricks of 8 cells; every brick occupied by the TF.
Volume cube() { return generateVolume("nbody", vec3l{65, 65, 65}); }

int64_t occupiedWith(const Volume& v, const TransferFunction& tf, const RenderParams& rp) {
  Engine e(BackendKind::CPU);
  test::load(e, v, tf, test::builder(BuilderKind::Grid));
  e.setRenderParams(rp);
  return e.occupancy().occupied;
}

// The integrator's rule for a point: kept by every clipping plane, in a drawn cropping region.
bool drawnPoint(const CropClip& cc, float x, float y, float z) {
  for (int i = 0; i < cc.numClipPlanes; ++i) {
    const float* c = cc.clip[i];
    if (c[0] * x + c[1] * y + c[2] * z + c[3] < 0.f) return false;
  }
  if (!cc.cropping) return true;
  auto slab = [](float p, float lo, float hi) { return p < lo ? 0 : (p < hi ? 1 : 2); };
  const int region = slab(x, cc.crop[0], cc.crop[1]) + 3 * slab(y, cc.crop[2], cc.crop[3]) +
                     9 * slab(z, cc.crop[4], cc.crop[5]);
  return (cc.cropFlags >> region) & 1;
}
}  // namespace

TEST(CropClip, ClassificationDropsWhatCroppingAndClippingRemove) {
  const Volume v = cube();
  const TransferFunction opaque = TransferFunction::preset("opaque", 0, 255);
  ASSERT_EQ(occupiedWith(v, opaque, RenderParams{}), 512);
  // Sub-volume x in [0, 30]: bricks 0..3 along x (brick 4 starts at 32), half of them.
  RenderParams crop;
  crop.cropping = true;
  crop.croppingFlags = 0x2000;
  const double planes[6] = {-1e9, 30, -1e9, 1e9, -1e9, 1e9};
  std::copy(planes, planes + 6, crop.croppingPlanes);
  EXPECT_EQ(occupiedWith(v, opaque, crop), 256);
  // The same half by a clipping plane keeping x <= 30.
  RenderParams clip;
  clip.clipPlanes.push_back({-1, 0, 0, 30});
  EXPECT_EQ(occupiedWith(v, opaque, clip), 256);
  // Both: x <= 30 and y >= 33 (bricks 4..7 along y, brick 3 ends at 32): a quarter.
  RenderParams both = crop;
  both.clipPlanes.push_back({0, 1, 0, -33});
  EXPECT_EQ(occupiedWith(v, opaque, both), 128);
  // Planes exactly on brick faces keep the neighbouring layer (the box is widened, conservative).
  RenderParams face = crop;
  face.croppingPlanes[1] = 32;
  EXPECT_EQ(occupiedWith(v, opaque, face), 320);
  // Nothing drawn, everything drawn, cropping planes beyond the box, cropping off.
  RenderParams none = crop;
  none.croppingFlags = 0;
  EXPECT_EQ(occupiedWith(v, opaque, none), 0);
  RenderParams all = crop;
  all.croppingFlags = 0x7ffffff;
  EXPECT_EQ(occupiedWith(v, opaque, all), 512);
  RenderParams off = crop;
  off.cropping = false;
  EXPECT_EQ(occupiedWith(v, opaque, off), 512);
  // The inverted sub-volume (the other 26 regions): x >= 30 is drawn, bricks 3..7 along x.
  RenderParams inverted = crop;
  inverted.croppingFlags = 0x7ffffff & ~0x2000;
  EXPECT_EQ(occupiedWith(v, opaque, inverted), 320);
  // A NaN cropping plane never empties a brick the integrator could draw.
  RenderParams nan = crop;
  nan.croppingPlanes[1] = NAN;
  EXPECT_EQ(occupiedWith(v, opaque, nan), 512);
  // The TF still decides inside the drawn part: with the ramp, the crop keeps a subset.
  const TransferFunction ramp = TransferFunction::preset("ramp", 0, 255);
  const int64_t rampAll = occupiedWith(v, ramp, RenderParams{}), rampCrop = occupiedWith(v, ramp, crop);
  EXPECT_GT(rampCrop, 0);
  EXPECT_LT(rampCrop, rampAll);
}

TEST(CropClip, BrickMayBeDrawnIsConservative) {
  // Random planes and flags; every point of a brick the test calls undrawable is undrawn.
  std::mt19937 rng(12);
  std::uniform_real_distribution<float> u(-4.f, 36.f), n(-1.f, 1.f), unit(0.f, 1.f);
  int empty = 0;
  for (int trial = 0; trial < 200; ++trial) {
    CropClip cc;
    cc.cropping = trial % 3 != 0;
    cc.cropFlags = int(rng() & 0x7ffffff);
    for (int a = 0; a < 3; ++a) {
      float p0 = u(rng), p1 = u(rng);
      if (trial % 5 == 0) p0 = std::round(p0 / 4) * 4, p1 = std::round(p1 / 4) * 4;  // on brick faces
      cc.crop[2 * a] = std::min(p0, p1);
      cc.crop[2 * a + 1] = std::max(p0, p1);
    }
    cc.numClipPlanes = int(rng() % 3);
    for (int i = 0; i < cc.numClipPlanes; ++i) {
      const vec3f q{u(rng), u(rng), u(rng)};
      float* c = cc.clip[i];
      c[0] = n(rng), c[1] = n(rng), c[2] = n(rng);
      if (trial % 4 == 0) c[0] = 1, c[1] = c[2] = 0;  // axis-aligned
      c[3] = -(c[0] * q.x + c[1] * q.y + c[2] * q.z);
    }
    for (int bz = 0; bz < 8; ++bz)
      for (int by = 0; by < 8; ++by)
        for (int bx = 0; bx < 8; ++bx) {
          const box3i box = brickCellBox(vec3i{bx, by, bz}, 4, vec3i{30, 31, 32});
          if (box.lo.x >= box.hi.x || box.lo.y >= box.hi.y || box.lo.z >= box.hi.z) continue;
          if (brickMayBeDrawn(box, cc)) continue;
          ++empty;
          for (int s = 0; s < 64; ++s) {
            // Points in the closed box, corners and faces included.
            auto at = [&](int lo, int hi) {
              const float r = unit(rng);
              return s < 8 ? float((s & 1) ? hi : lo) : float(lo) + r * float(hi - lo);
            };
            const float x = at(box.lo.x, box.hi.x), y = at(box.lo.y, box.hi.y), z = at(box.lo.z, box.hi.z);
            ASSERT_FALSE(drawnPoint(cc, x, y, z)) << "trial " << trial << " brick " << bx << "," << by << "," << bz;
          }
        }
  }
  EXPECT_GT(empty, 1000);  // the test does empty bricks, not only keep them
}

TEST(CropClip, CroppingAndClippingTogetherStayLosslessOnPlanesAtBrickFaces) {
  Volume v = scene();
  // Planes exactly on brick faces (index 8, 16, 24 along each axis) and a clipping plane on one.
  RenderParams rp;
  rp.cropping = true;
  rp.croppingFlags = 0x7ffffff & ~0x2000 & ~0x1;  // the inverted sub-volume without region 0
  for (int a = 0; a < 3; ++a) {
    rp.croppingPlanes[2 * a] = v.origin[a] + 8 * v.spacing[a];
    rp.croppingPlanes[2 * a + 1] = v.origin[a] + 24 * v.spacing[a];
  }
  rp.clipPlanes.push_back({0, 0, -1, v.origin[2] + 32 * v.spacing[2]});  // keep z <= index 32
  for (bool persp : {false, true})
    for (double az : {35.0, 90.0}) {
      Image naive = render(v, BuilderKind::Naive, rp, az, 25, persp);
      EXPECT_GT(test::coverage(naive), 0.001);
      for (BuilderKind k : kBuilders)
        EXPECT_LE(compareImages(naive, render(v, k, rp, az, 25, persp)).maxAbs, 1.f / 255.f)
            << builderName(k) << " az " << az << " persp " << persp;
    }
}

TEST(CropClip, CudaEveryBuilderEqualsNaiveWithCroppingAndClipping) {
  SKIP_WITHOUT_CUDA();
  Volume v = scene();
  RenderParams rp = cropped(v, 0x5140145);  // inverted fence
  rp.clipPlanes.push_back({0.6, -0.48, 0.64, -(0.6 * v.origin[0] - 0.48 * (v.origin[1] + 18) + 0.64 * (v.origin[2] + 16))});
  const TransferFunction tf = TransferFunction::preset("ramp", 0, 255);
  for (bool persp : {false, true}) {
    Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 35, 25, persp, 64, BackendKind::CPU, rp);
    ASSERT_GT(test::coverage(ref), 0.001);
    for (BuilderKind k : {BuilderKind::Naive, BuilderKind::Grid, BuilderKind::DistanceGrid, BuilderKind::LBVH,
                          BuilderKind::KdTreeGPUFast, BuilderKind::Hybrid}) {
      Image img = test::renderWith(v, tf, test::builder(k), 35, 25, persp, 64, BackendKind::CUDA, rp);
      EXPECT_LE(compareImages(ref, img).maxAbs, 2.f / 255.f) << builderName(k) << " persp " << persp;
    }
  }
  // The device classification drops what the CPU one drops, brick for brick.
  for (const RenderParams& p : {rp, cropped(v, 0x2000), RenderParams{}}) {
    Engine cpu(BackendKind::CPU), gpu(BackendKind::CUDA);
    test::load(cpu, v, tf, test::builder(BuilderKind::Grid));
    test::load(gpu, v, tf, test::builder(BuilderKind::Grid));
    cpu.setRenderParams(p);
    gpu.setRenderParams(p);
    EXPECT_EQ(cpu.occupancy().occ, gpu.occupancy().occ);
  }
}

TEST(CropClip, PlaneChangesReclassifyCameraChangesDoNot) {
  Volume v = scene();
  Engine e(BackendKind::CPU);
  test::load(e, v, TransferFunction::preset("ramp", 0, 255), test::builder(BuilderKind::KdTreeCPU));
  Image img;
  e.render(test::orbit(v, 35, 25), 32, 32, img);
  const Counters c0 = e.counters();
  EXPECT_EQ(c0.classifications, 1);
  EXPECT_EQ(c0.builds, 1);
  const int64_t full = e.occupancy().occupied;
  // Camera only, and the same render parameters set again: nothing is redone.
  e.render(test::orbit(v, 80, -10, true), 32, 32, img);
  e.setRenderParams(RenderParams{});
  e.render(test::orbit(v, 10, 40), 32, 32, img);
  EXPECT_EQ(e.counters().classifications, 1);
  EXPECT_EQ(e.counters().builds, 1);
  EXPECT_EQ(e.counters().colorUpdates, 0);
  // Moving cropping planes while cropping is off changes nothing either.
  RenderParams rp;
  rp.croppingPlanes[1] = 5;
  e.setRenderParams(rp);
  e.render(test::orbit(v, 10, 40), 32, 32, img);
  EXPECT_EQ(e.counters().classifications, 1);
  // Cropping on: re-classified and rebuilt (the occupancy shrank).
  rp = cropped(v, 0x2000);
  e.setRenderParams(rp);
  e.render(test::orbit(v, 10, 40), 32, 32, img);
  EXPECT_EQ(e.counters().classifications, 2);
  EXPECT_EQ(e.counters().builds, 2);
  EXPECT_LT(e.occupancy().occupied, full);
  // A camera change after it: nothing.
  e.render(test::orbit(v, 60, 20), 32, 32, img);
  EXPECT_EQ(e.counters().classifications, 2);
  EXPECT_EQ(e.counters().builds, 2);
  // A clipping plane that removes nothing: re-classified, not rebuilt (the occupancy is the same).
  rp.clipPlanes.push_back({1, 0, 0, 1e6});
  e.setRenderParams(rp);
  e.render(test::orbit(v, 60, 20), 32, 32, img);
  EXPECT_EQ(e.counters().classifications, 3);
  EXPECT_EQ(e.counters().builds, 2);
  // Cropping off again: back to the full occupancy.
  e.setRenderParams(RenderParams{});
  e.render(test::orbit(v, 60, 20), 32, 32, img);
  EXPECT_EQ(e.counters().classifications, 4);
  EXPECT_EQ(e.counters().builds, 3);
  EXPECT_EQ(e.occupancy().occupied, full);
  EXPECT_EQ(e.counters().colorUpdates, 0);
  EXPECT_EQ(e.counters().rangeGrids, 1);
}
