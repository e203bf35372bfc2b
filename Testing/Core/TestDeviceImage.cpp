// The image left on the device for CUDA-GL interop (Engine::setImageOnDevice): render() returns
// without waiting for the kernel, work queued on deviceImageStream() sees the finished frame (the
// same bits as the host image), its kernel time is read when asked for, and DeviceImageCopy
// writes a rectangle of it into a CUDA array as float4 or as RGBA8 rounded as the mapper's host
// path rounds, or blends it over an RGBA8 surface as GL's blend would. Skipped without a CUDA device.
#include "spaceskip/Backend.h"
#include "spaceskip/DeviceImageCopy.h"
#include "TestUtil.h"

#include <gtest/gtest.h>

#ifdef SPACESKIP_HAVE_CUDA
#include <cuda_runtime_api.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace spaceskip;

#ifdef SPACESKIP_HAVE_CUDA
namespace {

// The mapper's host rounding (vtkSpaceSkipCompositor::UploadHostImage).
unsigned char toByte(float s) {
  const float v = std::min(std::max(s, 0.f), 1.f);
  return static_cast<unsigned char>(v * 255.f + 0.5f);
}

// The device image `image` (w x h float4) as an Image, copied on `stream` behind what is queued.
bool download(const void* image, void* stream, int w, int h, Image& out) {
  out.width = w;
  out.height = h;
  out.rgba.resize(size_t(w) * size_t(h));
  const cudaStream_t s = static_cast<cudaStream_t>(stream);
  return cudaMemcpyAsync(out.rgba.data(), image, out.rgba.size() * sizeof(vec4f), cudaMemcpyDeviceToHost, s) ==
             cudaSuccess &&
         cudaStreamSynchronize(s) == cudaSuccess;
}

struct Scene {
  Volume v = generateVolume("nbody", vec3l{64, 64, 64}, 4);
  TransferFunction tf;
  Camera cam;
  Scene() {
    double lo, hi;
    v.scalarRange(lo, hi);
    tf = TransferFunction::preset("ramp", lo, hi);
    cam = test::orbit(v, 30, 20);
  }
};

}  // namespace

