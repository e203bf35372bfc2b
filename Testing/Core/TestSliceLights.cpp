// The slice blend mode and shading with a list of lights (VTK's light kit, several directional
// lights, positional lights): what each computes (vtkGPUVolumeRayCastMapper's semantics), and
// that every builder's image equals the Naive traversal's (lossless skipping), CPU and CUDA.
#include "TestUtil.h"

#include <gtest/gtest.h>

#include "spaceskip/Backend.h"

#include <cmath>
#include <tuple>

using namespace spaceskip;

namespace {

/// A w x h x d float volume filled by f(i, j, k), unit spacing.
template <class F>
Volume makeVolume(int w, int h, int d, F f) {
  return test::makeVolume<float>(w, h, d, VoxelType::Float32, f);
}

/// Shading by the light list alone (RenderParams::useLights) with these coefficients.
RenderParams lightsOnly(double ambient, double diffuse, double specular, std::vector<Light> lights = {}) {
  RenderParams r;
  r.shade = r.useLights = true;
  std::tie(r.ambient, r.diffuse, r.specular) = std::tie(ambient, diffuse, specular);
  r.lights = std::move(lights);
  return r;
}

vec4f centre(const Image& img) { return img.rgba[size_t(img.height / 2) * size_t(img.width) + size_t(img.width / 2)]; }

/// A directional light travelling along (dx, dy, dz), white of `intensity`.
Light directional(double dx, double dy, double dz, double intensity = 1.0) {
  Light l;
  for (int k = 0; k < 3; ++k) {
    l.focalPoint[k] = 0;
    l.diffuse[k] = l.specular[k] = intensity;
  }
  l.position[0] = -dx;
  l.position[1] = -dy;
  l.position[2] = -dz;
  return l;
}

/// VTK's light kit in a camera-free form: key, fill, back and head lights (vtkLightKit's default
/// intensities: key 0.75, fill key/3, back key/3.5, head key/3) from four directions.
std::vector<Light> lightKit() {
  std::vector<Light> k = {directional(-0.4, -0.6, -0.7, 0.75), directional(0.5, 0.2, -0.8, 0.25),
                          directional(0.3, -0.1, 0.9, 0.75 / 3.5), directional(0, 0, -1, 0.25)};
  k[1].ambient[0] = k[1].ambient[1] = k[1].ambient[2] = 0.1;  // an ambient colour, as lights may have
  return k;
}

RenderParams sliceParams(double ox, double oy, double oz, double nx, double ny, double nz) {
  RenderParams r;
  r.blend = BlendMode::Slice;
  r.sliceOrigin[0] = ox;
  r.sliceOrigin[1] = oy;
  r.sliceOrigin[2] = oz;
  r.sliceNormal[0] = nx;
  r.sliceNormal[1] = ny;
  r.sliceNormal[2] = nz;
  return r;
}

/// Faint at the lowest values (the background), then stronger: a slice shows its whole plane
/// and the data's cross-section on it.
TransferFunction sliceTF(double lo, double hi) {
  const double w = hi - lo;
  return TransferFunction::fromPoints({{lo, 0.2f, 0.3f, 0.9f, 0.1f}, {lo + 0.01 * w, 0.2f, 0.3f, 0.9f, 0.1f},
                                       {lo + 0.02 * w, 0.3f, 0.8f, 0.4f, 0.4f}, {hi, 0.9f, 0.2f, 0.1f, 0.9f}},
                                      lo, hi, 256);
}

struct Mode {
  const char* name;
  RenderParams rp;
};

/// The slice and light-list modes every builder must render as Naive does.
std::vector<Mode> sliceAndLightModes(const Volume& v) {
  double b[6];
  v.worldBounds(b);
  const double cx = 0.5 * (b[0] + b[1]), cy = 0.5 * (b[2] + b[3]), cz = 0.5 * (b[4] + b[5]);
  std::vector<Mode> m;
  RenderParams r = sliceParams(cx + 3.3, cy, cz, 0.6, 0.3, 0.74);
  m.push_back({"slice-oblique", r});
  r.sliceAsVTK = false;
  m.push_back({"slice-oblique-at-the-plane", r});
  r.shade = true;
  r.specular = 0.4;
  m.push_back({"slice-shade-headlight", r});
  r.useLights = true;
  r.lights = lightKit();
  m.push_back({"slice-shade-lightkit", r});
  RenderParams c;
  c.shade = true;
  c.ambient = 0.3;
  c.specular = 0.4;
  c.useLights = true;
  c.lights = lightKit();
  m.push_back({"composite-lightkit", c});
  c.lights = {directional(1, -0.2, -0.3, 0.8), directional(-0.7, 0.5, -0.2, 0.6)};
  c.twoSidedLighting = false;
  m.push_back({"composite-2-directional-one-sided", c});
  Light spot;
  spot.positional = true;
  spot.position[0] = b[1] + 10;
  spot.position[1] = cy + 5;
  spot.position[2] = b[5] + 20;
  spot.focalPoint[0] = cx;
  spot.focalPoint[1] = cy;
  spot.focalPoint[2] = cz;
  spot.coneAngle = 25;
  spot.attenuation[1] = 0.01;
  c.lights = {spot, directional(0, 0, -1, 0.5)};
  c.twoSidedLighting = true;
  m.push_back({"composite-spot+directional", c});
  RenderParams iso = c;
  iso.blend = BlendMode::Isosurface;
  double lo, hi;
  v.scalarRange(lo, hi);
  iso.isoValues = {lo + 0.5 * (hi - lo)};
  iso.lights = lightKit();
  m.push_back({"iso-lightkit", iso});
  return m;
}

}  // namespace

