// DeviceImageCopy: the device image into a mapped GL texture's array, as float4 texels (a
// strided copy) or as RGBA8 (a rounding kernel into scratch memory, then the copy: a quarter of
// the bytes for the compositing draw to read).
#include "CudaCommon.cuh"
#include "spaceskip/DeviceImageCopy.h"

namespace spaceskip {

namespace {

// Rounds as the mapper's host path does (vtkSpaceSkipCompositor::UploadHostImage: clamp,
// v * 255 + 0.5, truncate); __fmul_rn/__fadd_rn keep the multiply and the add apart, as the host
// computes them.
__device__ unsigned char roundTo8(float v) {
  v = fminf(fmaxf(v, 0.f), 1.f);
  return static_cast<unsigned char>(static_cast<unsigned>(__fadd_rn(__fmul_rn(v, 255.f), 0.5f)));
}

// Launch shape (both kernels): 2-D grid of 32x8 blocks over the w x h rectangle, one thread per pixel.
__global__ void roundToRgba8Kernel(const float4* image, int imageWidth, int x0, int y0, int w, int h, uchar4* out) {
  const int x = int(blockIdx.x * blockDim.x + threadIdx.x), y = int(blockIdx.y * blockDim.y + threadIdx.y);
  if (x >= w || y >= h) return;
  const float4 c = image[int64_t(y0 + y) * imageWidth + (x0 + x)];
  out[int64_t(y) * w + x] = make_uchar4(roundTo8(c.x), roundTo8(c.y), roundTo8(c.z), roundTo8(c.w));
}

// Premultiplied "over" into RGBA8 surface texels at (x0 + x + dx, y0 + y + dy): what GL's blend
// (ONE, ONE_MINUS_SRC_ALPHA) writes into an 8-bit normalized colour buffer.
// With the view's layers (a segmented frame not composited into the flat image), each pixel is
// composited from them here (compositeLayers): the same colour, no flat image written or read.
__global__ void blendOverKernel(const DeviceImageView src, int imageWidth, int x0, int y0, int w, int h, int dx,
                                int dy, bool eightBit, cudaSurfaceObject_t target) {
  const int x = int(blockIdx.x * blockDim.x + threadIdx.x), y = int(blockIdx.y * blockDim.y + threadIdx.y);
  if (x >= w || y >= h) return;
  const vec4f c = src.layers.layers ? compositeLayers(src.layers, x0 + x, y0 + y)
                                    : static_cast<const vec4f*>(src.image)[int64_t(y0 + y) * imageWidth + (x0 + x)];
  if (c.x == 0.f && c.y == 0.f && c.z == 0.f && c.w == 0.f) return;  // d' = d
  auto source = [eightBit](float v) {
    return eightBit ? float(roundTo8(v)) * (1.f / 255.f) : fminf(fmaxf(v, 0.f), 1.f);
  };
  const float s[4] = {source(c.x), source(c.y), source(c.z), source(c.w)};
  const int tx = x0 + x + dx, ty = y0 + y + dy;
  const uchar4 d = surf2Dread<uchar4>(target, tx * int(sizeof(uchar4)), ty);
  const unsigned char dv[4] = {d.x, d.y, d.z, d.w};
  unsigned char o[4];
  const float keep = 1.f - s[3];
  for (int i = 0; i < 4; ++i) o[i] = roundTo8(fmaf(float(dv[i]) * (1.f / 255.f), keep, s[i]));
  surf2Dwrite(make_uchar4(o[0], o[1], o[2], o[3]), target, tx * int(sizeof(uchar4)), ty);
}

}  // namespace

struct DeviceImageCopy::Impl {
  cuda::DeviceBuffer<uchar4> scratch;  ///< the rounded rectangle (eightBit)
  cudaStream_t lastStream = nullptr;
  bool used = false;
  // blendOver's surface of the last array (a mapped texture keeps its array from map to map).
  cudaArray_t surfaceArray = nullptr;
  cudaSurfaceObject_t surface = 0;