TEST(DeviceImage, StreamOrderedFrameEqualsTheHostImage) {
  SKIP_WITHOUT_CUDA();
  Scene s;
  const int w = 120, h = 90;
  for (BuilderKind k : {BuilderKind::Grid, BuilderKind::DistanceGrid}) {
    SCOPED_TRACE(builderName(k));
    Engine e(BackendKind::CUDA);
    test::load(e, s.v, s.tf, test::builder(k));
    Image host;
    e.render(s.cam, w, h, host);
    ASSERT_EQ(e.deviceImage(), nullptr);
    ASSERT_EQ(host.rgba.size(), size_t(w) * size_t(h));
    ASSERT_GT(test::coverage(host), 0.001);
    ASSERT_TRUE(e.setImageOnDevice(true));
    Image sized;
    e.render(s.cam, w, h, sized);
    EXPECT_EQ(sized.width, w);
    EXPECT_TRUE(sized.rgba.empty());
    const void* image = e.deviceImage();
    void* stream = e.deviceImageStream();
    ASSERT_NE(image, nullptr);
    ASSERT_NE(stream, nullptr);
    EXPECT_EQ(e.frameStats(false).deviceSeconds, -1.0) << "render() waited for the kernel";
    // Queued behind the kernel on the engine's stream: the finished frame.
    Image dev;
    ASSERT_TRUE(download(image, stream, w, h, dev));
    EXPECT_EQ(compareImages(host, dev).maxAbs, 0.f) << "the device image differs from the host image";
    EXPECT_GT(e.frameStats().deviceSeconds, 0.0) << "the kernel time, read on demand";

    // A rectangle into CUDA arrays (as into a mapped GL texture), 8-bit and float.
    const int x0 = 17, y0 = 9, rw = 71, rh = 58;
    DeviceImageCopy copy;
    for (bool eightBit : {true, false}) {
      SCOPED_TRACE(eightBit ? "RGBA8" : "float4");
      const cudaChannelFormatDesc desc = eightBit ? cudaCreateChannelDesc(8, 8, 8, 8, cudaChannelFormatKindUnsigned)
                                                  : cudaCreateChannelDesc(32, 32, 32, 32, cudaChannelFormatKindFloat);
      cudaArray_t array = nullptr;
      ASSERT_EQ(cudaMallocArray(&array, &desc, size_t(w), size_t(h)), cudaSuccess);
      EXPECT_EQ(copy.copy(image, w, h, array, x0, y0, rw, rh, eightBit, stream), 0);
      ASSERT_EQ(cudaStreamSynchronize(static_cast<cudaStream_t>(stream)), cudaSuccess);
      const size_t texel = eightBit ? 4 : sizeof(vec4f);
      std::vector<unsigned char> back(size_t(rw) * size_t(rh) * texel);
      ASSERT_EQ(cudaMemcpy2DFromArray(back.data(), size_t(rw) * texel, array, size_t(x0) * texel, size_t(y0),
                                      size_t(rw) * texel, size_t(rh), cudaMemcpyDeviceToHost),
                cudaSuccess);
      cudaFreeArray(array);
      int bad = 0;
      for (int y = 0; y < rh; ++y)
        for (int x = 0; x < rw; ++x) {
          const vec4f& c = host.rgba[size_t(y0 + y) * size_t(w) + size_t(x0 + x)];
          const size_t o = (size_t(y) * size_t(rw) + size_t(x)) * texel;
          if (eightBit) {
            const unsigned char want[4] = {toByte(c.x), toByte(c.y), toByte(c.z), toByte(c.w)};
            bad += !std::equal(want, want + 4, back.data() + o);
          } else {
            bad += std::memcmp(&c, back.data() + o, sizeof(vec4f)) != 0;
          }
        }
      EXPECT_EQ(bad, 0) << "texels differing from the host image (rounded as the host path rounds)";
    }
    // A rectangle outside the image is refused, not written.
    cudaArray_t array = nullptr;
    const cudaChannelFormatDesc desc = cudaCreateChannelDesc(8, 8, 8, 8, cudaChannelFormatKindUnsigned);
    ASSERT_EQ(cudaMallocArray(&array, &desc, size_t(w), size_t(h)), cudaSuccess);
    EXPECT_NE(copy.copy(image, w, h, array, w - 10, 0, 11, 5, true, stream), 0);
    cudaFreeArray(array);

    // Blended over an RGBA8 "framebuffer" larger than the image, at an offset (the viewport's
    // origin): within the rectangle GL's (ONE, ONE_MINUS_SRC_ALPHA) over the background, rounded
    // to the nearest 1/255 (here computed in double: at most 1/255 apart where float rounding
    // lands on the other side of a half), elsewhere and under transparent pixels the background.
    const int fw = w + 40, fh = h + 30, dx = 23, dy = 11;
    std::vector<unsigned char> background(size_t(fw) * size_t(fh) * 4);
    for (size_t i = 0; i < background.size(); ++i) background[i] = static_cast<unsigned char>((i * 7919u) >> 3);
    for (bool eightBit : {true, false}) {
      SCOPED_TRACE(eightBit ? "blend, 8-bit source" : "blend, float source");
      cudaArray_t target = nullptr;
      ASSERT_EQ(cudaMallocArray(&target, &desc, size_t(fw), size_t(fh), cudaArraySurfaceLoadStore), cudaSuccess);
      ASSERT_EQ(cudaMemcpy2DToArray(target, 0, 0, background.data(), size_t(fw) * 4, size_t(fw) * 4, size_t(fh),
                                    cudaMemcpyHostToDevice),
                cudaSuccess);
      EXPECT_EQ(copy.blendOver(image, w, h, target, fw, fh, x0, y0, rw, rh, dx, dy, eightBit, stream), 0);
      ASSERT_EQ(cudaStreamSynchronize(static_cast<cudaStream_t>(stream)), cudaSuccess);
      std::vector<unsigned char> back(background.size());
      ASSERT_EQ(cudaMemcpy2DFromArray(back.data(), size_t(fw) * 4, target, 0, 0, size_t(fw) * 4, size_t(fh),
                                      cudaMemcpyDeviceToHost),
                cudaSuccess);
      int far = 0, near = 0, outside = 0, covered = 0;
      for (int ty = 0; ty < fh; ++ty)
        for (int tx = 0; tx < fw; ++tx) {
          const size_t o = (size_t(ty) * size_t(fw) + size_t(tx)) * 4;
          const int ix = tx - dx, iy = ty - dy;
          if (ix < x0 || ix >= x0 + rw || iy < y0 || iy >= y0 + rh) {
            outside += !std::equal(back.begin() + o, back.begin() + o + 4, background.begin() + o);
            continue;
          }
          const vec4f& c = host.rgba[size_t(iy) * size_t(w) + size_t(ix)];
          const float src[4] = {c.x, c.y, c.z, c.w};
          double sv[4];
          for (int i = 0; i < 4; ++i)
            sv[i] = eightBit ? toByte(src[i]) / 255.0 : std::min(std::max(double(src[i]), 0.0), 1.0);
          covered += c.w > 0.f;
          for (int i = 0; i < 4; ++i) {
            const double want = std::min(1.0, sv[i] + background[o + i] / 255.0 * (1.0 - sv[3])) * 255.0 + 0.5;
            const int diff = std::abs(int(back[o + i]) - int(std::floor(want)));
            far += diff > 1;
            near += diff == 1;
          }
        }
      // A rectangle that does not fit the target is refused.
      EXPECT_NE(copy.blendOver(image, w, h, target, fw, fh, 0, 0, 11, 5, fw - 10, 0, eightBit, stream), 0);
      cudaFreeArray(target);
      EXPECT_GT(covered, 100) << "the rectangle should hold part of the volume";
      EXPECT_EQ(outside, 0) << "texels outside the rectangle were written";
      EXPECT_EQ(far, 0) << "channels more than 1/255 from the blend";
      EXPECT_LE(near, rw * rh / 50) << "channels 1/255 off: more than rounding ties explain";
    }
  }
}

