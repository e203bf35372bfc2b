// One host/device macro for code shared by the oneTBB and CUDA executors (cf. NanoVDB __hostdev__).
#pragma once

#if defined(__CUDACC__)
#define SS_HOSTDEV __host__ __device__
#define SS_INLINE __forceinline__
#else
#define SS_HOSTDEV
#define SS_INLINE inline
#endif

#define SS_FUNC SS_HOSTDEV SS_INLINE

/// SS_FUNC inlined by the host compiler as well, for small functions of the per-sample loops
/// that gcc keeps out of line in large callers (a trilinear sample inside the shadow rays' march).
#if defined(__CUDACC__)
#define SS_FORCE_FUNC SS_FUNC
#else
#define SS_FORCE_FUNC inline __attribute__((always_inline))
#endif

/// A shared function kept out of line on the GPU (one copy per template instance instead of one
/// in every kernel that calls it): for rarely taken, large paths such as scattering's shadow rays.
#if defined(__CUDACC__)
#define SS_NOINLINE_FUNC __host__ __device__ __noinline__
#else
#define SS_NOINLINE_FUNC
#endif
