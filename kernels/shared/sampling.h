// Sampling routines shared by kernels and host tests: directions, points on triangles. The
// MIS weights, power_heuristic among them, are in shared/mis.h (included here for its users).
#pragma once

#include "shared/math.h"
#include "shared/mis.h"

PR_NAMESPACE_BEGIN

// Cosine-weighted direction around +Z (local frame); pdf = cos(theta) / pi.
PR_INLINE float3 sample_cosine_hemisphere(float u1, float u2) {
  // Concentric mapping keeps strata compact (Shirley and Chiu 1997).
  const float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
  float r = 0.0f, phi = 0.0f;
  if (a != 0.0f || b != 0.0f) {
    if (a * a > b * b) {
      r = a;
      phi = (PR_PI / 4.0f) * (b / a);
    } else {
      r = b;
      phi = (PR_PI / 2.0f) - (PR_PI / 4.0f) * (a / b);
    }
  }
  const float x = r * cos(phi), y = r * sin(phi);
  const float z = sqrt(fmax(0.0f, 1.0f - x * x - y * y));
  return make_float3(x, y, z);
}

// Uniform direction on the hemisphere around +Z; pdf = 1 / (2 pi).
PR_INLINE float3 sample_uniform_hemisphere(float u1, float u2) {
  const float z = u1, r = sqrt(fmax(0.0f, 1.0f - z * z)), phi = 2.0f * PR_PI * u2;
  return make_float3(r * cos(phi), r * sin(phi), z);
}

// Uniform direction on the unit sphere; pdf = 1 / (4 pi).
PR_INLINE float3 sample_uniform_sphere(float u1, float u2) {
  const float z = 1.0f - 2.0f * u1;
  const float r = sqrt(fmax(0.0f, 1.0f - z * z));
  const float phi = 2.0f * PR_PI * u2;
  return make_float3(r * cos(phi), r * sin(phi), z);
}

// Uniform direction in a cone around +Z with cos of the half-angle cos_max; pdf =
// 1/(2pi(1-cos_max)).
PR_INLINE float3 sample_uniform_cone(float u1, float u2, float cos_max) {
  const float cos_t = 1.0f - u1 * (1.0f - cos_max);
  const float sin_t = sqrt(fmax(0.0f, 1.0f - cos_t * cos_t));
  const float phi = 2.0f * PR_PI * u2;
  return make_float3(sin_t * cos(phi), sin_t * sin(phi), cos_t);
}

// x in [0, 1) with density proportional to (1 - x) a + x b (a, b >= 0, not both 0): the root of
// the CDF's quadratic in a form without cancellation.
PR_INLINE float sample_linear(float u, float a, float b) {
  if (u == 0.0f && a == 0.0f) return 0.0f;
  const float x = u * (a + b) / (a + sqrt(fmax(0.0f, (1.0f - u) * a * a + u * b * b)));
  return fmin(x, 0.99999994f);
}

// A point of [0, 1)^2 with density proportional to the bilinear interpolation of the corner
// values w00 (at (0, 0)), w10, w01 and w11; and that density.
PR_INLINE float2 sample_bilinear(float u1, float u2, float w00, float w10, float w01, float w11) {
  const float y = sample_linear(u2, w00 + w10, w01 + w11);
  const float x = sample_linear(u1, w00 + (w01 - w00) * y, w10 + (w11 - w10) * y);
  return make_float2(x, y);
}
PR_INLINE float bilinear_pdf(float2 p, float w00, float w10, float w01, float w11) {
  const float sum = w00 + w10 + w01 + w11;
  if (!(sum > 0.0f)) return 1.0f;
  return 4.0f *
         ((1.0f - p.x) * (1.0f - p.y) * w00 + p.x * (1.0f - p.y) * w10 + (1.0f - p.x) * p.y * w01 +
          p.x * p.y * w11) /
         sum;
}

// Barycentrics (b1, b2) of a uniform point on a triangle (the square-root parameterisation).
PR_INLINE float2 sample_triangle(float u1, float u2) {
  const float s = sqrt(u1);
  return make_float2(s * (1.0f - u2), s * u2);
}

// Local (tangent-space) vector to world, and back, for an orthonormal frame (t, b, n).
PR_INLINE float3 to_world(float3 v, float3 t, float3 b, float3 n) {
  return v.x * t + v.y * b + v.z * n;
}
PR_INLINE float3 to_local(float3 v, float3 t, float3 b, float3 n) {
  return make_float3(dot(v, t), dot(v, b), dot(v, n));
}

PR_NAMESPACE_END
