// How the CUDA backend launches its render kernels: plain data the caller sets (the CLI from its
// options), instead of environment variables read behind its back. The CPU backend ignores it.
#pragma once

namespace spaceskip {

/// Each field's default leaves the choice to the backend. For measurement scripts written against
/// the old knobs (Testing/gpu/run-gpu.sh), the environment still overrides a field left at its
/// default: SPACESKIP_CUDA_BLOCK=WxH and SPACESKIP_CUDA_CARVEOUT=N (read when the backend is
/// made), SPACESKIP_CUDA_RESIDENT=N (read per frame).
struct LaunchParams {
  /// Threads per block of the render kernels, W x H with 32 <= W*H <= 256; 0: 16x8.
  int blockX = 0, blockY = 0;
  /// Percent of the unified L1 / shared memory given to shared memory (0..100, 0 = largest L1);
  /// -1: the driver's choice.
  int carveout = -1;
  /// Persistent launch: N resident blocks per SM take tiles from a counter; 0: one block per tile
  /// (the plain launch); -1: automatic (persistent for hardware-filtered volumes above 2 GiB).
  int resident = -1;
};

}  // namespace spaceskip
