// Vector math that compiles as OpenCL C 1.2 and as C++17. On the device the built-in float2/3/4
// types and functions are used; on the host small structs with the same names and operators
// stand in, so kernel code in shared/ is also the CPU reference. Build vectors with
// make_float3(...) (OpenCL's (float3)(...) cast syntax is not C++).
#pragma once

#include "shared/common.h"

#define PR_PI 3.14159265358979323846f
#define PR_INV_PI 0.31830988618379067154f
#define PR_INF_F 3.402823466e+38f

#ifdef PR_DEVICE_CODE

#define make_float2(x, y) ((float2)((x), (y)))
#define make_float3(x, y, z) ((float3)((x), (y), (z)))
#define make_float4(x, y, z, w) ((float4)((x), (y), (z), (w)))
#define make_uint2(x, y) ((uint2)((x), (y)))
PR_INLINE float pr_as_float(u32 v) {
  return as_float(v);
}
PR_INLINE u32 pr_as_uint(float v) {
  return as_uint(v);
}

#else  // host

#include <algorithm>
#include <cmath>
#include <cstring>

PR_NAMESPACE_BEGIN

// float overloads, so host arithmetic matches the device's single precision.
using std::acos;
using std::asin;
using std::atan2;
using std::cos;
using std::exp;
using std::fabs;
using std::floor;
using std::fmax;
using std::fmin;
using std::log;
using std::pow;
using std::sin;
using std::sqrt;
using std::tan;

struct float2 {
  float x, y;
};
struct float3 {
  float x, y, z;
};
struct float4 {
  float x, y, z, w;
};
struct uint2 {
  u32 x, y;
};

inline float2 make_float2(float x, float y) {
  return float2{x, y};
}
inline float3 make_float3(float x, float y, float z) {
  return float3{x, y, z};
}
inline float4 make_float4(float x, float y, float z, float w) {
  return float4{x, y, z, w};
}
inline uint2 make_uint2(u32 x, u32 y) {
  return uint2{x, y};
}

inline float pr_as_float(u32 v) {
  float f;
  std::memcpy(&f, &v, sizeof f);
  return f;
}
inline u32 pr_as_uint(float f) {
  u32 v;
  std::memcpy(&v, &f, sizeof v);
  return v;
}

// float3
inline float3 operator+(float3 a, float3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline float3 operator-(float3 a, float3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline float3 operator*(float3 a, float3 b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
inline float3 operator/(float3 a, float3 b) {
  return {a.x / b.x, a.y / b.y, a.z / b.z};
}
inline float3 operator*(float3 a, float s) {
  return {a.x * s, a.y * s, a.z * s};
}
inline float3 operator*(float s, float3 a) {
  return {a.x * s, a.y * s, a.z * s};
}
inline float3 operator/(float3 a, float s) {
  return {a.x / s, a.y / s, a.z / s};
}
inline float3 operator-(float3 a) {
  return {-a.x, -a.y, -a.z};
}
inline float3& operator+=(float3& a, float3 b) {
  return a = a + b;
}
inline float3& operator-=(float3& a, float3 b) {
  return a = a - b;
}
inline float3& operator*=(float3& a, float3 b) {
  return a = a * b;
}
inline float3& operator*=(float3& a, float s) {
  return a = a * s;
}
inline float3& operator/=(float3& a, float s) {
  return a = a / s;
}
inline float dot(float3 a, float3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline float3 cross(float3 a, float3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(float3 a) {
  return std::sqrt(dot(a, a));
}
inline float rsqrt(float x) {
  return 1.0f / std::sqrt(x);
}
inline float3 normalize(float3 a) {
  const float l = length(a);
  return l > 0.0f ? a / l : a;
}
inline float3 fmin(float3 a, float3 b) {
  return {std::fmin(a.x, b.x), std::fmin(a.y, b.y), std::fmin(a.z, b.z)};
}
inline float3 fmax(float3 a, float3 b) {
  return {std::fmax(a.x, b.x), std::fmax(a.y, b.y), std::fmax(a.z, b.z)};
}
inline float3 fabs(float3 a) {
  return {std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)};
}
inline float3 sqrt(float3 a) {
  return {std::sqrt(a.x), std::sqrt(a.y), std::sqrt(a.z)};
}
inline float clamp(float v, float lo, float hi) {
  return std::fmin(std::fmax(v, lo), hi);
}
inline float3 clamp(float3 v, float lo, float hi) {
  return {clamp(v.x, lo, hi), clamp(v.y, lo, hi), clamp(v.z, lo, hi)};
}
inline float mix(float a, float b, float t) {
  return a + (b - a) * t;
}
inline float3 mix(float3 a, float3 b, float t) {
  return a + (b - a) * t;
}
inline int isfinite_f(float v) {
  return std::isfinite(v) ? 1 : 0;
}
// OpenCL's clz: leading zero bits, 32 for 0.
inline u32 clz(u32 x) {
  return x ? u32(__builtin_clz(x)) : 32u;
}

// float2
inline float2 operator+(float2 a, float2 b) {
  return {a.x + b.x, a.y + b.y};
}
inline float2 operator-(float2 a, float2 b) {
  return {a.x - b.x, a.y - b.y};
}
inline float2 operator*(float2 a, float s) {
  return {a.x * s, a.y * s};
}
inline float2 operator*(float s, float2 a) {
  return {a.x * s, a.y * s};
}

// float4
inline float4 operator+(float4 a, float4 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w};
}
inline float4 operator*(float4 a, float s) {
  return {a.x * s, a.y * s, a.z * s, a.w * s};
}

PR_NAMESPACE_END

#endif  // PR_DEVICE_CODE

PR_NAMESPACE_BEGIN

#ifdef PR_DEVICE_CODE
PR_INLINE int isfinite_f(float v) {
  return isfinite(v) ? 1 : 0;
}
PR_INLINE float pr_sincos(float x, float* c) {
  return sincos(x, c);
}
#else
inline float pr_sincos(float x, float* c) {
  *c = std::cos(x);
  return std::sin(x);
}
#endif

PR_INLINE float3 pr_load3(PR_GLOBAL const float* p) {
  return make_float3(p[0], p[1], p[2]);
}
PR_INLINE float max3(float3 v) {
  return fmax(v.x, fmax(v.y, v.z));
}
PR_INLINE float min3(float3 v) {
  return fmin(v.x, fmin(v.y, v.z));
}
PR_INLINE float luminance(float3 c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}
// Whether a normal was given (the zero vector stands for none).
PR_INLINE int has_normal(float3 n) {
  return n.x != 0.0f || n.y != 0.0f || n.z != 0.0f;
}

// An orthonormal basis around unit n (Duff et al. 2017, branchless).
PR_INLINE void orthonormal_basis(float3 n, float3* t, float3* b) {
  const float sign = n.z >= 0.0f ? 1.0f : -1.0f;
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  *t = make_float3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  *b = make_float3(c, sign + n.y * n.y * a, -n.y);
}

PR_NAMESPACE_END
