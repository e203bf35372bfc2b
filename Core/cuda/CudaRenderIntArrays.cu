// CudaExecutor::launch (CudaRenderLaunch.cuh) for integer voxels read exactly (ArraySampler):
// one of the render kernels' translation units, which compile in parallel.
#include "CudaRenderLaunch.cuh"

namespace spaceskip::cuda {

SPACESKIP_INSTANTIATE_LAUNCH(ArraySampler<uint8_t>)
SPACESKIP_INSTANTIATE_LAUNCH(ArraySampler<int8_t>)
SPACESKIP_INSTANTIATE_LAUNCH(ArraySampler<uint16_t>)
SPACESKIP_INSTANTIATE_LAUNCH(ArraySampler<int16_t>)

}  // namespace spaceskip::cuda
