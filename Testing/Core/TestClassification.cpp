// Conservative classification: value ranges include the +1 halo; a TF spike between two voxel
// values is never classified empty; a TF edit re-classifies bricks only.
#include "spaceskip/Classification.h"
#include "spaceskip/render/Integrator.h"
#include "spaceskip/render/Scattering.h"
#include "TestUtil.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cmath>
#include <random>

using namespace spaceskip;

namespace {
Volume twoValueVolume(uint8_t a, uint8_t b, int n = 16) {
  // Left half a, right half b: the cells straddling x = n/2 interpolate between them.
  Volume v;
  v.allocate(vec3l{n, n, n}, VoxelType::UInt8);
  uint8_t* d = v.mutableData();
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) d[x + n * (y + n * z)] = x < n / 2 ? a : b;
  return v;
}
}  // namespace

TEST(Classification, RangeGridIncludesHalo) {
  Volume v = twoValueVolume(0, 200, 16);
  RangeGrid g = computeRangeGrid(v, 4);
  // Cells [4,8) of brick 1 use voxels 4..8; voxel 8 is 200, so the range is [0, 200].
  EXPECT_EQ(g.dims.x, 4);  // 15 cells / 4 -> 4 bricks
  EXPECT_FLOAT_EQ(g.vmin[size_t(g.index(1, 0, 0))], 0.f);
  EXPECT_FLOAT_EQ(g.vmax[size_t(g.index(1, 0, 0))], 200.f);
  EXPECT_FLOAT_EQ(g.vmax[size_t(g.index(0, 0, 0))], 0.f);
  EXPECT_FLOAT_EQ(g.vmin[size_t(g.index(2, 0, 0))], 200.f);
}

TEST(Classification, SpikeBetweenVoxelValuesIsNeverEmpty) {
  // Voxel values 0 and 200 only; the TF is opaque in one entry at 100 and nowhere else.
  // The paper's per-voxel flag would call everything empty; a trilinear sample between the
  // two halves does hit 100, so those bricks must stay occupied.
  Volume v = twoValueVolume(0, 200, 16);
  auto tf = TransferFunction::fromPoints({{0, 0, 0, 0, 0}, {200, 0, 0, 0, 0}}, 0, 200, 201);
  tf.table[100] = vec4f{1, 1, 1, 1};
  OccupancyGrid o = classify(computeRangeGrid(v, 4), tf);
  EXPECT_TRUE(o.at(1, 0, 0));
  EXPECT_FALSE(o.at(0, 0, 0));
  EXPECT_FALSE(o.at(3, 0, 0));
  // And the image agrees: the grid render is not empty and equals the naive render.
  Image naive = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 90, 0);
  Image grid = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0);
  EXPECT_GT(test::coverage(naive), 0.01);
  EXPECT_LE(compareImages(naive, grid).maxAbs, 1.f / 255.f);
}

TEST(Classification, ConservativeAgainstBruteForce) {
  // For random TFs, every brick that contains a sample with opacity > 0 must be occupied.
  Volume v = generateVolume("noise", vec3l{24, 20, 18}, 3);
  double lo, hi;
  ASSERT_TRUE(v.scalarRange(lo, hi));
  RangeGrid g = computeRangeGrid(v, 4);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0, 1);
  const float* d = static_cast<const float*>(v.data);
  ArraySampler<float> s{d, v.dims.x, v.dims.y, v.dims.z};
  for (int trial = 0; trial < 10; ++trial) {
    auto tf = TransferFunction::preset("zero", lo, hi, 256);
    int spike = int(u(rng) * 255);
    tf.table[size_t(spike)].w = 0.5f;
    OccupancyGrid o = classify(g, tf);
    TransferFunctionView view{tf.table.data(), 256, float(lo), float(255.0 / (hi - lo))};
    std::uniform_real_distribution<float> px(0.f, float(v.cellDims().x)), py(0.f, float(v.cellDims().y)),
        pz(0.f, float(v.cellDims().z));
    for (int i = 0; i < 20000; ++i) {
      vec3f p{px(rng), py(rng), pz(rng)};
      if (lookup(view, s.sample(p)).w > 0.f) {
        int bx = std::min(int(p.x) / 4, o.dims.x - 1), by = std::min(int(p.y) / 4, o.dims.y - 1),
            bz = std::min(int(p.z) / 4, o.dims.z - 1);
        ASSERT_TRUE(o.at(bx, by, bz)) << "sample at " << p.x << "," << p.y << "," << p.z;
      }
    }
  }
}

