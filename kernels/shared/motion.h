// Motion blur (--shutter, docs/design.md section 3, "Motion blur"): each camera sample has a time
// in the shutter interval, and every ray of its path sees the scene at that time. The host
// evaluates the animation at `steps` equally spaced times over the interval (the first at its
// opening, the middle one at the frame's own time); a sample's instance transforms and camera
// are blends of the two steps around its time. A blend of two transforms moves every point of
// the mesh along the segment between its two placements, so the union of the steps' boxes holds
// the instance at every time (the top-level BVH's boxes).
#pragma once

#include "shared/camera.h"
#include "shared/math.h"
#include "shared/rng.h"

#ifdef PR_DEVICE_CODE
// Transforms round as the host's and as they did before motion blur (shared/bvh.h): no fused
// multiply-adds, whichever header a kernel includes first.
#pragma OPENCL FP_CONTRACT OFF
#endif

PR_NAMESPACE_BEGIN

// A 3x4 row-major affine transform in private memory: row r is (m[4r], m[4r+1], m[4r+2] | m[4r+3]).
typedef struct {
  float m[12];
} Affine;

PR_INLINE float3 affine_point(const Affine* a, float3 p) {
  const float* m = a->m;
  return make_float3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3],
                     m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                     m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

PR_INLINE float3 affine_vector(const Affine* a, float3 v) {
  const float* m = a->m;
  return make_float3(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
                     m[8] * v.x + m[9] * v.y + m[10] * v.z);
}

// Normals transform by the inverse transpose: n_world = (world_to_object)^T n_object.
PR_INLINE float3 affine_normal(const Affine* w2o, float3 n) {
  const float* m = w2o->m;
  return make_float3(m[0] * n.x + m[4] * n.y + m[8] * n.z, m[1] * n.x + m[5] * n.y + m[9] * n.z,
                     m[2] * n.x + m[6] * n.y + m[10] * n.z);
}

PR_INLINE float affine_det(const Affine* a) {
  const float* m = a->m;
  return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
         m[2] * (m[4] * m[9] - m[5] * m[8]);
}

PR_INLINE void affine_load(PR_GLOBAL const float* src, Affine* a) {
  for (int k = 0; k < 12; ++k) a->m[k] = src[k];
}

// The inverse by cofactors (a singular transform gives non-finite entries, whose rays hit
// nothing).
PR_INLINE void affine_inverse(const Affine* a, Affine* inv) {
  const float* m = a->m;
  float* r = inv->m;
  const float s = 1.0f / affine_det(a);
  r[0] = (m[5] * m[10] - m[6] * m[9]) * s;
  r[1] = (m[2] * m[9] - m[1] * m[10]) * s;
  r[2] = (m[1] * m[6] - m[2] * m[5]) * s;
  r[4] = (m[6] * m[8] - m[4] * m[10]) * s;
  r[5] = (m[0] * m[10] - m[2] * m[8]) * s;
  r[6] = (m[2] * m[4] - m[0] * m[6]) * s;
  r[8] = (m[4] * m[9] - m[5] * m[8]) * s;
  r[9] = (m[1] * m[8] - m[0] * m[9]) * s;
  r[10] = (m[0] * m[5] - m[1] * m[4]) * s;
  for (int row = 0; row < 3; ++row)
    r[4 * row + 3] = -(r[4 * row] * m[3] + r[4 * row + 1] * m[7] + r[4 * row + 2] * m[11]);
}

// The step k below `time` (in [0, 1] over the interval) and the weight of the step after it.
PR_INLINE u32 motion_step(u32 steps, float time, float* a) {
  const float x = clamp(time, 0.0f, 1.0f) * (float)(steps - 1u);
  u32 k = (u32)x;
  if (k > steps - 2u) k = steps - 2u;
  *a = x - (float)k;
  return k;
}

// Instance `inst`'s object-to-world transform at `time` and its inverse; `motion` holds each
// instance's `steps` transforms (12 floats each) in a row.
PR_INLINE void motion_transform(PR_GLOBAL const float* motion, u32 steps, u32 inst, float time,
                                Affine* o2w, Affine* w2o) {
  float a;
  const u32 k = motion_step(steps, time, &a);
  PR_GLOBAL const float* m0 = motion + ((size_t)inst * steps + k) * 12u;
  for (int j = 0; j < 12; ++j) o2w->m[j] = m0[j] + a * (m0[12 + j] - m0[j]);
  affine_inverse(o2w, w2o);
}

// The camera at `time`: position, field of view and clipping planes blended, its axes blended
// and made orthonormal again (forward first). Two equal steps give the step itself, bit for bit,
// as pt_generate reads a camera still over the shutter (GpuScene::stillCamera).
PR_INLINE CameraParams camera_at_time(PR_GLOBAL const CameraParams* steps, u32 count, float time) {
  float a;
  const u32 k = motion_step(count, time, &a);
  const CameraParams c0 = steps[k], c1 = steps[k + 1u];
  if (c0.px == c1.px && c0.py == c1.py && c0.pz == c1.pz && c0.fx == c1.fx && c0.fy == c1.fy &&
      c0.fz == c1.fz && c0.ux == c1.ux && c0.uy == c1.uy && c0.uz == c1.uz &&
      c0.tan_half_fov == c1.tan_half_fov && c0.aspect == c1.aspect && c0.znear == c1.znear &&
      c0.zfar == c1.zfar)
    return c0;
  CameraParams c = c0;
  const float3 p0 = make_float3(c0.px, c0.py, c0.pz), p1 = make_float3(c1.px, c1.py, c1.pz);
  const float3 p = p0 + (p1 - p0) * a;
  const float3 f =
      normalize(make_float3(c0.fx, c0.fy, c0.fz) +
                (make_float3(c1.fx, c1.fy, c1.fz) - make_float3(c0.fx, c0.fy, c0.fz)) * a);
  float3 u = make_float3(c0.ux, c0.uy, c0.uz) +
             (make_float3(c1.ux, c1.uy, c1.uz) - make_float3(c0.ux, c0.uy, c0.uz)) * a;
  u = normalize(u - f * dot(u, f));
  const float3 r = cross(f, u);
  c.px = p.x, c.py = p.y, c.pz = p.z;
  c.fx = f.x, c.fy = f.y, c.fz = f.z;
  c.ux = u.x, c.uy = u.y, c.uz = u.z;
  c.rx = r.x, c.ry = r.y, c.rz = r.z;
  c.tan_half_fov = c0.tan_half_fov + (c1.tan_half_fov - c0.tan_half_fov) * a;
  c.aspect = c0.aspect + (c1.aspect - c0.aspect) * a;
  c.znear = c0.znear + (c1.znear - c0.znear) * a;
  c.zfar = c0.zfar + (c1.zfar - c0.zfar) * a;
  return c;
}

// The time (in [0, 1) over the shutter interval) of a camera sample: a padded Sobol dimension of
// its camera stream, so a pixel's samples are stratified in time and independent of its other
// dimensions.
#define PR_TIME_PAIR 0x7154u
PR_INLINE float shutter_time(u32 seed, u32 frame, u32 pixel, u32 sample) {
  const Rng r = rng_make(seed, PR_RNG_CAMERA, frame, pixel, sample);
  return pr_u32_to_unit(pr_sobol_pair(&r, PR_TIME_PAIR, 0u));
}

PR_NAMESPACE_END
