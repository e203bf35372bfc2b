// CudaExecutor::launch (CudaRenderLaunch.cuh) for dependent components (ChannelSampler) and
// nearest or label sampling (NearestSampler): one of the render kernels' translation units,
// which compile in parallel.
#include "CudaRenderLaunch.cuh"

namespace spaceskip::cuda {

SPACESKIP_INSTANTIATE_LAUNCH(ChannelSampler<uint8_t>)
SPACESKIP_INSTANTIATE_LAUNCH(ChannelSampler<int8_t>)
SPACESKIP_INSTANTIATE_LAUNCH(ChannelSampler<uint16_t>)
SPACESKIP_INSTANTIATE_LAUNCH(ChannelSampler<int16_t>)
SPACESKIP_INSTANTIATE_LAUNCH(ChannelSampler<float>)
SPACESKIP_INSTANTIATE_LAUNCH(ChannelSampler<double>)
SPACESKIP_INSTANTIATE_LAUNCH(NearestSampler<uint8_t>)
SPACESKIP_INSTANTIATE_LAUNCH(NearestSampler<int8_t>)
SPACESKIP_INSTANTIATE_LAUNCH(NearestSampler<uint16_t>)
SPACESKIP_INSTANTIATE_LAUNCH(NearestSampler<int16_t>)
SPACESKIP_INSTANTIATE_LAUNCH(NearestSampler<float>)
SPACESKIP_INSTANTIATE_LAUNCH(NearestSampler<double>)

}  // namespace spaceskip::cuda