TEST(Classification, NaNVoxelsAreIgnoredAndInfIsClamped) {
  Volume v;
  v.allocate(vec3l{8, 8, 8}, VoxelType::Float32);
  float* d = reinterpret_cast<float*>(v.mutableData());
  for (int i = 0; i < 512; ++i) d[i] = NAN;
  d[0] = INFINITY;
  RangeGrid g = computeRangeGrid(v, 4);
  EXPECT_TRUE(std::isinf(g.vmax[0]));
  EXPECT_GT(g.vmin[size_t(g.index(1, 1, 1))], g.vmax[size_t(g.index(1, 1, 1))]);  // all NaN: empty range
  auto tf = TransferFunction::preset("opaque", 0, 1);
  OccupancyGrid o = classify(g, tf);
  EXPECT_TRUE(o.at(0, 0, 0));
  EXPECT_FALSE(o.at(1, 1, 1));
}

TEST(Classification, OpacityZeroEverywhereAndOne) {
  Volume v = generateVolume("shell", vec3l{32, 32, 32});
  RangeGrid g = computeRangeGrid(v, 8);
  EXPECT_EQ(classify(g, TransferFunction::preset("zero", 0, 255)).occupied, 0);
  EXPECT_EQ(classify(g, TransferFunction::preset("opaque", 0, 255)).occupied, g.size());
}

TEST(Classification, ExactZerosUnderParaViewsDefaultRampAreEmpty) {
  // ParaView's default opacity map is a ramp from (data min, 0) to (data max, 1). A brick whose
  // voxels (with the halo) are all exactly the data minimum can only sample that value, which
  // maps onto table entry 0 exactly: opacity 0, so the brick is empty. Bricks touching a
  // non-zero voxel stay occupied, and every builder still draws the naive image.
  const int n = 48;
  const Volume v = test::makeVolume<uint8_t>(n, n, n, VoxelType::UInt8, [](int x, int y, int z) {
    const double r = std::sqrt(double((x - 20) * (x - 20) + (y - 24) * (y - 24) + (z - 26) * (z - 26)));
    return r < 7 ? uint8_t(255 - r * 30) : uint8_t(0);  // a ball in exact zeros
  });
  const auto tf = TransferFunction::fromPoints({{0, 0.23f, 0.3f, 0.75f, 0.f}, {255, 0.7f, 0.02f, 0.15f, 1.f}}, 0,
                                               255, 1024);
  RangeGrid g = computeRangeGrid(v, 8);
  OccupancyGrid o = classify(g, tf);
  for (int64_t i = 0; i < g.size(); ++i)
    EXPECT_EQ(o.occ[size_t(i)] != 0, g.vmax[size_t(i)] > 0.f) << "brick " << i;
  EXPECT_LT(o.occupancy(), 0.2);
  EXPECT_GT(o.occupied, 0);
  // A value just above zero is not skipped: the table's entry 1 is > 0 and blends in.
  EXPECT_GT(OpacityRangeMax(tf).query(0.0, 1e-3), 0.f);
  EXPECT_EQ(OpacityRangeMax(tf).query(0.0, 0.0), 0.f);
  const Image naive = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 30, 20);
  EXPECT_GT(test::coverage(naive), 0.005);
  for (BuilderKind k : {BuilderKind::Grid, BuilderKind::LBVHCPU, BuilderKind::KdTreeCPU, BuilderKind::Hybrid,
                        BuilderKind::DistanceGrid}) {
    const Image img = test::renderWith(v, tf, test::builder(k), 30, 20);
    EXPECT_LE(compareImages(naive, img).maxAbs, 1.f / 255.f) << "builder " << int(k);
  }
}

