// Sparse residency (BrickPool.h): pool layout, the pool sampler against in-core sampling, the
// residency bookkeeping (slots, LRU eviction, overflow), the rule each blend mode needs, and
// end to end on the CPU backend under a budget below the volume: the image equals the in-core
// image for every builder and mode, and only the needed bricks are ever resident.
#include "TestUtil.h"

#include <gtest/gtest.h>

#include "spaceskip/Backend.h"
#include "spaceskip/BrickPool.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>

using namespace spaceskip;

namespace {

/// Blobs in an empty 160^3 uint8 volume: 5^3 pool bricks of 32 cells, a few of them occupied.
Volume blobs() {
  const double c[4][4] = {{30, 40, 50, 9}, {110, 60, 40, 12}, {70, 120, 120, 10}, {140, 140, 30, 6}};
  return test::makeVolume<uint8_t>(160, 160, 160, VoxelType::UInt8, [&](int i, int j, int k) {
    double v = 0;
    for (const auto& b : c) {
      const double d2 = (i - b[0]) * (i - b[0]) + (j - b[1]) * (j - b[1]) + (k - b[2]) * (k - b[2]);
      v = std::max(v, 250.0 * std::exp(-d2 / (2 * b[3] * b[3])));
    }
    return v < 4 ? 0.0 : v;
  });
}

/// Transparent up to `from`, then a ramp to opaque red-yellow.
TransferFunction rampFrom(double from) {
  return TransferFunction::fromPoints({{0, 0, 0, 0, 0}, {from, 0.9f, 0.3f, 0.1f, 0}, {255, 1, 1, 0.2f, 0.8f}}, 0, 255,
                                      256);
}

}  // namespace

TEST(BrickPool, LayoutRoundsToClassificationBricks) {
  const PoolLayout a = makePoolLayout(vec3l{160, 100, 1}, 8, 32);
  EXPECT_EQ(a.brick, 32);
  EXPECT_EQ(a.bdims.x, 5);  // 159 cells
  EXPECT_EQ(a.bdims.y, 4);  // 99 cells
  EXPECT_EQ(a.bdims.z, 1);  // one voxel: one cell
  EXPECT_EQ(a.slotVoxels(), 33 * 33 * 33);
  EXPECT_EQ(makePoolLayout(vec3l{64, 64, 64}, 12, 32).brick, 36);  // nearest multiple of 12
  EXPECT_EQ(makePoolLayout(vec3l{64, 64, 64}, 64, 32).brick, 64);  // at least the classification brick
}

TEST(BrickPool, ResidentSamplesAreBitIdenticalToInCoreOnesAndOthersAreNaN) {
  for (VoxelType type : {VoxelType::UInt16, VoxelType::Float32}) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.f, 1000.f);
    Volume v = type == VoxelType::UInt16
                   ? test::makeVolume<uint16_t>(37, 29, 41, type, [&](int, int, int) { return std::floor(u(rng)); })
                   : test::makeVolume<float>(37, 29, 41, type, [&](int, int, int) { return u(rng); });
    const PoolLayout L = makePoolLayout(v.dims, 4, 8);
    BrickResidency res;
    res.reset(L.count(), L.count());
    std::vector<uint8_t> needed(size_t(L.count()), 1);
    needed[3] = 0;  // one brick left out
    const BrickResidency::Plan plan = res.update(needed.data());
    ASSERT_TRUE(plan.fits);
    EXPECT_EQ(int64_t(plan.bricks.size()), L.count() - 1);
    dispatchVoxelType(type, [&](auto t) {
      using T = decltype(t);
      std::vector<T> pool(size_t(L.count() * L.slotVoxels()));
      for (size_t i = 0; i < plan.bricks.size(); ++i)
        gatherBrick<T>(v, L, plan.bricks[i], pool.data() + int64_t(plan.slots[i]) * L.slotVoxels());
      const PoolSampler<T> ps{pool.data(), res.table().data(), v.dims.x, v.dims.y, v.dims.z, L.brick, L.bdims.x,
                              L.bdims.y, NAN};
      const ArraySampler<T> as{static_cast<const T*>(v.data), v.dims.x, v.dims.y, v.dims.z};
      std::uniform_real_distribution<float> px(-2.f, 43.f);
      int nan = 0;
      for (int s = 0; s < 20000; ++s) {
        vec3f p{px(rng), px(rng), px(rng)};
        if (s % 7 == 0) p.x = float(int(p.x));  // on voxel planes, brick faces included
        const float a = as.sample(p), b = ps.sample(p);
        int64_t x0, x1, y0, y1, z0, z1;
        float f;
        ArraySampler<T>::axis(p.x, v.dims.x, x0, x1, f);
        ArraySampler<T>::axis(p.y, v.dims.y, y0, y1, f);
        ArraySampler<T>::axis(p.z, v.dims.z, z0, z1, f);
        const int64_t brick = x0 / L.brick + L.bdims.x * (y0 / L.brick + L.bdims.y * (z0 / L.brick));
        if (brick == 3) {
          EXPECT_TRUE(std::isnan(b));
          ++nan;
        } else {
          ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << "at " << p.x << "," << p.y << "," << p.z;
        }
      }
      EXPECT_GT(nan, 0);
    });
  }
}

