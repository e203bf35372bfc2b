// DistanceGrid's distance field on the device: the three passes of DistanceField.h, up to 8 threads
// a line per pass (distanceSegment) (the same distanceLine as the oneTBB build, so both fields agree).
#pragma once
#include "CudaCommon.cuh"
#include "spaceskip/Classification.h"
#include "spaceskip/Math.h"

#include <vector>

namespace spaceskip::cuda {

struct DistanceWorkspace {
  DeviceBuffer<uint8_t> a, b;  ///< ping-pong; the result is in `a`
};

/// Fills ws.a with the capped Chebyshev distance field of the occupancy `occ` (dims bricks);
/// returns ws.a's pointer. Synchronizes `stream`. `maxSegments` (Tuning::distanceSegments, 1..8)
/// caps the threads a line of the staged kernel uses.
const uint8_t* computeDistanceField(const uint8_t* occ, vec3i dims, int cap, DistanceWorkspace& ws,
                                    cudaStream_t stream, int maxSegments = 8);
/// The same from a host grid to a host field, on the default stream (for the tests).
std::vector<uint8_t> fieldOnDevice(const OccupancyGrid& occ, int cap);

}  // namespace spaceskip::cuda