TEST(Engine, ColourEditUpdatesTableOnlyOpacityEditReclassifies) {
  Volume v = generateVolume("shell", vec3l{32, 32, 32});
  Engine e(BackendKind::CPU);
  e.setLogger([](const std::string&) {});
  e.setVolume(v);
  auto tf = TransferFunction::preset("ramp", 0, 255);
  e.setTransferFunction(tf);
  BuildParams p;
  p.builder = BuilderKind::Grid;
  e.setBuildParams(p);
  double b[6];
  v.worldBounds(b);
  Image img;
  Camera cam = orbitCamera(b, 20, 10, 1, false, 1);
  e.render(cam, 32, 32, img);
  Counters c0 = e.counters();
  EXPECT_EQ(c0.rangeGrids, 1);
  EXPECT_EQ(c0.classifications, 1);
  EXPECT_EQ(c0.builds, 1);
  // Colour-only edit: no classification, no rebuild.
  auto tf2 = tf;
  for (auto& t : tf2.table) t.x = 1.f - t.x;
  e.setTransferFunction(tf2);
  e.render(cam, 32, 32, img);
  EXPECT_EQ(e.counters().classifications, 1);
  EXPECT_EQ(e.counters().builds, 1);
  EXPECT_EQ(e.counters().colorUpdates, 1);
  // Opacity edit that keeps the occupied set: re-classify, no rebuild.
  auto tf3 = tf2;
  for (auto& t : tf3.table) t.w *= 0.5f;
  e.setTransferFunction(tf3);
  e.render(cam, 32, 32, img);
  EXPECT_EQ(e.counters().classifications, 2);
  EXPECT_EQ(e.counters().builds, 1);
  // Opacity edit that empties bricks: re-classify and rebuild.
  e.setTransferFunction(TransferFunction::preset("zero", 0, 255));
  e.render(cam, 32, 32, img);
  EXPECT_EQ(e.counters().classifications, 3);
  EXPECT_EQ(e.counters().builds, 2);
  EXPECT_EQ(e.counters().rangeGrids, 1);  // value ranges are computed once per volume
  EXPECT_EQ(test::coverage(img), 0.0);
}

TEST(Engine, ACallerThatKnowsWhatChangedSavesTheCompares) {
  // setTransferFunction(tf, colorMayDiffer, opacityMayDiffer): the VTK mapper knows which of its
  // functions was edited; the engine then compares only that part of the table, with the same
  // outcome (counters) as the full compare.
  Volume v = generateVolume("shell", vec3l{32, 32, 32});
  Engine e(BackendKind::CPU);
  e.setLogger([](const std::string&) {});
  e.setVolume(v);
  const auto tf = TransferFunction::preset("ramp", 0, 255);
  e.setTransferFunction(tf);
  e.setBuildParams(test::builder(BuilderKind::Grid));
  double b[6];
  v.worldBounds(b);
  Image img;
  const Camera cam = orbitCamera(b, 20, 10, 1, false, 1);
  e.render(cam, 32, 32, img);
  Counters c = e.counters();
  EXPECT_EQ(c.colorCompares + c.opacityCompares, 0) << "the first table is new as a whole";
  // A colour edit, said to be one: no opacity compare, a colour update only.
  auto colour = tf;
  for (auto& t : colour.table) t.x = 1.f - t.x;
  e.setTransferFunction(colour, true, false);
  e.render(cam, 32, 32, img);
  EXPECT_EQ(e.counters().opacityCompares, c.opacityCompares);
  EXPECT_EQ(e.counters().colorCompares, c.colorCompares + 1);
  EXPECT_EQ(e.counters().colorUpdates, c.colorUpdates + 1);
  EXPECT_EQ(e.counters().classifications, c.classifications);
  c = e.counters();
  // An opacity edit, said to be one: one opacity compare, no colour compare, re-classified.
  auto opacity = colour;
  for (auto& t : opacity.table) t.w *= 0.5f;
  e.setTransferFunction(opacity, false, true);
  e.render(cam, 32, 32, img);
  EXPECT_EQ(e.counters().opacityCompares, c.opacityCompares + 1);
  EXPECT_EQ(e.counters().colorCompares, c.colorCompares);
  EXPECT_EQ(e.counters().classifications, c.classifications + 1);
  EXPECT_EQ(e.counters().colorUpdates, c.colorUpdates);
  c = e.counters();
  // Nothing may differ: nothing compared, nothing redone.
  e.setTransferFunction(opacity, false, false);
  e.render(cam, 32, 32, img);
  EXPECT_EQ(e.counters().opacityCompares + e.counters().colorCompares, c.opacityCompares + c.colorCompares);
  EXPECT_EQ(e.counters().classifications, c.classifications);
  EXPECT_EQ(e.counters().colorUpdates, c.colorUpdates);
  // The default (both may differ): an unchanged opacity is compared, then the colour.
  c = e.counters();
  e.setTransferFunction(colour);
  e.render(cam, 32, 32, img);
  EXPECT_EQ(e.counters().opacityCompares, c.opacityCompares + 1);
  EXPECT_EQ(e.counters().classifications, c.classifications + 1) << "the opacity differs";
  EXPECT_EQ(e.counters().colorCompares, c.colorCompares) << "the whole table is set again";
  // The image is the one of an engine given the same table from the start.
  Engine fresh(BackendKind::CPU);
  fresh.setLogger([](const std::string&) {});
  test::load(fresh, v, colour, test::builder(BuilderKind::Grid));
  Image ref;
  fresh.render(cam, 32, 32, ref);
  EXPECT_EQ(compareImages(ref, img).maxAbs, 0.f);
}

