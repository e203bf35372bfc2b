// The float compositing of MPI ranks' pieces on the GPU (spaceskip/PeerImages.h): addBehind, the
// one blend the host and the device share, stops where the ray stopped; PieceBlend on the device
// equals the host blend of the same pieces in the same order (device and host pieces mixed, more
// pieces than one launch takes, rectangles clipped to the viewport); PeerImages shares a frame and
// refuses a handle it cannot map with a reason instead of failing hard. The device cases are
// skipped without a CUDA device.
#include "spaceskip/PeerImages.h"
#include "TestUtil.h"

#include <gtest/gtest.h>

#ifdef SPACESKIP_HAVE_CUDA
#include <cuda_runtime_api.h>
#endif

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

using namespace spaceskip;

TEST(PieceBlend, AddBehindIsFrontToBackOverAndStopsWhereTheRayStopped) {
  vec4f acc{0.2f, 0.1f, 0.0f, 0.5f};
  addBehind(acc, vec4f{0.4f, 0.2f, 0.6f, 0.8f}, 2.f);
  EXPECT_FLOAT_EQ(acc.x, 0.2f + 0.5f * 0.4f);
  EXPECT_FLOAT_EQ(acc.y, 0.1f + 0.5f * 0.2f);
  EXPECT_FLOAT_EQ(acc.z, 0.5f * 0.6f);
  EXPECT_FLOAT_EQ(acc.w, 0.5f + 0.5f * 0.8f);
  // Opacity 0.9 reached a threshold of 0.9: nothing behind is added.
  const vec4f stopped = acc;
  addBehind(acc, vec4f{1.f, 1.f, 1.f, 1.f}, 0.9f);
  EXPECT_EQ(acc.x, stopped.x);
  EXPECT_EQ(acc.w, stopped.w);
}

#ifdef SPACESKIP_HAVE_CUDA
namespace {

struct Piece {
  int x, y, w, h;
  bool host;
  std::vector<vec4f> pixels;
};

// Premultiplied colours with opacity in [0, 0.35]: many pieces reach the threshold in some pixels.
std::vector<Piece> randomPieces(int count, int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<Piece> pieces;
  for (int k = 0; k < count; ++k) {
    Piece p;
    p.w = 1 + int(u(rng) * float(width - 1));
    p.h = 1 + int(u(rng) * float(height - 1));
    p.x = int(u(rng) * float(width - p.w));
    p.y = int(u(rng) * float(height - p.h));
    p.host = k % 3 == 1;
    p.pixels.resize(size_t(p.w) * size_t(p.h));
    for (vec4f& c : p.pixels) {
      const float a = 0.35f * u(rng);
      c = vec4f{a * u(rng), a * u(rng), a * u(rng), a};
    }
    pieces.push_back(std::move(p));
  }
  return pieces;
}

}  // namespace

TEST(PieceBlend, DeviceBlendEqualsTheHostBlendInTheSameOrder) {
  SKIP_WITHOUT_CUDA();
  const int width = 97, height = 61;
  const float stopAt = 0.9f;
  // 70 pieces: more than one launch takes (64), so the second launch goes on from the first's sum.
  const std::vector<Piece> pieces = randomPieces(70, width, height, 7);
  std::vector<vec4f> expected(size_t(width) * size_t(height), vec4f{0, 0, 0, 0});
  for (const Piece& p : pieces)
    for (int j = 0; j < p.h; ++j)
      for (int i = 0; i < p.w; ++i)
        addBehind(expected[size_t(p.y + j) * width + size_t(p.x + i)], p.pixels[size_t(j) * p.w + size_t(i)], stopAt);

  std::vector<void*> deviceCopies;
  std::vector<BlendSource> sources;
  for (const Piece& p : pieces) {
    BlendSource b;
    b.x = p.x;
    b.y = p.y;
    b.w = p.w;
    b.h = p.h;
    b.rowPixels = size_t(p.w);
    b.host = p.host;
    if (p.host) {
      b.pixels = p.pixels.data();
    } else {
      void* d = nullptr;
      ASSERT_EQ(cudaMalloc(&d, p.pixels.size() * sizeof(vec4f)), cudaSuccess);
      ASSERT_EQ(cudaMemcpy(d, p.pixels.data(), p.pixels.size() * sizeof(vec4f), cudaMemcpyHostToDevice), cudaSuccess);
      deviceCopies.push_back(d);
      b.pixels = d;
    }
    sources.push_back(b);
  }
  PieceBlend blend;
  std::string problem;
  const void* sum = blend.blend(sources, width, height, stopAt, nullptr, problem);
  ASSERT_NE(sum, nullptr) << problem;
  std::vector<vec4f> got(expected.size());
  ASSERT_TRUE(PeerImages::download(sum, got.size(), &got[0].x, problem)) << problem;
  float worst = 0.f;
  for (size_t i = 0; i < got.size(); ++i)
    worst = std::max({worst, std::fabs(got[i].x - expected[i].x), std::fabs(got[i].y - expected[i].y),
                      std::fabs(got[i].z - expected[i].z), std::fabs(got[i].w - expected[i].w)});
  EXPECT_LT(worst, 1e-5f) << "the device blend differs from the host blend";
  // Some pixels stopped: the threshold matters in this case.
  EXPECT_TRUE(std::any_of(expected.begin(), expected.end(), [&](const vec4f& c) { return c.w >= stopAt; }));
  for (void* d : deviceCopies) cudaFree(d);
}

TEST(PeerImages, ShareKeepsAHandleAndABadHandleIsRefusedWithAReason) {
  SKIP_WITHOUT_CUDA();
  const size_t pixels = 64 * 32;
  std::vector<vec4f> frame(pixels, vec4f{0.25f, 0.5f, 0.75f, 1.f});
  void* d = nullptr;
  ASSERT_EQ(cudaMalloc(&d, pixels * sizeof(vec4f)), cudaSuccess);
  ASSERT_EQ(cudaMemcpy(d, frame.data(), pixels * sizeof(vec4f), cudaMemcpyHostToDevice), cudaSuccess);
  PeerImages peers;
  PeerImages::Handle first{}, again{}, larger{};
  std::string problem;
  ASSERT_TRUE(peers.share(d, pixels, nullptr, first, problem)) << problem;
  EXPECT_TRUE(std::any_of(first.begin(), first.end(), [](char c) { return c != 0; }));
  // The same size: the same buffer, the same handle. A larger frame: a new buffer.
  ASSERT_TRUE(peers.share(d, pixels, nullptr, again, problem)) << problem;
  EXPECT_EQ(first, again);
  void* big = nullptr;
  ASSERT_EQ(cudaMalloc(&big, 2 * pixels * sizeof(vec4f)), cudaSuccess);
  ASSERT_TRUE(peers.share(big, 2 * pixels, nullptr, larger, problem)) << problem;
  EXPECT_NE(first, larger);
  // A handle of garbage (or one this process exported itself) cannot be mapped: a reason, no crash.
  PeerImages::Handle garbage{};
  garbage.fill(7);
  problem.clear();
  EXPECT_EQ(peers.map(1, garbage, problem), nullptr);
  EXPECT_FALSE(problem.empty());
  // CUDA is still usable afterwards.
  std::vector<vec4f> back(pixels);
  EXPECT_TRUE(PeerImages::download(d, pixels, &back[0].x, problem)) << problem;
  EXPECT_EQ(back[7].z, 0.75f);
  cudaFree(d);
  cudaFree(big);
}
#endif