TEST(BrickPool, ResidencyEvictsTheLeastRecentlyNeededAndRefusesOverflow) {
  BrickResidency r;
  r.reset(6, 3);
  auto set = [](std::initializer_list<int> on) {
    std::vector<uint8_t> n(6, 0);
    for (int i : on) n[size_t(i)] = 1;
    return n;
  };
  auto a = set({0, 1});
  BrickResidency::Plan p = r.update(a.data());
  EXPECT_EQ(p.bricks, (std::vector<int64_t>{0, 1}));
  EXPECT_EQ(p.slots, (std::vector<int32_t>{0, 1}));
  auto b = set({2});
  p = r.update(b.data());  // a free slot: nothing evicted, 0 and 1 stay
  EXPECT_EQ(p.bricks, (std::vector<int64_t>{2}));
  EXPECT_EQ(p.evicted, 0);
  EXPECT_EQ(r.resident(), 3);
  auto c = set({1, 3});
  p = r.update(c.data());  // 1 stays; 3 evicts brick 0 (needed longest ago; 2 was needed later)
  EXPECT_EQ(p.bricks, (std::vector<int64_t>{3}));
  EXPECT_EQ(p.evicted, 1);
  EXPECT_EQ(r.table()[0], -1);
  EXPECT_GE(r.table()[2], 0);
  EXPECT_EQ(r.table()[3], 0);  // brick 0's slot
  auto again = set({1, 3});
  p = r.update(again.data());  // nothing to do
  EXPECT_TRUE(p.bricks.empty());
  auto over = set({0, 1, 2, 4});
  const std::vector<int32_t> before = r.table();
  p = r.update(over.data());
  EXPECT_FALSE(p.fits);
  EXPECT_EQ(p.needed, 4);
  EXPECT_EQ(r.table(), before);  // nothing changed
  // Every slot holds at most one brick and the table agrees.
  std::vector<int> seen(3, 0);
  for (int32_t s : r.table())
    if (s >= 0) ++seen[size_t(s)];
  for (int s : seen) EXPECT_LE(s, 1);
}

TEST(BrickPool, PoolsGrowWithWhatViewsNeedWithinTheBudget) {
  BrickResidency::Demand d{10, 10, 0};
  EXPECT_EQ(grownCapacity(d, 0, 100), 12);   // the needed plus a quarter
  EXPECT_EQ(grownCapacity(d, 0, 11), 11);    // within the budget
  d = BrickResidency::Demand{10, 3, 5};
  EXPECT_EQ(grownCapacity(d, 12, 100), 12);  // the missing fit the free slots
  d = BrickResidency::Demand{10, 8, 2};
  EXPECT_EQ(grownCapacity(d, 12, 100), 24);  // twice as large: evicted bricks stay cached
  EXPECT_EQ(grownCapacity(d, 12, 12), 12);   // at the budget: evict instead
  BrickResidency r;
  r.reset(8, 2);
  std::vector<uint8_t> all(8, 1);
  EXPECT_FALSE(r.update(all.data()).fits);
  r.grow(8);
  const BrickResidency::Plan p = r.update(all.data());
  EXPECT_TRUE(p.fits);
  EXPECT_EQ(p.slots.back(), 7);
}