TEST(SubMasks, AVoxelSetsThePartsWhoseSamplesCanReadIt) {
  // Brick 8: parts of 2 cells, part k of an axis reads voxels [2k, 2k + 2]. Voxel 4 lies in
  // the spans of parts 1 and 2 on each axis: 8 bits; voxel 0 in part 0's only.
  Volume v;
  v.allocate(vec3l{17, 17, 17}, VoxelType::UInt8);
  uint8_t* d = v.mutableData();
  std::fill(d, d + 17 * 17 * 17, uint8_t(0));
  d[4 + 17 * (4 + 17 * 4)] = 200;
  auto tf = TransferFunction::fromPoints({{0, 0, 0, 0, 0}, {100, 0, 0, 0, 0}, {200, 1, 1, 1, 1}}, 0, 200, 201);
  OccupancyGrid o = classify(computeRangeGrid(v, 8), tf);
  ASSERT_EQ(o.dims.x, 2);
  const SubMasks sm = computeSubMasks(v, o, tf);
  const std::vector<uint64_t>& m = sm.mask;
  ASSERT_EQ(m.size(), size_t(o.size()));
  ASSERT_EQ(sm.state.size(), size_t(o.size()));
  EXPECT_EQ(sm.state[0], kBrickParts) << "8 of 64 parts set: walked part by part";
  EXPECT_EQ(sm.state[1], kBrickEmpty);
  uint64_t want = 0;
  for (int z = 1; z <= 2; ++z)
    for (int y = 1; y <= 2; ++y)
      for (int x = 1; x <= 2; ++x) want |= uint64_t(1) << (x + 4 * (y + 4 * z));
  EXPECT_EQ(m[size_t(o.index(0, 0, 0))], want);
  for (int64_t i = 1; i < o.size(); ++i) EXPECT_EQ(m[size_t(i)], 0u) << "brick " << i;
  d[4 + 17 * (4 + 17 * 4)] = 0;
  d[0] = 200;
  o = classify(computeRangeGrid(v, 8), tf);
  EXPECT_EQ(computeSubMasks(v, o, tf).mask[0], uint64_t(1));
  // Bricks without four parts of >= 2 cells have no masks.
  EXPECT_TRUE(computeSubMasks(v, classify(computeRangeGrid(v, 4), tf), tf).mask.empty());
  // A brick with more set parts than Tuning::subMaskMaxSet is marched whole.
  std::fill(d, d + 17 * 17 * 17, uint8_t(200));
  o = classify(computeRangeGrid(v, 8), tf);
  const SubMasks full = computeSubMasks(v, o, tf);
  EXPECT_EQ(full.mask[0], ~uint64_t(0));
  EXPECT_EQ(full.state[0], kBrickWhole);
  // DistanceGrid's byte: occupied bricks take the parts mark from their state, or when empty now.
  EXPECT_EQ(markedDistance(0, kBrickParts), kBrickPartsBit);
  EXPECT_EQ(markedDistance(0, kBrickWhole), 0);
  EXPECT_EQ(markedDistance(0, kBrickEmpty), kBrickPartsBit);
  EXPECT_EQ(markedDistance(kBrickPartsBit, kBrickWhole), 0);
  EXPECT_EQ(markedDistance(5, kBrickEmpty), 5);
}

