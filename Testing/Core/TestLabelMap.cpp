// Label maps (issue 37): no invented colour, every builder equals Naive, a label edit reads no
// voxel, and the blended sampling against each label rendered as its own binary volume.
#include "TestUtil.h"

#include "spaceskip/LabelMap.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <set>
#include <tuple>

using namespace spaceskip;
using namespace spaceskip::test;

namespace {

struct Blob {
  double x, y, z, r;
  int label;
};

/// A uint8 label map of `n`^3 voxels: background 0, the blobs painted in order (a later one
/// overwrites an earlier one where they overlap, so touching blobs share borders).
Volume blobLabels(int n, const std::vector<Blob>& blobs) {
  return makeVolume<uint8_t>(n, n, n, VoxelType::UInt8, [&](int i, int j, int k) {
    int l = 0;
    for (const Blob& b : blobs) {
      const double dx = i - b.x, dy = j - b.y, dz = k - b.z;
      if (dx * dx + dy * dy + dz * dz <= b.r * b.r) l = b.label;
    }
    return l;
  });
}

/// Touching blobs whose ids are far apart (1 next to 5, 2 next to 9): interpolating ids would
/// draw the labels in between at their borders.
std::vector<Blob> touchingBlobs() {
  return {{14, 14, 14, 8, 1}, {24, 15, 15, 7, 5}, {16, 25, 18, 7, 9}, {26, 26, 26, 6, 2}, {10, 28, 28, 5, 3}};
}

LabelTable tableFor(const std::vector<int>& ids, float opacity) {
  LabelTable t;
  for (size_t i = 0; i < ids.size(); ++i) {
    Label l;
    l.id = ids[i];
    // Distinct colours (no two share a channel triple).
    l.r = float((i * 37 + 11) % 64) / 63.f;
    l.g = float((i * 23 + 40) % 64) / 63.f;
    l.b = float((i * 53 + 5) % 64) / 63.f;
    l.opacity = opacity;
    t.labels.push_back(l);
  }
  return t;
}

Image renderLabels(const Volume& v, const LabelTable& t, LabelSampling s, BuildParams p, double az, double el,
                   bool shade = false, int size = 64, Engine* engine = nullptr) {
  Engine local(BackendKind::CPU);
  Engine& e = engine ? *engine : local;
  e.setLogger([](const std::string&) {});
  e.setVolume(v);
  e.setBuildParams(p);
  e.setLabelTable(t);
  RenderParams rp;
  rp.labelMap = true;
  rp.labelSampling = s;
  rp.shade = shade;
  e.setRenderParams(rp);
  Image img;
  e.render(orbit(v, az, el), size, size, img);
  EXPECT_TRUE(e.labelMapActive());
  return img;
}

/// Pixels whose colour is neither the background nor one label's colour (opaque labels, unshaded:
/// the first drawn sample decides the pixel).
int64_t unexplained(const Image& img, const LabelTable& t) {
  int64_t bad = 0;
  for (const vec4f& p : img.rgba) {
    if (p.w == 0.f && p.x == 0.f && p.y == 0.f && p.z == 0.f) continue;
    bool ok = false;
    for (const Label& l : t.labels)
      ok = ok || (std::fabs(p.x - l.r) < 1e-6f && std::fabs(p.y - l.g) < 1e-6f && std::fabs(p.z - l.b) < 1e-6f &&
                  std::fabs(p.w - 1.f) < 1e-6f);
    bad += ok ? 0 : 1;
  }
  return bad;
}

}  // namespace

TEST(LabelMap, LabelSetsHoldEveryVoxelSamplesRead) {
  const Volume v = blobLabels(32, touchingBlobs());
  const LabelSets s = computeLabelSets(v, 8);
  EXPECT_EQ(s.lo, 0);
  EXPECT_EQ(s.hi, 9);
  const uint8_t* d = static_cast<const uint8_t*>(v.data);
  for (int bz = 0; bz < s.dims.z; ++bz)
    for (int by = 0; by < s.dims.y; ++by)
      for (int bx = 0; bx < s.dims.x; ++bx) {
        const int64_t i = bx + int64_t(s.dims.x) * (by + int64_t(s.dims.y) * bz);
        std::set<int> want, got;
        for (int z = bz * 8; z <= std::min(bz * 8 + 8, 31); ++z)
          for (int y = by * 8; y <= std::min(by * 8 + 8, 31); ++y)
            for (int x = bx * 8; x <= std::min(bx * 8 + 8, 31); ++x) want.insert(d[x + 32 * (y + 32 * z)]);
        for (int64_t k = s.offset[size_t(i)]; k < s.offset[size_t(i) + 1]; ++k) got.insert(s.labels[size_t(k)] + s.lo);
        EXPECT_EQ(want, got) << "brick " << bx << "," << by << "," << bz;
      }
}