TEST(DeviceImage, LayersBlendLikeTheFlatImage) {
  // A segmented frame left on the device keeps its layers (Engine::deviceImageView) until the
  // flat image is asked for (Engine::deviceImage composites them then); the CUDA blend composites
  // the layers as it reads them. Both blends must write the same texels bit for bit, and the
  // flat image must equal the host image. 4 segments forced (rays this short are whole by
  // default; Tuning::raySegments), the box's rectangle with flags.
  SKIP_WITHOUT_CUDA();
  Scene s;
  const int w = 120, h = 90;
  Tuning segmented;
  segmented.raySegments = 4;
  const cudaChannelFormatDesc desc = cudaCreateChannelDesc(8, 8, 8, 8, cudaChannelFormatKindUnsigned);
  {
    for (bool eightBit : {true, false}) {
      SCOPED_TRACE(eightBit ? "8-bit" : "float");
      Engine e(BackendKind::CUDA);
      e.setTuning(segmented);
      test::load(e, s.v, s.tf, test::builder(BuilderKind::DistanceGrid));
      Image host;
      e.render(s.cam, w, h, host);
      ASSERT_TRUE(e.setImageOnDevice(true));
      Image sized;
      e.render(s.cam, w, h, sized);
      const DeviceImageView view = e.deviceImageView();
      ASSERT_NE(view.image, nullptr);
      ASSERT_NE(view.layers.layers, nullptr) << "the layers were composited before anyone asked";
      EXPECT_EQ(view.layers.segments, 4);
      void* stream = e.deviceImageStream();
      ASSERT_NE(stream, nullptr);
      std::vector<unsigned char> background(size_t(w) * size_t(h) * 4);
      for (size_t i = 0; i < background.size(); ++i) background[i] = static_cast<unsigned char>((i * 7919u) >> 3);
      std::vector<unsigned char> back[2];
      DeviceImageCopy copy;
      for (int pass = 0; pass < 2; ++pass) {
        cudaArray_t target = nullptr;
        ASSERT_EQ(cudaMallocArray(&target, &desc, size_t(w), size_t(h), cudaArraySurfaceLoadStore), cudaSuccess);
        ASSERT_EQ(cudaMemcpy2DToArray(target, 0, 0, background.data(), size_t(w) * 4, size_t(w) * 4, size_t(h),
                                      cudaMemcpyHostToDevice),
                  cudaSuccess);
        if (pass == 0) {
          EXPECT_EQ(copy.blendOver(view, w, h, target, w, h, 3, 2, w - 5, h - 4, 0, 0, eightBit, stream), 0);
        } else {
          const void* flat = e.deviceImage();  // composites the layers now
          ASSERT_NE(flat, nullptr);
          EXPECT_EQ(e.deviceImageView().layers.layers, nullptr) << "the layers are composited once";
          EXPECT_EQ(copy.blendOver(flat, w, h, target, w, h, 3, 2, w - 5, h - 4, 0, 0, eightBit, stream), 0);
          Image dev;
          ASSERT_TRUE(download(flat, stream, w, h, dev));
          EXPECT_EQ(compareImages(host, dev).maxAbs, 0.f) << "the composited layers differ from the host image";
        }
        ASSERT_EQ(cudaStreamSynchronize(static_cast<cudaStream_t>(stream)), cudaSuccess);
        back[pass].resize(background.size());
        ASSERT_EQ(cudaMemcpy2DFromArray(back[pass].data(), size_t(w) * 4, target, 0, 0, size_t(w) * 4, size_t(h),
                                        cudaMemcpyDeviceToHost),
                  cudaSuccess);
        cudaFreeArray(target);
      }
      EXPECT_NE(back[0], background) << "the blend should colour some texels";
      EXPECT_EQ(back[0], back[1]) << "the blend from the layers differs from the blend of the flat image";
    }
  }
}
#endif