TEST(Slice, TheRaysValueIsTheSampleOnThePlane) {
  // Values grow with x; the TF maps them linearly. Seen along x (azimuth 90), a plane x = 10.25
  // gives every pixel the value at x = 10.25 (82) with the TF's raw opacity (no correction for
  // the sample distance: one sample, as VTK).
  Volume v = makeVolume(32, 32, 32, [](int i, int, int) { return float(i) * 8.f; });
  TransferFunction tf = TransferFunction::fromPoints({{0, 0.f, 0.f, 1.f, 0.1f}, {248, 1.f, 0.f, 0.f, 0.5f}}, 0, 248, 256);
  RenderParams s = sliceParams(10.25, 0, 0, 1, 0, 0);
  s.sampleDistance = 0.1;
  s.sliceAsVTK = false;
  Image a = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 48, BackendKind::CPU, s);
  const float f = 82.f / 248.f;
  const vec4f c = centre(a);
  EXPECT_NEAR(c.w, 0.1f + 0.4f * f, 2e-3f);
  EXPECT_NEAR(c.x / c.w, f, 5e-3f);
  EXPECT_NEAR(c.z / c.w, 1.f - f, 5e-3f);
  // Where VTK's shader reads it: x = 10.25 * 32 / 31 - 0.5 (31 cells), the value 80.65.
  s.sliceAsVTK = true;
  const float fv = (10.25f * 32.f / 31.f - 0.5f) * 8.f / 248.f;
  EXPECT_NEAR(centre(test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 48, BackendKind::CPU, s)).w,
              0.1f + 0.4f * fv, 2e-3f);
  s.sliceAsVTK = false;
  // Moving the plane changes the value; seen along z instead, each pixel sees its own x.
  s.sliceOrigin[0] = 20.5;
  EXPECT_NEAR(centre(test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 48, BackendKind::CPU, s)).w,
              0.1f + 0.4f * 164.f / 248.f, 2e-3f);
  RenderParams z = sliceParams(0, 0, 15.5, 0, 0, 1);
  z.sliceAsVTK = false;
  Image along = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 0, 0, false, 48, BackendKind::CPU, z);
  Image mip = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 0, 0, false, 48, BackendKind::CPU,
                               [] { RenderParams m; m.blend = BlendMode::MaximumIntensity; return m; }());
  EXPECT_GT(test::coverage(along), 0.05);
  EXPECT_LE(compareImages(along, mip).maxAbs, 2e-3f);  // one x per ray: the slice is the MIP
  // A plane outside the box, or parallel to the rays, draws nothing.
  s.sliceOrigin[0] = 40;
  EXPECT_EQ(test::coverage(test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 48, BackendKind::CPU, s)), 0.0);
  s.sliceOrigin[0] = 10.25;
  EXPECT_EQ(test::coverage(test::renderWith(v, tf, test::builder(BuilderKind::Grid), 0, 0, false, 48, BackendKind::CPU, s)), 0.0);
}

