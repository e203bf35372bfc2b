// DeviceImageCopy: the device image into a mapped GL texture's array, as float4 texels (a
// strided copy) or as RGBA8 (a rounding kernel into scratch memory, then the copy: a quarter of
// the bytes for the compositing draw to read).
#include "CudaCommon.cuh"
#include "spaceskip/DeviceImageCopy.h"

namespace spaceskip {

namespace {

// Launch shape: 2-D grid of 32x8 blocks over the w x h rectangle, one thread per pixel. Rounds
// as the mapper's host path does (vtkSpaceSkipCompositor::UploadHostImage: clamp, v * 255 + 0.5,
// truncate); __fmul_rn/__fadd_rn keep the multiply and the add apart, as the host computes them.
__global__ void roundToRgba8Kernel(const float4* image, int imageWidth, int x0, int y0, int w, int h, uchar4* out) {
  const int x = int(blockIdx.x * blockDim.x + threadIdx.x), y = int(blockIdx.y * blockDim.y + threadIdx.y);
  if (x >= w || y >= h) return;
  const float4 c = image[int64_t(y0 + y) * imageWidth + (x0 + x)];
  auto q = [](float v) {
    v = fminf(fmaxf(v, 0.f), 1.f);
    return static_cast<unsigned char>(static_cast<unsigned>(__fadd_rn(__fmul_rn(v, 255.f), 0.5f)));
  };
  out[int64_t(y) * w + x] = make_uchar4(q(c.x), q(c.y), q(c.z), q(c.w));
}

}  // namespace

struct DeviceImageCopy::Impl {
  cuda::DeviceBuffer<uchar4> scratch;  ///< the rounded rectangle (eightBit)
  cudaStream_t lastStream = nullptr;
  bool used = false;
};

DeviceImageCopy::DeviceImageCopy() : impl_(new Impl) {}

DeviceImageCopy::~DeviceImageCopy() {
  if (impl_->used) cudaDeviceSynchronize();  // a queued copy may still read the scratch memory
  (void)cudaGetLastError();
}

int DeviceImageCopy::copy(const void* image, int imageWidth, int imageHeight, void* array, int x0, int y0, int w,
                          int h, bool eightBit, void* stream) {
  if (!image || !array || x0 < 0 || y0 < 0 || w <= 0 || h <= 0 || x0 + w > imageWidth || y0 + h > imageHeight)
    return int(cudaErrorInvalidValue);
  Impl& d = *impl_;
  const cudaStream_t s = static_cast<cudaStream_t>(stream);
  // Another stream (a new engine): the scratch memory may still be read by the old one's copy.
  if (d.used && s != d.lastStream) {
    const cudaError_t e = cudaDeviceSynchronize();
    if (e != cudaSuccess) return int(e);
  }
  d.lastStream = s;
  d.used = true;
  const cudaArray_t a = static_cast<cudaArray_t>(array);
  const auto* src = static_cast<const float4*>(image);
  if (!eightBit) {
    const size_t row = size_t(imageWidth) * sizeof(float4);
    return int(cudaMemcpy2DToArrayAsync(a, size_t(x0) * sizeof(float4), size_t(y0), src + int64_t(y0) * imageWidth + x0,
                                        row, size_t(w) * sizeof(float4), size_t(h), cudaMemcpyDeviceToDevice, s));
  }
  try {
    // The whole image's size, not the rectangle's: the memory held stays put while the view moves.
    d.scratch.reserve(size_t(imageWidth) * size_t(imageHeight));
  } catch (const BackendError&) {
    return int(cudaErrorMemoryAllocation);
  }
  const dim3 block(32, 8);
  const dim3 grid(unsigned((w + 31) / 32), unsigned((h + 7) / 8));
  roundToRgba8Kernel<<<grid, block, 0, s>>>(src, imageWidth, x0, y0, w, h, d.scratch.get());
  const cudaError_t e = cudaPeekAtLastError();
  if (e != cudaSuccess) return int(e);
  const size_t row = size_t(w) * sizeof(uchar4);
  return int(cudaMemcpy2DToArrayAsync(a, size_t(x0) * sizeof(uchar4), size_t(y0), d.scratch.get(), row, row,
                                      size_t(h), cudaMemcpyDeviceToDevice, s));
}

}  // namespace spaceskip