// (a) Opaque labels, unshaded: every pixel is the background or exactly one label's colour, in
// both samplings; the same map drawn as an ordinary volume through a transfer function with the
// labels' colours at their ids invents colours at the borders (the check can fail).
TEST(LabelMap, NoInventedColour) {
  const Volume v = blobLabels(36, touchingBlobs());
  const LabelTable t = tableFor({1, 2, 3, 5, 9}, 1.f);
  for (LabelSampling s : {LabelSampling::Nearest, LabelSampling::Blend})
    for (auto [az, el] : {std::pair{30.0, 20.0}, std::pair{-60.0, 45.0}, std::pair{0.0, 0.0}}) {
      const Image img = renderLabels(v, t, s, builder(BuilderKind::Grid), az, el);
      EXPECT_GT(coverage(img), 0.1);
      EXPECT_EQ(unexplained(img, t), 0) << "sampling " << int(s) << " az " << az << " el " << el;
    }
  std::vector<TFPoint> pts{{0, 0, 0, 0, 0}};
  for (const Label& l : t.labels) pts.push_back({double(l.id), l.r, l.g, l.b, 1.f});
  const TransferFunction tf = TransferFunction::fromPoints(pts, 0, 9, 10);
  const Image ordinary = renderWith(v, tf, builder(BuilderKind::Grid), 30, 20, false, 64);
  EXPECT_GT(unexplained(ordinary, t), 20);
}

// (b) Every CPU builder draws Naive's image, shaded and translucent, with some labels hidden.
TEST(LabelMap, EveryBuilderEqualsNaive) {
  const Volume v = blobLabels(40, touchingBlobs());
  LabelTable t = tableFor({1, 2, 3, 5, 9}, 0.4f);
  t.labels[1].visible = false;   // id 2
  t.labels[3].opacity = 0.f;     // id 5
  for (LabelSampling s : {LabelSampling::Nearest, LabelSampling::Blend}) {
    const Image ref = renderLabels(v, t, s, builder(BuilderKind::Naive), 30, 20, true);
    ASSERT_GT(coverage(ref), 0.05);
    std::vector<BuildParams> builders = skippingBuilders(true);
    builders.push_back(builder(BuilderKind::Auto));
    for (const BuildParams& p : builders) {
      Engine e(BackendKind::CPU);
      const Image img = renderLabels(v, t, s, p, 30, 20, true, 64, &e);
      EXPECT_LE(compareImages(ref, img).maxAbs, 1e-5f) << builderName(p.builder) << " brick " << p.brick;
      EXPECT_LT(e.occupancy().occupancy(), 1.0) << "hidden labels leave bricks empty";
    }
  }
}

