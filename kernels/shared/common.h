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
#define PR_INLINE inline
#define PR_NAMESPACE_BEGIN
#define PR_NAMESPACE_END
#define PR_STATIC_ASSERT(cond, msg)
#else
#include <cstddef>
#include <cstdint>
#define PR_GLOBAL
#define PR_CONSTANT
#define PR_INLINE inline
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