TEST(BrickPool, NeedRulesFollowTheBlendMode) {
  const TransferFunction tf = rampFrom(100);  // entries 0..100 transparent
  const PoolNeedRule mip = poolNeedFor(BlendMode::MaximumIntensity, false, tf, 0, 0);
  EXPECT_EQ(mip.need, PoolNeed::Above);
  EXPECT_LE(mip.lo, 100.f);
  EXPECT_GE(mip.lo, 97.f);
  EXPECT_FALSE(classBrickNeeded(mip, 0, 0.f, 90.f));  // wholly transparent: cannot decide a visible max
  EXPECT_TRUE(classBrickNeeded(mip, 0, 0.f, 120.f));
  const PoolNeedRule minip = poolNeedFor(BlendMode::MinimumIntensity, false, tf, 0, 0);
  EXPECT_EQ(minip.need, PoolNeed::Below);
  EXPECT_EQ(minip.hi, INFINITY);  // the last entry is visible
  const PoolNeedRule comp = poolNeedFor(BlendMode::Composite, true, tf, 0, 0);
  EXPECT_EQ(comp.need, PoolNeed::Occupancy);
  EXPECT_EQ(comp.reach, 1);
  EXPECT_TRUE(classBrickNeeded(comp, 1, 0.f, 0.f));
  EXPECT_FALSE(classBrickNeeded(comp, 0, 0.f, 255.f));
  EXPECT_EQ(poolNeedFor(BlendMode::Isosurface, false, tf, 0, 0).need, PoolNeed::All);
  const PoolNeedRule avg = poolNeedFor(BlendMode::AverageIntensity, false, tf, 50, 60);
  EXPECT_TRUE(classBrickNeeded(avg, 0, 40.f, 55.f));
  EXPECT_FALSE(classBrickNeeded(avg, 0, 61.f, 90.f));
  EXPECT_FALSE(classBrickNeeded(avg, 0, INFINITY, -INFINITY));  // NaN only
}

TEST(BrickPool, ShadingReachesOneCellIntoTheNeighbourBrick) {
  // 2 x 1 x 1 pool bricks of 16 cells over 4 x 2 x 2 classification bricks of 8: only the
  // classification brick at the face of pool brick 0 towards pool brick 1 is needed.
  const PoolLayout L = makePoolLayout(vec3l{33, 17, 17}, 8, 16);
  ASSERT_EQ(L.bdims.x, 2);
  const vec3i cd{4, 2, 2};
  std::vector<uint8_t> occ(16, 0);
  std::vector<float> lo(16, 0.f), hi(16, 0.f);
  occ[1] = 1;  // classification brick x = 1 (cells 8..15): pool brick 0, touching pool brick 1
  PoolNeedRule r;
  EXPECT_TRUE(poolBrickNeeded(0, L, cd, 8, occ.data(), lo.data(), hi.data(), r));
  EXPECT_FALSE(poolBrickNeeded(1, L, cd, 8, occ.data(), lo.data(), hi.data(), r));
  r.reach = 1;  // shaded: the gradient at cell 15 reads cell 16, in pool brick 1
  EXPECT_TRUE(poolBrickNeeded(1, L, cd, 8, occ.data(), lo.data(), hi.data(), r));
  occ[1] = 0;
  occ[0] = 1;  // cells 0..7: one cell of reach does not reach pool brick 1
  EXPECT_FALSE(poolBrickNeeded(1, L, cd, 8, occ.data(), lo.data(), hi.data(), r));
}