// CUDA against the CPU (skipped without a device). Skipping is lossless on the device: every
// builder of the CUDA backend (its GPU builders among them) equals CUDA's Naive (<= 1/255) on both
// samplings, shaded or not; and CUDA's Naive equals the CPU's (<= 1/255; before the label
// indicator became nested lerps, the shaded images differed by up to 8.6/255 in 40 pixels: the
// normals of a label's inside were rounding noise, rounded differently by each). A label hidden on the CUDA
// engine (the label sets' classification on the device) reads no voxel and equals a fresh CUDA
// engine with the new table.
TEST(LabelMap, CudaEqualsCpuForEveryBuilderAndEdit) {
  std::string why;
  if (!cudaAvailable(&why)) GTEST_SKIP() << why;
  const Volume v = blobLabels(40, touchingBlobs());
  LabelTable t = tableFor({1, 2, 3, 5, 9}, 0.4f);
  t.labels[1].visible = false;  // id 2
  t.labels[3].opacity = 0.f;    // id 5
  const float kTol = 1.f / 255.f;
  auto cudaLabels = [&](const LabelTable& table, LabelSampling s, BuilderKind k, bool shade, Engine* e = nullptr) {
    Engine local(BackendKind::CUDA);
    Engine& eng = e ? *e : local;
    EXPECT_EQ(eng.backendKind(), BackendKind::CUDA);
    return renderLabels(v, table, s, builder(k), 30, 20, shade, 64, &eng);
  };
  for (bool shade : {false, true}) {
    for (LabelSampling s : {LabelSampling::Nearest, LabelSampling::Blend}) {
      const Image cpu = renderLabels(v, t, s, builder(BuilderKind::Naive), 30, 20, shade);
      const Image ref = cudaLabels(t, s, BuilderKind::Naive, shade);
      ASSERT_GT(coverage(ref), 0.05);
      const ImageDiff d = compareImages(cpu, ref);
      const double drawn = coverage(ref) * 64 * 64;
      std::cout << "labels CUDA vs CPU, sampling " << int(s) << (shade ? " shaded" : " unshaded") << ": "
                << d.differing << " of " << drawn << " drawn pixels differ, max " << d.maxAbs * 255 << "/255, "
                << d.psnr << " dB\n";
      EXPECT_LE(d.maxAbs, kTol) << "sampling " << int(s) << " shade " << shade;
      for (BuilderKind k : {BuilderKind::Grid, BuilderKind::DistanceGrid, BuilderKind::LBVH, BuilderKind::KdTreeGPU,
                            BuilderKind::KdTreeGPUFast, BuilderKind::Hybrid, BuilderKind::Auto}) {
        const Image img = cudaLabels(t, s, k, shade);
        EXPECT_LE(compareImages(ref, img).maxAbs, kTol) << builderName(k) << " sampling " << int(s) << " shade "
                                                        << shade;
      }
    }
  }
  Engine e(BackendKind::CUDA);
  cudaLabels(t, LabelSampling::Blend, BuilderKind::KdTreeGPUFast, true, &e);
  const Counters c0 = e.counters();
  LabelTable t1 = t;
  t1.labels[0].visible = false;  // label 1, the largest blob
  e.setLabelTable(t1);
  Image img;
  e.render(orbit(v, 30, 20), 64, 64, img);
  EXPECT_EQ(e.counters().voxelPasses, c0.voxelPasses);
  EXPECT_EQ(e.counters().classifications, c0.classifications + 1);
  const Image fresh = cudaLabels(t1, LabelSampling::Blend, BuilderKind::Naive, true);
  EXPECT_LE(compareImages(fresh, img).maxAbs, kTol);
}

// (c) Toggling a label and changing an opacity: no voxel pass; a rebuild only where the
// occupancy changed; the image equals a fresh engine's with the new table.
TEST(LabelMap, EditsReadNoVoxels) {
  const Volume v = blobLabels(40, touchingBlobs());
  const LabelTable t0 = tableFor({1, 2, 3, 5, 9}, 0.5f);
  Engine e(BackendKind::CPU);
  renderLabels(v, t0, LabelSampling::Blend, builder(BuilderKind::KdTreeCPU), 30, 20, true, 48, &e);
  const Counters c0 = e.counters();
  EXPECT_EQ(c0.labelSets, 1);
  const int64_t occ0 = e.occupancy().occupied;

  LabelTable t1 = t0;
  t1.labels[0].visible = false;  // label 1, the largest blob: bricks empty
  Image img;
  e.setLabelTable(t1);
  e.render(orbit(v, 30, 20), 48, 48, img);
  const Counters c1 = e.counters();
  EXPECT_EQ(c1.voxelPasses, c0.voxelPasses);
  EXPECT_EQ(c1.labelSets, c0.labelSets);
  EXPECT_EQ(c1.rangeGrids, c0.rangeGrids);
  EXPECT_EQ(c1.classifications, c0.classifications + 1);
  EXPECT_EQ(c1.builds, c0.builds + 1);
  EXPECT_LT(e.occupancy().occupied, occ0);
  const Image fresh1 = renderLabels(v, t1, LabelSampling::Blend, builder(BuilderKind::KdTreeCPU), 30, 20, true, 48);
  EXPECT_EQ(compareImages(img, fresh1).maxAbs, 0.f);

  LabelTable t2 = t1;
  t2.labels[2].opacity = 0.9f;  // an opacity edit: the table alone
  e.setLabelTable(t2);
  e.render(orbit(v, 30, 20), 48, 48, img);
  const Counters c2 = e.counters();
  EXPECT_EQ(c2.voxelPasses, c1.voxelPasses);
  EXPECT_EQ(c2.classifications, c1.classifications);
  EXPECT_EQ(c2.builds, c1.builds);
  const Image fresh2 = renderLabels(v, t2, LabelSampling::Blend, builder(BuilderKind::KdTreeCPU), 30, 20, true, 48);
  EXPECT_EQ(compareImages(img, fresh2).maxAbs, 0.f);

  LabelTable t3 = t2;  // a visible label the volume lacks (id 4): classified, nothing rebuilt
  Label absent;
  absent.id = 4;
  t3.labels.push_back(absent);
  e.setLabelTable(t3);
  e.render(orbit(v, 30, 20), 48, 48, img);
  const Counters c3 = e.counters();
  EXPECT_EQ(c3.voxelPasses, c2.voxelPasses);
  EXPECT_EQ(c3.classifications, c2.classifications + 1);
  EXPECT_EQ(c3.builds, c2.builds);
  EXPECT_EQ(compareImages(img, fresh2).maxAbs, 0.f);

  // Back to the ordinary volume and to the label map: the caller's TF comes back.
  RenderParams rp = e.renderParams();
  rp.labelMap = false;
  e.setTransferFunction(TransferFunction::preset("ramp", 0, 9));
  e.setRenderParams(rp);
  e.render(orbit(v, 30, 20), 48, 48, img);
  EXPECT_FALSE(e.labelMapActive());
  rp.labelMap = true;
  e.setRenderParams(rp);
  e.render(orbit(v, 30, 20), 48, 48, img);
  EXPECT_EQ(compareImages(img, fresh2).maxAbs, 0.f);
  EXPECT_EQ(e.counters().labelSets, 1);
}

