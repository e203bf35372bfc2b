// SIMD ray packets for the oneTBB backend (host only, never seen by nvcc): several pixels' rays
// marched in the lanes of one SIMD vector, the instruction set picked at run time (Highway's
// dynamic dispatch: SSSE3 ... AVX2, AVX-512). Each lane takes exactly the samples the shared
// per-ray integrator takes (render/Integrator.h, renderPixel) with the same float operations in
// the same order, so the image is the scalar integrator's, bit for bit; the lanes only run side
// by side, which hides the latency of one ray's compositing chain and its voxel fetches.
// Without Highway (SPACESKIP_HAVE_HWY undefined) nothing qualifies and the scalar path runs.
#pragma once
#include "spaceskip/Volume.h"
#include "spaceskip/render/FrameShared.h"

#include <cstdint>
#include <vector>

namespace spaceskip {

/// Whether marchPacketTile renders frame `f` over a volume of this type and shape: composite
/// frames, with or without clipping planes and cropping, unshaded or shaded with the headlight
/// or directional lights (ParaView's light kit), without positional lights, scattering or 2-D
/// functions, with any traversal (each lane walks its own ray's runs with
/// the shared iterators, Traversal.h, as IntervalMarcher::marchRuns does), serial (no piece),
/// no incoming opacity, no sample counts; one component of 8- or 16-bit integers or float32,
/// every axis at least 2 voxels, fewer than 2^31 voxel bytes (32-bit gather offsets). Else the
/// scalar integrator.
bool packetMarchable(const FrameView& f, VoxelType type, int components, int64_t nx, int64_t ny, int64_t nz);

/// The frame's table as the packets read it: per channel (r, g, b, a) and entry i the pair
/// (entry i, entry min(i + 1, size - 1)), so one 64-bit load fetches both ends of a lookup.
void packetPairTable(const TransferFunctionView& tf, std::vector<float>& pairs);

/// Renders pixels [x0, x1) x [y0, y1) of a frame packetMarchable accepted into `px` (row-major,
/// f.width wide), each pixel as renderPixel<ArraySampler<T>> does. `pairs`:
/// packetPairTable(f.tf).
void marchPacketTile(const FrameView& f, const float* pairs, VoxelType type, const void* voxels, int64_t nx,
                     int64_t ny, int64_t nz, int x0, int y0, int x1, int y1, vec4f* px);

/// The instruction set the packets run on this machine ("AVX2", "AVX3", ...), "none" without
/// Highway.
const char* packetTarget();

}  // namespace spaceskip