namespace {

struct Case {
  const char* name;
  RenderParams rp;
};

std::vector<Case> modes() {
  auto blend = [](BlendMode b) {
    RenderParams r;
    r.blend = b;
    return r;
  };
  RenderParams shaded;
  shaded.shade = true;
  shaded.specular = 0.5;
  RenderParams average = blend(BlendMode::AverageIntensity);
  average.averageRange[0] = 120;
  average.averageRange[1] = 255;
  RenderParams slice = blend(BlendMode::Slice);
  const double origin[3] = {110, 60, 40}, normal[3] = {0.3, 0.2, 0.93};
  std::copy(origin, origin + 3, slice.sliceOrigin);
  std::copy(normal, normal + 3, slice.sliceNormal);
  slice.shade = true;
  return {{"composite", RenderParams{}}, {"composite-shaded", shaded},
          {"mip", blend(BlendMode::MaximumIntensity)}, {"average", average},
          {"additive", blend(BlendMode::Additive)}, {"slice-shaded", slice}};
}

Image renderBudget(const Volume& v, const TransferFunction& tf, BuilderKind b, const RenderParams& rp, int64_t budget,
                   ResidencyStats* stats = nullptr, int poolBrick = 32) {
  Engine e(BackendKind::CPU);
  e.setMemoryBudget(budget, poolBrick);
  test::load(e, v, tf, test::builder(b));
  e.setRenderParams(rp);
  Image img;
  e.render(test::orbit(v, 30, 20, true), 80, 80, img);
  if (stats) *stats = e.frameStats().residency;
  return img;
}

}  // namespace

TEST(BrickPool, CpuSparseImageEqualsInCoreForEveryBuilderAndMode) {
  const Volume v = blobs();
  const TransferFunction tf = rampFrom(60);
  const int64_t budget = int64_t(v.byteSize()) * 3 / 5;  // 60% of the volume
  for (const Case& c : modes()) {
    const Image ref = renderBudget(v, tf, BuilderKind::Naive, c.rp, 0);
    ASSERT_GT(test::coverage(ref), 0.0) << c.name;
    for (BuilderKind b : {BuilderKind::Naive, BuilderKind::Grid, BuilderKind::DistanceGrid, BuilderKind::LBVHCPU,
                          BuilderKind::KdTreeCPU, BuilderKind::Hybrid, BuilderKind::Auto}) {
      ResidencyStats s;
      // Pool bricks of 32 cells (5^3 of them), and of 16 (the default) for Naive and Grid.
      const Image img = renderBudget(v, tf, b, c.rp, budget, &s);
      if (b == BuilderKind::Naive || b == BuilderKind::Grid) {
        ResidencyStats s16;
        const Image i16 = renderBudget(v, tf, b, c.rp, budget, &s16, 16);
        EXPECT_EQ(s16.poolBrick, 16);
        EXPECT_LT(s16.needed, s16.bricks) << c.name;
        EXPECT_EQ(compareImages(ref, i16).maxAbs, 0.0) << c.name << " " << builderName(b) << ", pool bricks of 16";
      }
      EXPECT_TRUE(s.sparse) << c.name;
      EXPECT_FALSE(s.overflow) << c.name << " needed " << s.needed << " of " << s.bricks << ", slots " << s.capacity;
      EXPECT_GT(s.resident, 0) << c.name;
      EXPECT_LT(s.needed, s.bricks) << c.name << ": some pool bricks must stay out";
      const ImageDiff d = compareImages(ref, img);
      EXPECT_EQ(d.maxAbs, 0.0) << c.name << " " << builderName(b) << ": sparse differs from in core";
    }
  }
}

TEST(BrickPool, CpuSparseMipSkipsAsInCore) {
  // Non-resident samples read MIP's bound (poolFill), so the running maximum lets the value-range
  // traversal skip the empty bricks as in core (NaN would leave it marching every brick).
  const Volume v = blobs();
  RenderParams rp;
  rp.blend = BlendMode::MaximumIntensity;
  rp.countSamples = true;
  int64_t samples[2] = {0, 0};
  Image img[2];
  for (int sparse = 0; sparse < 2; ++sparse) {
    Engine e(BackendKind::CPU);
    test::load(e, v, rampFrom(60), test::builder(BuilderKind::Grid));
    if (sparse) e.setMemoryBudget(int64_t(v.byteSize()) / 2, 16);
    e.setRenderParams(rp);
    e.render(test::orbit(v, 30, 20, true), 80, 80, img[sparse]);
    samples[sparse] = e.frameStats().samples;
    EXPECT_EQ(e.frameStats().residency.sparse, sparse == 1);
  }
  EXPECT_EQ(compareImages(img[0], img[1]).maxAbs, 0.0);
  EXPECT_LE(double(samples[1]), 1.05 * double(samples[0])) << "in core " << samples[0] << ", sparse " << samples[1];
}

