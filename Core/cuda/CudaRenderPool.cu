// CudaExecutor::launch (CudaRenderLaunch.cuh) for sparse residency (PoolSampler: the resident
// bricks): one of the render kernels' translation units, which compile in parallel.
#include "CudaRenderLaunch.cuh"

namespace spaceskip::cuda {

SPACESKIP_INSTANTIATE_LAUNCH(PoolSampler<uint8_t>)
SPACESKIP_INSTANTIATE_LAUNCH(PoolSampler<int8_t>)
SPACESKIP_INSTANTIATE_LAUNCH(PoolSampler<uint16_t>)
SPACESKIP_INSTANTIATE_LAUNCH(PoolSampler<int16_t>)
SPACESKIP_INSTANTIATE_LAUNCH(PoolSampler<float>)
SPACESKIP_INSTANTIATE_LAUNCH(PoolSampler<double>)

}  // namespace spaceskip::cuda
