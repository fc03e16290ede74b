// The C subset shared by host (C++17) and kernels (OpenCL C 1.2): fixed-width scalar names and
// the qualifiers that differ between the two. Host code sees everything in namespace pr::dev.
#pragma once

#ifdef __OPENCL_C_VERSION__
#define PR_DEVICE_CODE 1
typedef uint u32;
typedef int i32;
typedef ulong u64;
#define PR_GLOBAL __global
#define PR_CONSTANT __constant
#define PR_TABLE __constant  // a table at program scope
// Helpers are inlined. Intel's OpenCL CPU compiler (2026.2) miscompiles an out-of-line function
// that passes a float3, by value or inside a struct it points to, once it vectorises across
// work-items (lanes read their float3 at a 16-byte stride where 12 were written). PR_CALLABLE
// marks the few large functions that may stay out of line, where inlining every call site would
// multiply compile time: their parameters and results must hold no float3. `static`: C99
// `inline` alone promises an external definition that no kernel file provides.
#define PR_INLINE static inline __attribute__((always_inline))
#define PR_CALLABLE static inline
#define PR_NAMESPACE_BEGIN
#define PR_NAMESPACE_END
// The host checks the layouts; here the assertion is an empty declaration that takes its `;`
// (C99 has no stray `;` at file scope).
#define PR_STATIC_ASSERT(cond, msg) struct pr_static_assert_
// Every kernel: one work-item's computation already uses float4 (BVH slabs, triangle packets),
// so a compiler should not pack work-items into vector lanes (OpenCL 1.2 6.7.2). Intel's CPU
// compiler heeds the hint: packing lanes made connect 8x and the whole reuse frame 4.4x slower
// (divergent paths) and its compile 10x longer (220 s). PoCL and GPU compilers ignore it.
#define PR_KERNEL __kernel __attribute__((vec_type_hint(float4)))
#else
#include <cstddef>
#include <cstdint>
#define PR_GLOBAL
#define PR_CONSTANT
#define PR_TABLE inline const
#define PR_INLINE inline
#define PR_CALLABLE inline
#define PR_NAMESPACE_BEGIN \
  namespace pr {           \
  namespace dev {
#define PR_NAMESPACE_END \
  }                      \
  }
#define PR_STATIC_ASSERT(cond, msg) static_assert(cond, msg)
PR_NAMESPACE_BEGIN
typedef uint32_t u32;
typedef int32_t i32;
typedef uint64_t u64;
PR_NAMESPACE_END
#endif

// Internal invariants of the shared code (host/util/check.h's PR_CHECK for the host): the
// host's CPU reference, which runs this code in the tests, checks them and aborts on a failed
// one. Kernels compile them out: OpenCL C 1.2 has no way to stop a kernel, and a printf in the
// traversal loop crashed PoCL 3.1's work-group compiler.
#ifdef PR_DEVICE_CODE
#define PR_KCHECK(cond) ((void)0)
#else
#include <cstdio>
#include <cstdlib>
#define PR_KCHECK(cond)                                                                     \
  ((cond) ? (void)0                                                                         \
          : (std::fprintf(stderr, "pathreuse: check failed: %s (%s:%d)\n", #cond, __FILE__, \
                          __LINE__),                                                        \
             std::abort()))
#endif

#ifdef PR_DEVICE_CODE
// --noise-threshold's mask (PR_ARGS_PIXEL_MASK): whether pixel px takes pass `sample`.
PR_INLINE int pixel_takes_pass(__global const uint* budget, uint masked, uint px, uint sample) {
  return !masked || sample < budget[px];
}
#endif