TEST(BrickPool, CpuTfEditsUploadOnlyNewBricksAndEvictUnderATightBudget) {
  const Volume v = blobs();
  Engine e(BackendKind::CPU);
  const PoolLayout L = makePoolLayout(v.dims, 8, 32);
  const int64_t slot = L.slotVoxels();
  test::load(e, v, rampFrom(200), test::builder(BuilderKind::Grid));
  e.setMemoryBudget(slot * 32, 32);  // 32 slots of 125 pool bricks
  const Camera cam = test::orbit(v, 10, 30, true);
  Image img;
  e.render(cam, 64, 64, img);
  ResidencyStats s = e.frameStats().residency;
  ASSERT_TRUE(s.sparse);
  ASSERT_EQ(s.maxCapacity, 32);
  EXPECT_LT(s.capacity, 32);  // the pool takes what the view needs (plus a quarter), not the budget
  EXPECT_GE(s.capacity, s.needed);
  const int64_t first = s.uploaded;
  EXPECT_EQ(first, s.needed);
  EXPECT_GT(first, 0);
  e.render(cam, 64, 64, img);  // same TF: nothing to upload
  EXPECT_EQ(e.frameStats().residency.uploaded, 0);
  // A TF that shows more: only the newly needed bricks are uploaded, evicting the old ones
  // only when the slots run out; the image equals the in-core one.
  for (double from : {120.0, 40.0, 200.0}) {
    e.setTransferFunction(rampFrom(from));
    e.render(cam, 64, 64, img);
    s = e.frameStats().residency;
    EXPECT_FALSE(s.overflow) << from;
    EXPECT_LE(s.resident, s.capacity);
    EXPECT_GE(s.resident, s.needed);
    Engine ref(BackendKind::CPU);
    test::load(ref, v, rampFrom(from), test::builder(BuilderKind::Grid));
    Image in;
    ref.render(cam, 64, 64, in);
    EXPECT_EQ(compareImages(in, img).maxAbs, 0.0) << from;
  }
  // Back to the first TF: its bricks were kept while slots allowed.
  EXPECT_LE(e.frameStats().residency.uploaded, first);
}

TEST(BrickPool, CpuClippingToOneHalfThenTheOtherEvictsAndStaysExact) {
  // Two clipping planes that keep complementary halves: each half's bricks fit 20 slots, both
  // do not, so the second half evicts the first one's (least recently needed) bricks.
  const Volume v = blobs();
  const PoolLayout L = makePoolLayout(v.dims, 8, 32);
  Engine e(BackendKind::CPU);
  test::load(e, v, rampFrom(40), test::builder(BuilderKind::KdTreeCPU));
  e.setMemoryBudget(L.slotVoxels() * 20, 32);
  const Camera cam = test::orbit(v, 40, 10, true);
  int64_t evicted = 0;
  for (int round = 0; round < 2; ++round)
    for (double side : {1.0, -1.0}) {
      RenderParams rp;
      rp.clipPlanes = {{side, 0, 0, -side * 80}};
      e.setRenderParams(rp);
      Image img;
      e.render(cam, 64, 64, img);
      const ResidencyStats s = e.frameStats().residency;
      ASSERT_FALSE(s.overflow) << "needed " << s.needed;
      EXPECT_LE(s.resident, 20);
      evicted += s.evicted;
      Engine ref(BackendKind::CPU);
      test::load(ref, v, rampFrom(40), test::builder(BuilderKind::KdTreeCPU));
      ref.setRenderParams(rp);
      Image in;
      ref.render(cam, 64, 64, in);
      ASSERT_GT(test::coverage(in), 0.0);
      EXPECT_EQ(compareImages(in, img).maxAbs, 0.0) << "side " << side << " round " << round;
    }
  EXPECT_GT(evicted, 0);
}

