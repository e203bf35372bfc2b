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
