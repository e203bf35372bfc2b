// DistanceGrid's distance field on the device: the three passes of DistanceField.h, one thread
// per brick per pass (the same per-brick function as the oneTBB build, so both fields agree).
#pragma once
#include "CudaCommon.cuh"
#include "spaceskip/Math.h"

namespace spaceskip::cuda {

struct DistanceWorkspace {
  DeviceBuffer<uint8_t> a, b;  ///< ping-pong; the result is in `b`
};

/// Fills ws.b with the capped Chebyshev distance field of the occupancy `occ` (dims bricks);
/// returns ws.b's pointer. Synchronizes `stream`.
const uint8_t* computeDistanceField(const uint8_t* occ, vec3i dims, int cap, DistanceWorkspace& ws,
                                    cudaStream_t stream);

}  // namespace spaceskip::cuda