TEST(BrickPool, CpuOverflowIsSaidAndRendersTheWholeVolume) {
  const Volume v = blobs();
  Engine e(BackendKind::CPU);
  std::vector<std::string> said;
  test::load(e, v, rampFrom(10), test::builder(BuilderKind::Grid));
  e.setLogger([&](const std::string& m) { said.push_back(m); });
  const PoolLayout L = makePoolLayout(v.dims, 8, 32);
  e.setMemoryBudget(L.slotVoxels() * 2, 32);  // two slots: every blob needs more
  Image img;
  e.render(test::orbit(v, 10, 30), 64, 64, img);
  EXPECT_TRUE(e.frameStats().residency.overflow);
  ASSERT_FALSE(said.empty());
  EXPECT_NE(said.back().find("exceed the memory budget"), std::string::npos) << said.back();
  const Image in = test::renderWith(v, rampFrom(10), test::builder(BuilderKind::Grid), 10, 30, false, 64);
  EXPECT_EQ(compareImages(in, img).maxAbs, 0.0);
  // Isosurface needs every brick with data: no pool of 40% holds it.
  RenderParams iso;
  iso.blend = BlendMode::Isosurface;
  iso.isoValues = {100};
  ResidencyStats s;
  const Image isoImg = renderBudget(v, rampFrom(10), BuilderKind::Grid, iso, int64_t(v.byteSize()) * 2 / 5, &s);
  EXPECT_TRUE(s.sparse);
  EXPECT_TRUE(s.overflow);
  EXPECT_EQ(compareImages(renderBudget(v, rampFrom(10), BuilderKind::Grid, iso, 0), isoImg).maxAbs, 0.0);
}

TEST(BrickPool, CpuShadedStepAtAPoolBrickFaceReadsTheNeighbourBrick) {
  // Opaque for x < 32, empty beyond: the shaded samples just before x = 32 take their gradient
  // from voxels of the empty pool brick next door, which must therefore be resident.
  const Volume v = test::makeVolume<uint8_t>(97, 33, 33, VoxelType::UInt8, [](int i, int, int) { return i < 32 ? 200 : 0; });
  RenderParams rp;
  rp.shade = true;
  rp.specular = 0.6;
  const TransferFunction tf = rampFrom(50);
  for (double az : {60.0, 120.0}) {
    Engine in(BackendKind::CPU);
    test::load(in, v, tf, test::builder(BuilderKind::Grid));
    in.setRenderParams(rp);
    Engine sp(BackendKind::CPU);
    test::load(sp, v, tf, test::builder(BuilderKind::Grid));
    sp.setRenderParams(rp);
    sp.setMemoryBudget(int64_t(v.byteSize()) * 3 / 4, 32);
    Image a, b;
    const Camera cam = test::orbit(v, az, 20, true);
    in.render(cam, 80, 80, a);
    sp.render(cam, 80, 80, b);
    const ResidencyStats s = sp.frameStats().residency;
    ASSERT_TRUE(s.sparse);
    EXPECT_EQ(s.needed, 2);  // the opaque brick and its neighbour; the third stays out
    EXPECT_EQ(compareImages(a, b).maxAbs, 0.0) << "azimuth " << az;
  }
}