TEST(Slice, OnePlaneOneSampleAndTheDrawnPartOnly) {
  Volume v = generateVolume("vessels", vec3l{40, 40, 40});
  double lo, hi;
  ASSERT_TRUE(v.scalarRange(lo, hi));
  auto tf = sliceTF(lo, hi);
  RenderParams s = sliceParams(19.5, 19.5, 19.5, 0.2, 0.1, 1);
  int64_t samples = 0;
  Image full = test::renderCounting(v, tf, BuilderKind::Naive, test::orbit(v, 20, 30), 48, samples, s);
  ASSERT_GT(test::coverage(full), 0.02);
  int hits = 0;
  for (const vec4f& p : full.rgba) hits += p.w > 0.f ? 1 : 0;
  EXPECT_LE(samples, int64_t(48 * 48));  // at most one sample per ray, however thick the volume
  EXPECT_GE(samples, int64_t(hits));
  // A clipping plane keeping x >= 20 removes the slice's other half; cropping to the sub-volume
  // x, y, z in [10, 30] keeps only that part of it. Nothing appears that the full slice lacks.
  RenderParams clipped = s;
  clipped.clipPlanes.push_back({1, 0, 0, -20});
  Image c = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 20, 30, false, 48, BackendKind::CPU, clipped);
  RenderParams cropped = s;
  cropped.cropping = true;
  for (int a = 0; a < 3; ++a) {
    cropped.croppingPlanes[2 * a] = 10;
    cropped.croppingPlanes[2 * a + 1] = 30;
  }
  Image k = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 20, 30, false, 48, BackendKind::CPU, cropped);
  for (const Image* img : {&c, &k}) {
    EXPECT_GT(test::coverage(*img), 0.1 * test::coverage(full));
    EXPECT_LT(test::coverage(*img), 0.8 * test::coverage(full));
    for (size_t i = 0; i < img->rgba.size(); ++i)
      if (img->rgba[i].w > 0.f) EXPECT_LE(std::fabs(img->rgba[i].w - full.rgba[i].w), 1e-5f);
  }
}

TEST(Slice, ABadPlaneFallsBackToTheCentreWithOneWarning) {
  Volume v = makeVolume(24, 24, 24, [](int, int, int k) { return float(k) * 10.f; });
  auto tf = TransferFunction::fromPoints({{0, 1.f, 1.f, 1.f, 0.2f}, {230, 1.f, 1.f, 1.f, 0.6f}}, 0, 230, 256);
  std::vector<std::string> said;
  Engine e(BackendKind::CPU, [&](const std::string& m) { said.push_back(m); });
  e.setVolume(v);
  e.setTransferFunction(tf);
  e.setBuildParams(test::builder(BuilderKind::Grid));
  RenderParams s = sliceParams(0, 0, 0, 0, 0, 0);
  e.setRenderParams(s);
  Image img;
  e.render(test::orbit(v, 0, 0), 32, 32, img);
  e.render(test::orbit(v, 0, 0), 32, 32, img);
  ASSERT_EQ(said.size(), 1u);
  EXPECT_NE(said[0].find("slice"), std::string::npos);
  // The centre plane z = 11.5 holds the value 115: opacity 0.2 + 0.4 * 0.5 (VTK reads it at
  // 11.5 * 24 / 23 - 0.5 = 11.5 too: the centre is where its coordinates are exact).
  EXPECT_NEAR(centre(img).w, 0.4f, 2e-3f);
}

TEST(Slice, EveryBuilderEqualsNaiveAndLightsToo) {
  const char* shapes[] = {"vessels", "nbody"};
  const bool persp[] = {false, true};
  for (const char* shape : shapes) {
    Volume v = generateVolume(shape, vec3l{40, 42, 37});
    double lo, hi;
    ASSERT_TRUE(v.scalarRange(lo, hi));
    for (const Mode& m : sliceAndLightModes(v))
      for (bool p : persp) {
        const TransferFunction tf = m.rp.blend == BlendMode::Slice ? sliceTF(lo, hi)
                                                                   : TransferFunction::preset("ramp", lo, hi, 256);
        Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 30, 20, p, 40, BackendKind::CPU, m.rp);
        ASSERT_GT(test::coverage(ref), 0.0) << shape << " " << m.name << " renders nothing";
        for (const BuildParams& bp : test::skippingBuilders()) {
          Image img = test::renderWith(v, tf, bp, 30, 20, p, 40, BackendKind::CPU, m.rp);
          EXPECT_LE(compareImages(ref, img).maxAbs, 1.f / 255.f)
              << shape << " " << m.name << " " << builderName(bp.builder) << " brick " << bp.brick;
          EXPECT_FALSE(hasNonFinite(img)) << shape << " " << m.name;
        }
      }
  }
}