  /// Another stream than the last call's (a new engine): the last call's work may still use the
  /// scratch memory or the surface.
  cudaError_t useStream(cudaStream_t s) {
    if (used && s != lastStream) {
      const cudaError_t e = cudaDeviceSynchronize();
      if (e != cudaSuccess) return e;
    }
    lastStream = s;
    used = true;
    return cudaSuccess;
  }
};

DeviceImageCopy::DeviceImageCopy() : impl_(new Impl) {}

DeviceImageCopy::~DeviceImageCopy() {
  if (impl_->used) cudaDeviceSynchronize();  // a queued copy may still read the scratch memory
  if (impl_->surface) cudaDestroySurfaceObject(impl_->surface);
  (void)cudaGetLastError();
}

int DeviceImageCopy::copy(const void* image, int imageWidth, int imageHeight, void* array, int x0, int y0, int w,
                          int h, bool eightBit, void* stream) {
  if (!image || !array || x0 < 0 || y0 < 0 || w <= 0 || h <= 0 || x0 + w > imageWidth || y0 + h > imageHeight)
    return int(cudaErrorInvalidValue);
  Impl& d = *impl_;
  const cudaStream_t s = static_cast<cudaStream_t>(stream);
  if (const cudaError_t e = d.useStream(s); e != cudaSuccess) return int(e);
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

int DeviceImageCopy::blendOver(const void* image, int imageWidth, int imageHeight, void* array, int arrayWidth,
                               int arrayHeight, int x0, int y0, int w, int h, int dx, int dy, bool eightBit,
                               void* stream) {
  DeviceImageView v;
  v.image = image;
  return blendOver(v, imageWidth, imageHeight, array, arrayWidth, arrayHeight, x0, y0, w, h, dx, dy, eightBit, stream);
}

int DeviceImageCopy::blendOver(const DeviceImageView& image, int imageWidth, int imageHeight, void* array,
                               int arrayWidth, int arrayHeight, int x0, int y0, int w, int h, int dx, int dy,
                               bool eightBit, void* stream) {
  const bool layered = image.layers.layers != nullptr;
  if ((!image.image && !layered) ||
      (layered && (image.layers.width != imageWidth || image.layers.height != imageHeight)) || !array || x0 < 0 ||
      y0 < 0 || w <= 0 || h <= 0 || x0 + w > imageWidth || y0 + h > imageHeight || x0 + dx < 0 || y0 + dy < 0 || x0 + dx + w > arrayWidth || y0 + dy + h > arrayHeight)
    return int(cudaErrorInvalidValue);
  Impl& d = *impl_;
  const cudaStream_t s = static_cast<cudaStream_t>(stream);
  if (const cudaError_t e = d.useStream(s); e != cudaSuccess) return int(e);
  const cudaArray_t a = static_cast<cudaArray_t>(array);
  if (a != d.surfaceArray) {
    releaseSurface();
    cudaResourceDesc r{};
    r.resType = cudaResourceTypeArray;
    r.res.array.array = a;
    if (const cudaError_t e = cudaCreateSurfaceObject(&d.surface, &r); e != cudaSuccess) return int(e);
    d.surfaceArray = a;
  }
  const dim3 block(32, 8);
  const dim3 grid(unsigned((w + 31) / 32), unsigned((h + 7) / 8));
  blendOverKernel<<<grid, block, 0, s>>>(image, imageWidth, x0, y0, w, h, dx, dy, eightBit, d.surface);
  return int(cudaPeekAtLastError());
}

void DeviceImageCopy::releaseSurface() {
  Impl& d = *impl_;
  if (!d.surface) return;
  cudaDeviceSynchronize();  // a queued blend may still write through it
  cudaDestroySurfaceObject(d.surface);
  (void)cudaGetLastError();
  d.surface = 0;
  d.surfaceArray = nullptr;
}

}  // namespace spaceskip