// (d) Against each label rendered as its own binary volume (trilinear, opacity where it
// interpolates above 1/2), composited: blobs apart in every axis's projection, so each pixel
// sees one label and the sum of the per-label images is the reference.
TEST(LabelMap, BlendMatchesPerLabelBinaryVolumes) {
  const std::vector<Blob> blobs{{9, 9, 9, 5.5, 1}, {20, 20, 20, 5.5, 4}, {31, 31, 31, 5.5, 9}, {42, 42, 42, 4.5, 200}};
  const int n = 52;
  const Volume v = blobLabels(n, blobs);
  const LabelTable t = tableFor({1, 4, 9, 200}, 0.6f);
  for (auto [az, el] : {std::pair{10.0, 10.0}, std::pair{80.0, -15.0}}) {
    Image ref;
    for (const Label& l : t.labels) {
      const uint8_t* d = static_cast<const uint8_t*>(v.data);
      const Volume ind = makeVolume<float>(n, n, n, VoxelType::Float32, [&](int i, int j, int k) {
        return d[i + n * (j + n * k)] == l.id ? 1.f : 0.f;
      });
      TransferFunction tf;
      tf.rangeMin = 0;
      tf.rangeMax = 1;
      tf.table.resize(8192);
      for (size_t i = 0; i < tf.table.size(); ++i)
        tf.table[i] = i >= tf.table.size() / 2 ? vec4f{l.r, l.g, l.b, l.opacity} : vec4f{l.r, l.g, l.b, 0.f};
      const Image one = renderWith(ind, tf, builder(BuilderKind::Naive), az, el, false, 96);
      if (ref.rgba.empty()) ref = one;
      else
        for (size_t i = 0; i < ref.rgba.size(); ++i) {
          vec4f& r = ref.rgba[i];
          const vec4f& o = one.rgba[i];
          r = vec4f{r.x + o.x, r.y + o.y, r.z + o.z, r.w + o.w};
        }
    }
    ASSERT_GT(coverage(ref), 0.02);
    const Image blend = renderLabels(v, t, LabelSampling::Blend, builder(BuilderKind::Grid), az, el, false, 96);
    const Image nearest = renderLabels(v, t, LabelSampling::Nearest, builder(BuilderKind::Grid), az, el, false, 96);
    const double pb = compareImages(ref, blend).psnr, pn = compareImages(ref, nearest).psnr;
    std::printf("per-label reference, az %g el %g: blend %.1f dB, nearest %.1f dB\n", az, el, pb, pn);
    EXPECT_GE(pb, 40.0);
    EXPECT_GT(pb, pn);
  }
}

// Nearest sampling of an ordinary volume: every builder equals Naive, and the image differs
// from the trilinear one.
TEST(LabelMap, NearestOrdinaryVolume) {
  const Volume v = generateVolume("nbody", vec3l{32, 32, 32});
  const TransferFunction tf = randomTF(7);
  RenderParams rp;
  rp.nearest = true;
  const Image ref = renderWith(v, tf, builder(BuilderKind::Naive), 30, 20, false, 64, BackendKind::CPU, rp);
  const Image tri = renderWith(v, tf, builder(BuilderKind::Naive), 30, 20, false, 64);
  EXPECT_GT(compareImages(ref, tri).maxAbs, 2.f / 255.f);
  for (const BuildParams& p : skippingBuilders()) {
    const Image img = renderWith(v, tf, p, 30, 20, false, 64, BackendKind::CPU, rp);
    EXPECT_LE(compareImages(ref, img).maxAbs, 1e-5f) << builderName(p.builder);
  }
}