TEST(Slice, CudaEqualsCpu) {
  SKIP_WITHOUT_CUDA();
  Volume v = generateVolume("vessels", vec3l{64, 61, 67});
  double lo, hi;
  ASSERT_TRUE(v.scalarRange(lo, hi));
  for (const Mode& m : sliceAndLightModes(v)) {
    const TransferFunction tf = m.rp.blend == BlendMode::Slice ? sliceTF(lo, hi)
                                                               : TransferFunction::preset("ramp", lo, hi, 256);
    test::expectCudaBuildersEqualNaive(v, tf, m.rp, m.name);
  }
}

TEST(Lights, DirectionalLightsTwoSidedColouredAndSummed) {
  // Values grow with x: the unit normal is +x everywhere. Seen along x, ambient 0, diffuse 1,
  // specular 0: a white light of intensity 1 travelling along -x (n.l = -1) lights the samples
  // fully with two-sided lighting (the unshaded image) and not at all one-sided; one travelling
  // along +x lights them fully either way.
  Volume v = makeVolume(24, 24, 24, [](int i, int, int) { return float(i) * 10.f; });
  TransferFunction tf = TransferFunction::fromPoints({{0, 0.8f, 0.5f, 0.2f, 0.3f}, {230, 0.2f, 0.5f, 0.9f, 0.3f}}, 0, 230, 256);
  auto render = [&](const RenderParams& r) {
    return test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 32, BackendKind::CPU, r);
  };
  const Image plain = render(RenderParams{});
  ASSERT_GT(test::coverage(plain), 0.1);
  RenderParams lit = lightsOnly(0, 1, 0, {directional(-1, 0, 0)});
  EXPECT_LE(compareImages(plain, render(lit)).maxAbs, 2e-3f);
  lit.twoSidedLighting = false;
  const vec4f dark = centre(render(lit));
  EXPECT_GT(dark.w, 0.1f);
  EXPECT_LT(dark.x + dark.y + dark.z, 1e-4f);
  lit.lights = {directional(1, 0, 0)};
  EXPECT_LE(compareImages(plain, render(lit)).maxAbs, 2e-3f);
  // Two lights of half the intensity sum to one; a red light lights the red channel only; a light
  // across the gradient (n.l = 0) adds nothing.
  lit.lights = {directional(1, 0, 0, 0.5), directional(1, 0, 0, 0.5), directional(0, 0, 1)};
  EXPECT_LE(compareImages(plain, render(lit)).maxAbs, 2e-3f);
  Light red = directional(1, 0, 0);
  red.diffuse[1] = red.diffuse[2] = 0;
  lit.lights = {red};
  const vec4f r = centre(render(lit)), p = centre(plain);
  EXPECT_NEAR(r.x, p.x, 2e-3f);
  EXPECT_LT(r.y + r.z, 1e-4f);
  // Ambient is the lights' ambient colour times Ambient, not the sample's colour.
  lit.ambient = 1;
  lit.diffuse = 0;
  Light amb = directional(0, 0, 1);
  amb.ambient[0] = amb.ambient[1] = amb.ambient[2] = 0.25;
  lit.lights = {amb};
  const vec4f a = centre(render(lit));
  EXPECT_NEAR(a.x / a.w, 0.25f, 2e-3f);
  EXPECT_NEAR(a.z / a.w, 0.25f, 2e-3f);
  // Shading switched on with no light at all is black, as in VTK.
  lit.lights.clear();
  lit.ambient = 0.5;
  lit.diffuse = 0.7;
  const vec4f none = centre(render(lit));
  EXPECT_GT(none.w, 0.1f);
  EXPECT_LT(none.x + none.y + none.z, 1e-4f);
}