TEST(BrickPool, CudaSparseImageEqualsInCoreForEveryBuilderAndMode) {
  SKIP_WITHOUT_CUDA();
  const Volume v = blobs();
  const TransferFunction tf = rampFrom(60);
  const int64_t budget = int64_t(v.byteSize()) * 3 / 5;
  for (const Case& c : modes()) {
    Engine in(BackendKind::CUDA);
    test::load(in, v, tf, test::builder(BuilderKind::Naive));
    in.setMemoryBudget(INT64_MAX);
    in.setRenderParams(c.rp);
    Image ref;
    const Camera cam = test::orbit(v, 30, 20, true);
    in.render(cam, 80, 80, ref);
    ASSERT_EQ(in.frameStats().backend, "cuda");
    ASSERT_FALSE(in.frameStats().residency.sparse);
    for (BuilderKind b : {BuilderKind::Naive, BuilderKind::Grid, BuilderKind::DistanceGrid, BuilderKind::LBVH,
                          BuilderKind::KdTreeGPUFast, BuilderKind::KdTreeCPU, BuilderKind::Hybrid}) {
      for (int poolBrick : {16, 32}) {
        Engine e(BackendKind::CUDA);
        test::load(e, v, tf, test::builder(b));
        e.setMemoryBudget(budget, poolBrick);
        e.setRenderParams(c.rp);
        Image img;
        e.render(cam, 80, 80, img);
        const ResidencyStats s = e.frameStats().residency;
        ASSERT_EQ(e.frameStats().backend, "cuda") << c.name << " " << builderName(b);
        EXPECT_TRUE(s.sparse);
        EXPECT_LT(s.needed, s.bricks);
        // Bit-identical samples; the kernels that read them are separate instantiations, whose
        // float contractions may differ in the last bit (shaded frames: 6e-8 measured on the H100).
        EXPECT_LE(compareImages(ref, img).maxAbs, 1e-6) << c.name << " " << builderName(b) << " pool " << poolBrick;
        // CUDA's sparse image equals the CPU's in-core image as closely as the in-core ones agree.
        if (b == BuilderKind::Grid && poolBrick == 16) {
          Engine cpu(BackendKind::CPU);
          test::load(cpu, v, tf, test::builder(BuilderKind::Grid));
          cpu.setRenderParams(c.rp);
          Image ci;
          cpu.render(cam, 80, 80, ci);
          EXPECT_LE(compareImages(ci, img).maxAbs * 255.0, 1.0) << c.name;
        }
      }
    }
  }
}

TEST(BrickPool, CudaOverflowFallsBackToTheCpuWithOneMessage) {
  SKIP_WITHOUT_CUDA();
  const Volume v = blobs();
  std::vector<std::string> said;
  Engine e(BackendKind::CUDA);
  test::load(e, v, rampFrom(10), test::builder(BuilderKind::Grid));
  e.setLogger([&](const std::string& m) { said.push_back(m); });
  e.setMemoryBudget(makePoolLayout(v.dims, 8, 16).slotVoxels() * 3, 16);
  Image img;
  e.render(test::orbit(v, 10, 30), 64, 64, img);
  EXPECT_EQ(e.frameStats().backend, "cpu");
  ASSERT_EQ(said.size(), 1u);
  EXPECT_NE(said[0].find("exceed the memory budget"), std::string::npos) << said[0];
  const Image in = test::renderWith(v, rampFrom(10), test::builder(BuilderKind::Grid), 10, 30, false, 64);
  EXPECT_EQ(compareImages(in, img).maxAbs, 0.0);
}

TEST(BrickPool, CudaVolumeAboveTheDeviceStaysOnItSparse) {
  // The default budget follows the device's memory (here capped by
  // spaceskip::testing::setDeviceMemoryLimit, which fails allocations as a real out-of-memory does): a volume above it is kept sparse on
  // the device instead of falling back to the CPU.
  SKIP_WITHOUT_CUDA();
  const Volume v = blobs();
  const TransferFunction tf = rampFrom(60);
  const int64_t bricks = int64_t(20) * 20 * 20;
  const int64_t limit = (int64_t(1) << 30) + bricks * 32 + int64_t(v.byteSize()) * 3 / 5;
  spaceskip::testing::setDeviceMemoryLimit(limit);
  std::vector<std::string> said;
  Image img;
  ResidencyStats s;
  std::string backend;
  {
    Engine e(BackendKind::CUDA);
    test::load(e, v, tf, test::builder(BuilderKind::Grid));
    e.setLogger([&](const std::string& m) { said.push_back(m); });
    e.render(test::orbit(v, 30, 20, true), 80, 80, img);
    s = e.frameStats().residency;
    backend = e.frameStats().backend;
  }
  spaceskip::testing::setDeviceMemoryLimit(-1);
  EXPECT_EQ(backend, "cuda");
  EXPECT_TRUE(s.sparse);
  EXPECT_LT(s.budgetBytes, int64_t(v.byteSize()));
  EXPECT_TRUE(said.empty()) << said.front();
  const Image in = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 30, 20, true, 80);
  EXPECT_LE(compareImages(in, img).maxAbs * 255.0, 1.0);
}