// A label map asked for on float voxels: said, drawn as the ordinary volume.
TEST(LabelMap, FloatVolumeFallsBack) {
  const Volume v = generateVolume("noise", vec3l{24, 24, 24});
  ASSERT_EQ(v.type, VoxelType::Float32);
  Engine e(BackendKind::CPU);
  std::vector<std::string> said;
  load(e, v, TransferFunction::preset("ramp", 0, 1), builder(BuilderKind::Grid));
  e.setLogger([&](const std::string& m) { said.push_back(m); });
  RenderParams rp;
  rp.labelMap = true;
  e.setRenderParams(rp);
  Image img;
  e.render(orbit(v, 30, 20), 32, 32, img);
  EXPECT_FALSE(e.labelMapActive());
  ASSERT_EQ(said.size(), 1u);
  EXPECT_NE(said[0].find("label map"), std::string::npos);
  const Image plain = renderWith(v, TransferFunction::preset("ramp", 0, 1), builder(BuilderKind::Grid), 30, 20, false, 32);
  EXPECT_EQ(compareImages(img, plain).maxAbs, 0.f);
}

// The label-map benchmark's data set (generateLabels, `spaceskip bench --label-map`): the same
// voxels for the same seed, every requested id present (uint16 above 255 labels), and a hide/show
// toggle of one label re-classifies over the label sets without reading a voxel.
TEST(LabelMap, GeneratedLabelsAreDeterministicWithEveryId) {
  const vec3l d{64, 64, 64};
  const Volume a = generateLabels(d, 256, 1), b = generateLabels(d, 256, 1), c = generateLabels(d, 256, 2);
  ASSERT_EQ(a.type, VoxelType::UInt16);
  const size_t bytes = size_t(a.voxelCount()) * 2;
  EXPECT_EQ(std::memcmp(a.data, b.data, bytes), 0);
  EXPECT_NE(std::memcmp(a.data, c.data, bytes), 0);
  const Volume viaShape = generateVolume("labels", d);
  EXPECT_EQ(std::memcmp(a.data, viaShape.data, bytes), 0);
  const uint16_t* p = static_cast<const uint16_t*>(a.data);
  std::set<int> ids(p, p + a.voxelCount());
  EXPECT_EQ(ids.size(), 257u);  // 0 and 1..256
  EXPECT_EQ(*ids.begin(), 0);
  EXPECT_EQ(*ids.rbegin(), 256);
  const int64_t background = std::count(p, p + a.voxelCount(), uint16_t(0));
  EXPECT_GT(background, a.voxelCount() / 2);  // sparse: most of the volume is empty
  const Volume few = generateVolume("labels40", d);
  ASSERT_EQ(few.type, VoxelType::UInt8);
  const uint8_t* q = static_cast<const uint8_t*>(few.data);
  EXPECT_EQ(std::set<int>(q, q + few.voxelCount()).size(), 41u);
}

TEST(LabelMap, ToggleOnGeneratedLabelsReadsNoVoxels) {
  const Volume v = generateLabels(vec3l{64, 64, 64}, 256, 1);
  std::vector<int> ids;
  for (int id = 1; id <= 256; ++id) ids.push_back(id);
  LabelTable t = tableFor(ids, 0.5f);
  for (Label& l : t.labels) l.visible = l.id % 10 == 0;  // the bench's tenth
  Engine e(BackendKind::CPU);
  const Image before = renderLabels(v, t, LabelSampling::Blend, builder(BuilderKind::Grid), 30, 20, false, 48, &e);
  const Counters c0 = e.counters();
  const int64_t occ0 = e.occupancy().occupied;
  Image img;
  t.labels[9].visible = false;  // id 10: hidden
  e.setLabelTable(t);
  e.render(orbit(v, 30, 20), 48, 48, img);
  EXPECT_LT(e.occupancy().occupied, occ0);
  t.labels[9].visible = true;  // and shown again
  e.setLabelTable(t);
  e.render(orbit(v, 30, 20), 48, 48, img);
  const Counters c1 = e.counters();
  EXPECT_EQ(c1.voxelPasses, c0.voxelPasses);
  EXPECT_EQ(c1.labelSets, c0.labelSets);
  EXPECT_EQ(c1.rangeGrids, c0.rangeGrids);
  EXPECT_EQ(c1.classifications, c0.classifications + 2);
  EXPECT_EQ(e.occupancy().occupied, occ0);
  EXPECT_EQ(compareImages(before, img).maxAbs, 0.f);
}