TEST(Lights, SpecularFollowsTheReflection) {
  // Values fall with x (normal -x), seen from +x (rays along -x): a light travelling along the
  // rays, from behind the eye, reflects straight back to it (r.v = 1): specular 1 adds white; a
  // light at 90 degrees to the normal gives none.
  Volume v = makeVolume(24, 24, 24, [](int i, int, int) { return float(23 - i) * 10.f; });
  TransferFunction tf = TransferFunction::fromPoints({{0, 0.f, 0.f, 0.f, 0.3f}, {230, 0.f, 0.f, 0.f, 0.3f}}, 0, 230, 256);
  RenderParams lit = lightsOnly(0, 0, 1, {directional(-1, 0, 0)});
  const vec4f s = centre(test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 32, BackendKind::CPU, lit));
  EXPECT_NEAR(s.x / s.w, 1.f, 2e-3f);
  lit.lights = {directional(0, 1, 0)};
  const vec4f n = centre(test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 32, BackendKind::CPU, lit));
  EXPECT_LT(n.x / n.w, 1e-3f);
}

TEST(Lights, PositionalLightsAttenuateAndConeOut) {
  // A positional light far away along +x, no cone, no attenuation: as a directional light. With
  // quadratic attenuation it dims by 1 / (1 + q d^2); a narrow spot aimed away lights nothing.
  Volume v = makeVolume(24, 24, 24, [](int i, int, int) { return float(i) * 10.f; });
  TransferFunction tf = TransferFunction::fromPoints({{0, 0.8f, 0.5f, 0.2f, 0.3f}, {230, 0.2f, 0.5f, 0.9f, 0.3f}}, 0, 230, 256);
  auto render = [&](const RenderParams& r) {
    return test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 32, BackendKind::CPU, r);
  };
  RenderParams lit = lightsOnly(0, 1, 0);
  Light p;
  p.positional = true;
  p.position[0] = 1e5;
  p.position[1] = p.position[2] = 11.5;
  p.focalPoint[0] = 0;
  p.focalPoint[1] = p.focalPoint[2] = 11.5;
  p.coneAngle = 180;
  lit.lights = {p};
  const Image far = render(lit);
  EXPECT_LE(compareImages(render(RenderParams{}), far).maxAbs, 3e-3f);
  lit.lights[0].position[0] = 111.5;  // 100 from the centre x = 11.5, 88..111 from the samples
  lit.lights[0].attenuation[2] = 1e-4;
  const vec4f dim = centre(render(lit)), full = centre(far);
  EXPECT_LT(dim.x, full.x * 0.6f);
  EXPECT_GT(dim.x, full.x * 0.4f);
  lit.lights[0].coneAngle = 10;
  lit.lights[0].focalPoint[0] = 200;  // aimed away from the volume
  const vec4f off = centre(render(lit));
  EXPECT_LT(off.x + off.y + off.z, 1e-4f);
}

TEST(Lights, MoreThanTheMostAreCutWithOneWarning) {
  Volume v = generateVolume("vessels", vec3l{32, 32, 32});
  double lo, hi;
  ASSERT_TRUE(v.scalarRange(lo, hi));
  auto tf = TransferFunction::preset("ramp", lo, hi, 256);
  RenderParams r;
  r.shade = true;
  r.useLights = true;
  for (int i = 0; i < kMaxLights + 3; ++i)
    r.lights.push_back(directional(std::cos(i * 0.7), std::sin(i * 0.7), -0.5 - 0.1 * i, 0.2));
  std::vector<std::string> said;
  Engine e(BackendKind::CPU, [&](const std::string& m) { said.push_back(m); });
  e.setVolume(v);
  e.setTransferFunction(tf);
  e.setBuildParams(test::builder(BuilderKind::Grid));
  e.setRenderParams(r);
  Image all, first;
  e.render(test::orbit(v, 30, 20), 32, 32, all);
  e.render(test::orbit(v, 30, 20), 32, 32, all);
  ASSERT_EQ(said.size(), 1u);
  EXPECT_NE(said[0].find("lights"), std::string::npos);
  r.lights.resize(size_t(kMaxLights));
  first = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 30, 20, false, 32, BackendKind::CPU, r);
  EXPECT_EQ(compareImages(all, first).maxAbs, 0.f);
  r.lights.resize(3);  // and fewer lights give another image
  EXPECT_GT(compareImages(all, test::renderWith(v, tf, test::builder(BuilderKind::Grid), 30, 20, false, 32,
                                                BackendKind::CPU, r)).maxAbs, 0.01f);
}
