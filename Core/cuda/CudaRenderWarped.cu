// CudaExecutor::launch (CudaRenderLaunch.cuh) for rectilinear grids drawn through their
// coordinates (WarpedSampler, AxisWarp.h): one sampler for every voxel type, one of the render
// kernels' translation units, which compile in parallel.
#include "CudaRenderLaunch.cuh"

namespace spaceskip::cuda {

SPACESKIP_INSTANTIATE_LAUNCH(WarpedSampler)

}  // namespace spaceskip::cuda
