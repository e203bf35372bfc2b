// A volume rendered in pieces (as ParaView's ranks do under MPI) and composited in visibility
// order gives the image of the whole volume: every piece samples the whole volume's lattice,
// draws its owned cells only (half-open) and reads its neighbours' voxels from ghost layers.
#include "TestUtil.h"

#include "spaceskip/Backend.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

using namespace spaceskip;

namespace {
/// A piece: point extent [lo, hi] (inclusive, ghost layers included) and owned cells [ownLo, ownHi).
struct Part {
  int lo[3], hi[3], ownLo[3], ownHi[3];
};

Volume whole() {
  return test::offsetNbody();
}

/// Cells [0, n) of axis `a` split at cell s into two parts, each with `ghost` layers of the other.
void split(const Part& p, int a, int s, int ghost, int wholePts, Part& low, Part& high) {
  low = high = p;
  low.ownHi[a] = s;
  low.hi[a] = std::min(s + ghost, wholePts - 1);
  high.ownLo[a] = s;
  high.lo[a] = std::max(s - ghost, 0);
}

/// The piece's voxels as a volume of its own, and where it lies in the whole one.
Volume cut(const Volume& v, const Part& p, VolumePiece& piece) {
  Volume out;
  out.type = v.type;
  out.dims = vec3l{p.hi[0] - p.lo[0] + 1, p.hi[1] - p.lo[1] + 1, p.hi[2] - p.lo[2] + 1};
  std::copy(v.spacing, v.spacing + 3, out.spacing);
  for (int a = 0; a < 3; ++a) out.origin[a] = v.origin[a] + v.spacing[a] * p.lo[a];
  out.allocate(out.dims, v.type);
  const size_t vs = voxelSize(v.type);
  const auto* src = static_cast<const unsigned char*>(v.data);
  for (int64_t k = 0; k < out.dims.z; ++k)
    for (int64_t j = 0; j < out.dims.y; ++j) {
      const int64_t from = p.lo[0] + v.dims.x * ((p.lo[1] + j) + v.dims.y * (p.lo[2] + k));
      std::memcpy(out.mutableData() + size_t(out.dims.x * (j + out.dims.y * k)) * vs, src + size_t(from) * vs,
                  size_t(out.dims.x) * vs);
    }
  out.data = out.mutableData();
  piece.wholeDims = v.dims;
  std::copy(v.origin, v.origin + 3, piece.wholeOrigin);
  piece.offset = vec3l{p.lo[0], p.lo[1], p.lo[2]};
  piece.ownedLo = vec3l{p.ownLo[0], p.ownLo[1], p.ownLo[2]};
  piece.ownedHi = vec3l{p.ownHi[0], p.ownHi[1], p.ownHi[2]};
  return out;
}

struct Case {
  BuilderKind builder;
  bool persp;
  RenderParams rp;
};

Image renderPiece(const Volume& v, const VolumePiece* piece, const Case& c, double az, double el,
                  const Volume& world, BackendKind backend = BackendKind::CPU) {
  Engine e(backend);
  test::load(e, v, TransferFunction::preset("ramp", 0, 255), test::builder(c.builder));
  e.setRenderParams(c.rp);
  if (piece) e.setPiece(*piece);
  Image img;
  e.render(test::orbit(world, az, el, c.persp), 64, 64, img);
  return img;
}

/// front over back, premultiplied
void over(Image& acc, const Image& back) {
  for (size_t i = 0; i < acc.rgba.size(); ++i) {
    const float k = 1.f - acc.rgba[i].w;
    acc.rgba[i].x += k * back.rgba[i].x;
    acc.rgba[i].y += k * back.rgba[i].y;
    acc.rgba[i].z += k * back.rgba[i].z;
    acc.rgba[i].w += k * back.rgba[i].w;
  }
}

/// The camera's side of the plane index = s on axis a (the orbit camera's eye, test::orbit).
bool eyeBelow(const Volume& v, double az, double el, bool persp, int a, int s) {
  double b[6];
  v.worldBounds(b);
  const double c[3] = {(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2};
  const double dx = b[1] - b[0], dy = b[3] - b[2], dz = b[5] - b[4];
  const double radius = 0.5 * std::sqrt(dx * dx + dy * dy + dz * dz);
  const double A = az * M_PI / 180, E = el * M_PI / 180;
  const double dir[3] = {std::sin(A) * std::cos(E), std::sin(E), std::cos(A) * std::cos(E)};
  const double dist = persp ? radius / std::sin(15.0 * M_PI / 180.0) : 3 * radius;
  return c[a] + dir[a] * dist < v.origin[a] + v.spacing[a] * s;
}

/// Naive, Grid and KdTreeCPU, orthographic and perspective, each with `rp` and the first sample
/// one step in (as the VTK mapper without jitter).
std::vector<Case> everyBuilderAndProjection(RenderParams rp) {
  rp.firstSampleOffset = 1;
  std::vector<Case> cs;
  for (BuilderKind k : {BuilderKind::Naive, BuilderKind::Grid, BuilderKind::KdTreeCPU})
    for (bool persp : {false, true}) cs.push_back({k, persp, rp});
  return cs;
}

std::vector<Case> cases() {
  std::vector<Case> cs = everyBuilderAndProjection(RenderParams{});
  RenderParams jit;
  jit.jitter = true;
  jit.jitterSeed = 7;
  cs.push_back({BuilderKind::Grid, true, jit});
  RenderParams shade;
  shade.shade = true;
  shade.firstSampleOffset = 1;
  cs.push_back({BuilderKind::KdTreeCPU, true, shade});
  RenderParams crop;  // VTK's fence, planes at a third and two thirds of the box
  crop.cropping = true;
  crop.croppingFlags = 0x2ebfeba;
  const Volume v = whole();
  for (int a = 0; a < 3; ++a) {
    crop.croppingPlanes[2 * a] = v.origin[a] + (v.dims[a] - 1) * v.spacing[a] / 3.0;
    crop.croppingPlanes[2 * a + 1] = v.origin[a] + 2.0 * (v.dims[a] - 1) * v.spacing[a] / 3.0;
  }
  cs.push_back({BuilderKind::Grid, false, crop});
  RenderParams clip;
  clip.clipPlanes.push_back({0.6, -0.3, 0.74, -0.6 * 2.0 + 0.3 * 140 - 0.74 * 18});
  clip.firstSampleOffset = 1;
  cs.push_back({BuilderKind::KdTreeCPU, true, clip});
  return cs;
}

/// Early ray termination at a low threshold, so that many rays stop in the back piece.
std::vector<Case> ertCases() {
  RenderParams ert;
  ert.ertThreshold = 0.3;
  std::vector<Case> cs = everyBuilderAndProjection(ert);
  ert.shade = true;  // and shaded, the first sample at the entry
  cs.push_back({BuilderKind::Grid, true, ert});
  return cs;
}

/// `v` cut in two pieces along x at cell 17: va (with its piece pa) below, vb above.
void halves(const Volume& v, Volume& va, VolumePiece& pa, Volume& vb, VolumePiece& pb) {
  const int pts[3] = {int(v.dims.x), int(v.dims.y), int(v.dims.z)};
  Part all{{0, 0, 0}, {pts[0] - 1, pts[1] - 1, pts[2] - 1}, {0, 0, 0}, {pts[0] - 1, pts[1] - 1, pts[2] - 1}};
  Part a, b;
  split(all, 0, 17, 1, pts[0], a, b);
  va = cut(v, a, pa);
  vb = cut(v, b, pb);
}
}  // namespace

TEST(Pieces, APieceThatIsTheWholeVolumeRendersTheSerialImageExactly) {
  const Volume v = whole();
  for (const Case& c : cases()) {
    Part p{{0, 0, 0}, {int(v.dims.x) - 1, int(v.dims.y) - 1, int(v.dims.z) - 1}, {0, 0, 0},
           {int(v.dims.x) - 1, int(v.dims.y) - 1, int(v.dims.z) - 1}};
    VolumePiece piece;
    const Volume data = cut(v, p, piece);
    const Image serial = renderPiece(v, nullptr, c, 35, 25, v);
    EXPECT_EQ(compareImages(serial, renderPiece(data, &piece, c, 35, 25, v)).maxAbs, 0.f) << builderName(c.builder);
  }
}

// Two pieces split along x, and three as ParaView's extent translator splits for 3 ranks (y, then
// the upper half along x): composited front to back they give the whole volume's image.
TEST(Pieces, CompositedPiecesEqualTheWholeVolume) {
  const Volume v = whole();
  const int pts[3] = {int(v.dims.x), int(v.dims.y), int(v.dims.z)};
  Part all{{0, 0, 0}, {pts[0] - 1, pts[1] - 1, pts[2] - 1}, {0, 0, 0}, {pts[0] - 1, pts[1] - 1, pts[2] - 1}};
  for (double az : {35.0, 200.0}) {
    const double el = az > 100 ? -30.0 : 25.0;
    for (const Case& c : cases()) {
      const Image serial = renderPiece(v, nullptr, c, az, el, v);
      ASSERT_GT(test::coverage(serial), 0.01);
      // 2 pieces, x split at cell 17, one ghost layer (gradients read one voxel beyond a sample).
      Part a, b;
      split(all, 0, 17, 1, pts[0], a, b);
      VolumePiece pa, pb;
      const Volume va = cut(v, a, pa), vb = cut(v, b, pb);
      Image ia = renderPiece(va, &pa, c, az, el, v), ib = renderPiece(vb, &pb, c, az, el, v);
      Image two = eyeBelow(v, az, el, c.persp, 0, 17) ? ia : ib;
      over(two, eyeBelow(v, az, el, c.persp, 0, 17) ? ib : ia);
      EXPECT_LE(compareImages(serial, two).maxAbs, 1e-3f) << "2 pieces, " << builderName(c.builder) << " az " << az;
      // Each piece draws something (the split is not trivial).
      EXPECT_GT(test::coverage(ia), 0.001);
      EXPECT_GT(test::coverage(ib), 0.001);

      // 3 pieces: y at 18; the upper part split along x at 20.
      Part lowY, highY, left, right;
      split(all, 1, 18, 1, pts[1], lowY, highY);
      split(highY, 0, 20, 1, pts[0], left, right);
      VolumePiece p0, p1, p2;
      const Volume v0 = cut(v, lowY, p0), v1 = cut(v, left, p1), v2 = cut(v, right, p2);
      const Image i0 = renderPiece(v0, &p0, c, az, el, v);
      Image upper = renderPiece(v1, &p1, c, az, el, v);
      const Image i2 = renderPiece(v2, &p2, c, az, el, v);
      const bool leftFront = eyeBelow(v, az, el, c.persp, 0, 20);
      if (!leftFront) {
        Image t = i2;
        over(t, upper);
        upper = t;
      } else {
        over(upper, i2);
      }
      Image three = eyeBelow(v, az, el, c.persp, 1, 18) ? i0 : upper;
      over(three, eyeBelow(v, az, el, c.persp, 1, 18) ? upper : i0);
      EXPECT_LE(compareImages(serial, three).maxAbs, 1e-3f) << "3 pieces, " << builderName(c.builder) << " az " << az;
    }
  }
}

// Without the shared lattice each piece would start its samples at its own box (the seams the
// MPI image had): the check above must be able to fail. A piece whose offset is off by one
// voxel samples the wrong voxels and is caught.
TEST(Pieces, AWrongOffsetIsVisible) {
  const Volume v = whole();
  const int pts[3] = {int(v.dims.x), int(v.dims.y), int(v.dims.z)};
  Part all{{0, 0, 0}, {pts[0] - 1, pts[1] - 1, pts[2] - 1}, {0, 0, 0}, {pts[0] - 1, pts[1] - 1, pts[2] - 1}};
  Part a, b;
  split(all, 0, 17, 1, pts[0], a, b);
  VolumePiece pb;
  const Volume vb = cut(v, b, pb);
  Case c{BuilderKind::Grid, false, RenderParams{}};
  const Image good = renderPiece(vb, &pb, c, 35, 25, v);
  pb.offset.x += 1;
  pb.ownedLo.x += 1;
  EXPECT_GT(compareImages(good, renderPiece(vb, &pb, c, 35, 25, v)).maxAbs, 0.05f);
  // A piece that does not fit its volume is ignored (rendered whole), not a crash.
  pb.offset.x = 1000;
  std::vector<std::string> said;
  Engine e(BackendKind::CPU);
  test::load(e, vb, TransferFunction::preset("ramp", 0, 255), test::builder(BuilderKind::Grid));
  e.setLogger([&](const std::string& m) { said.push_back(m); });
  e.setPiece(pb);
  Image img;
  e.render(test::orbit(v, 35, 25), 32, 32, img);
  ASSERT_EQ(said.size(), 1u);
  EXPECT_NE(said[0].find("does not fit"), std::string::npos);
}

// The same lattice code on the device: CUDA pieces composite to the CPU's whole image.
TEST(Pieces, CudaPiecesEqualTheWholeVolume) {
  SKIP_WITHOUT_CUDA();
  const Volume v = whole();
  const int pts[3] = {int(v.dims.x), int(v.dims.y), int(v.dims.z)};
  Part all{{0, 0, 0}, {pts[0] - 1, pts[1] - 1, pts[2] - 1}, {0, 0, 0}, {pts[0] - 1, pts[1] - 1, pts[2] - 1}};
  for (const Case& c : cases()) {
    if (c.builder == BuilderKind::KdTreeCPU) continue;  // a CPU builder; Grid and Naive run on the device
    const Image serial = renderPiece(v, nullptr, c, 35, 25, v);
    Part a, b;
    split(all, 0, 17, 1, pts[0], a, b);
    VolumePiece pa, pb;
    const Volume va = cut(v, a, pa), vb = cut(v, b, pb);
    Image ia = renderPiece(va, &pa, c, 35, 25, v, BackendKind::CUDA);
    const Image ib = renderPiece(vb, &pb, c, 35, 25, v, BackendKind::CUDA);
    const bool aFront = eyeBelow(v, 35, 25, c.persp, 0, 17);
    Image two = aFront ? ia : ib;
    over(two, aFront ? ib : ia);
    EXPECT_LE(compareImages(serial, two).maxAbs, 1.f / 255.f) << builderName(c.builder);
  }
}

// followBias (IceT's 8-bit blend) raises the colour only where a piece lies behind along the ray.
TEST(Pieces, FollowBiasRaisesOnlyPixelsWithAPieceBehind) {
  const Volume v = whole();
  VolumePiece pa, pb;
  Volume va, vb;
  halves(v, va, pa, vb, pb);
  const Case c{BuilderKind::Grid, false, RenderParams{}};
  const bool aFront = eyeBelow(v, 35, 25, false, 0, 17);
  VolumePiece& front = aFront ? pa : pb;
  VolumePiece& back = aFront ? pb : pa;
  const Volume& vf = aFront ? va : vb;
  const Volume& vback = aFront ? vb : va;
  const Image f0 = renderPiece(vf, &front, c, 35, 25, v), b0 = renderPiece(vback, &back, c, 35, 25, v);
  front.followBias = back.followBias = 0.5f / 255.f;
  const Image f1 = renderPiece(vf, &front, c, 35, 25, v), b1 = renderPiece(vback, &back, c, 35, 25, v);
  EXPECT_EQ(compareImages(b0, b1).maxAbs, 0.f);  // nothing behind the back piece
  EXPECT_NEAR(compareImages(f0, f1).maxAbs, 0.5f / 255.f, 1e-6f);
}

namespace {
/// Two pieces (x split at cell 17) rendered front to back, the back one given the front one's
/// opacity as alphaIn (pieces composited in float in one process: vtkSpaceSkipBlockRenderer).
/// Returns front + back (the back image is already weighted), and in `plainOver` the two blended
/// with "over" without alphaIn.
Image carriedPieces(const Case& c, BackendKind backend, Image* plainOver) {
  const Volume v = whole();
  VolumePiece pa, pb;
  Volume va, vb;
  halves(v, va, pa, vb, pb);
  const bool aFront = eyeBelow(v, 35, 25, c.persp, 0, 17);
  const Image front = renderPiece(aFront ? va : vb, aFront ? &pa : &pb, c, 35, 25, v, backend);
  std::vector<float> alpha(front.rgba.size());
  for (size_t i = 0; i < alpha.size(); ++i) alpha[i] = front.rgba[i].w;
  Engine e(backend);
  test::load(e, aFront ? vb : va, TransferFunction::preset("ramp", 0, 255), test::builder(c.builder));
  e.setRenderParams(c.rp);
  e.setPiece(aFront ? pb : pa);
  Image back;
  e.render(test::orbit(v, 35, 25, c.persp), 64, 64, back, nullptr, alpha.data());
  Image sum = front;
  for (size_t i = 0; i < sum.rgba.size(); ++i) {
    sum.rgba[i].x += back.rgba[i].x;
    sum.rgba[i].y += back.rgba[i].y;
    sum.rgba[i].z += back.rgba[i].z;
    sum.rgba[i].w += back.rgba[i].w;
  }
  if (plainOver) {
    *plainOver = front;
    over(*plainOver, renderPiece(aFront ? vb : va, aFront ? &pb : &pa, c, 35, 25, v, backend));
  }
  return sum;
}

}  // namespace

// alphaIn: the back piece's rays go on from the front piece's opacity, so early ray termination
// stops where the whole volume's ray stops and front + back is the whole image; blended with
// "over" without it, the pieces differ where a ray terminates in the back piece.
TEST(Pieces, AlphaInCarriesEarlyRayTerminationAcrossPieces) {
  const Volume v = whole();
  for (const Case& c : ertCases()) {
    const Image serial = renderPiece(v, nullptr, c, 35, 25, v);
    ASSERT_GT(test::coverage(serial), 0.01);
    Image plain;
    const Image carried = carriedPieces(c, BackendKind::CPU, &plain);
    EXPECT_LE(compareImages(serial, carried).maxAbs, 1e-3f) << builderName(c.builder) << " persp " << c.persp;
    EXPECT_GT(compareImages(serial, plain).maxAbs, 0.01f) << builderName(c.builder) << " persp " << c.persp;
  }
}

TEST(Pieces, CudaAlphaInCarriesEarlyRayTerminationAcrossPieces) {
  SKIP_WITHOUT_CUDA();
  const Volume v = whole();
  for (const Case& c : ertCases()) {
    if (c.builder == BuilderKind::KdTreeCPU) continue;
    const Image serial = renderPiece(v, nullptr, c, 35, 25, v);
    const Image carried = carriedPieces(c, BackendKind::CUDA, nullptr);
    EXPECT_LE(compareImages(serial, carried).maxAbs, 1.f / 255.f) << builderName(c.builder);
  }
}