TEST(SubMasks, ThePartWalkYieldsExactlyTheSetParts) {
  // One brick, random masks (sparse and dense) and random rays, a third of them parallel to a
  // face: a point of the ray strictly inside a part lies in a yielded run exactly when the part
  // is set (the walk clipped to the set parts' box, setPartBox). Brick 8: the cell arithmetic
  // multiplies by 1 / 8; brick 12: it divides.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  int64_t checked = 0, inside = 0;
  for (int brick : {8, 12}) {
    const float B = float(brick), S = B / float(kSubPerAxis);
    for (int trial = 0; trial < 3000; ++trial) {
      uint64_t mask = 0;
      if (trial % 5 == 0) {
        mask = uint64_t(rng()) << 32 | uint64_t(rng());
      } else {
        for (int i = 1 + trial % 6; i > 0; --i) mask |= uint64_t(1) << (rng() % 64);
      }
      const uint8_t state = kBrickParts;
      GridView g{&state, vec3i{1, 1, 1}, brick};
      g.sub = &mask;
      const vec3f target{u(rng) * B, u(rng) * B, u(rng) * B};
      Ray r{vec3f{(u(rng) * 3.f - 1.f) * B, (u(rng) * 3.f - 1.f) * B, (u(rng) * 3.f - 1.f) * B}, vec3f{0, 0, 0}};
      if (trial % 3 == 0) {  // parallel to one or two faces
        r.org.x = target.x;
        if (trial % 2 == 0) r.org.z = target.z;
      }
      r.dir = normalize(target - r.org);
      if (!(length(r.dir) > 0.f)) continue;
      const vec3f inv = safeInverse(r.dir);
      float t0, t1;
      intersectBox(r, inv, vec3f{0, 0, 0}, vec3f{B, B, B}, t0, t1);
      t0 = std::max(t0, 0.f);
      if (!(t0 < t1)) continue;
      GridPartsIter it;
      it.init(g, r, inv, t0, t1);
      std::vector<std::array<float, 2>> runs;
      float a, b;
      for (Step st; (st = it.next(AllBricksActive{}, a, b)) != Step::Done;) {
        if (st == Step::Interval) runs.push_back({a, b});
      }
      for (int i = 0; i < 256; ++i) {
        const float t = t0 + (t1 - t0) * (float(i) + 0.5f) / 256.f;
        const vec3f p = r.org + r.dir * t;
        int k[3];
        bool nearFace = false;
        for (int ax = 0; ax < 3; ++ax) {
          const float q = p[ax] / S;
          nearFace = nearFace || std::fabs(q - std::round(q)) < 1e-3f;
          k[ax] = std::clamp(int(std::floor(q)), 0, kSubPerAxis - 1);
        }
        if (nearFace) continue;
        const bool set = (mask >> (k[0] + kSubPerAxis * (k[1] + kSubPerAxis * k[2]))) & 1u;
        const bool inRun = std::any_of(runs.begin(), runs.end(), [&](const std::array<float, 2>& run) {
          return run[0] <= t && t < run[1];
        });
        ASSERT_EQ(set, inRun) << "brick " << brick << ", trial " << trial << ", t " << t;
        ++checked;
        inside += set;
      }
    }
  }
  EXPECT_GT(checked, 500000);
  EXPECT_GT(inside, checked / 20);
}

TEST(SubMasks, FewerSamplesAndTheSameImage) {
  // Walking the set parts of an occupied brick skips only samples of opacity 0: the image is
  // the same bit for bit and equals Naive's; sparse data takes far fewer samples.
  Volume v = generateVolume("nbody", vec3l{96, 96, 96}, 3);
  auto tf = TransferFunction::preset("ramp", 0, 255);
  const std::array<std::array<double, 2>, 2> cams = {{{10, 10}, {73, -35}}};
  for (const std::array<double, 2>& cam : cams) {
    const Camera c = test::orbit(v, cam[0], cam[1], cam[0] > 50);
    int64_t naiveSamples = 0;
    const Image naive = test::renderCounting(v, tf, BuilderKind::Naive, c, 96, naiveSamples);
    for (BuilderKind k : {BuilderKind::Grid, BuilderKind::DistanceGrid}) {
      int64_t with = 0, without = 0, byDefault = 0;
      Tuning noMasks, masks;
      noMasks.subMasks = false;
      masks.cpuSubMasks = true;  // the oneTBB backend marches whole bricks unless told
      const Image whole = test::renderCounting(v, tf, k, c, 96, without, RenderParams{}, noMasks);
      const Image parts = test::renderCounting(v, tf, k, c, 96, with, RenderParams{}, masks);
      test::renderCounting(v, tf, k, c, 96, byDefault);
      EXPECT_EQ(byDefault, without) << builderName(k) << ": the CPU's default marches whole bricks";
      EXPECT_EQ(compareImages(whole, parts).maxAbs, 0.f) << builderName(k);
      EXPECT_LE(compareImages(naive, parts).maxAbs, 1.f / 255.f) << builderName(k);
      EXPECT_GT(with, 0) << builderName(k);
      EXPECT_LT(with * 3, without * 2) << builderName(k) << ": " << with << " samples with masks, " << without
                                       << " without";
    }
  }
}
