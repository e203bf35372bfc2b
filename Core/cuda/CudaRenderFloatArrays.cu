// CudaExecutor::launch (CudaRenderLaunch.cuh) for float voxels read exactly (ArraySampler) and
// every voxel type through the texture unit (TextureSampler): one of the render kernels'
// translation units, which compile in parallel.
#include "CudaRenderLaunch.cuh"

namespace spaceskip::cuda {

SPACESKIP_INSTANTIATE_LAUNCH(ArraySampler<float>)
SPACESKIP_INSTANTIATE_LAUNCH(ArraySampler<double>)
SPACESKIP_INSTANTIATE_LAUNCH(TextureSampler)

}  // namespace spaceskip::cuda
