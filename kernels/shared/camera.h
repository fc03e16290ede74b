// The pinhole camera: a ray through a jittered point of a pixel. Pixel (0, 0) is the top left.
#pragma once

#include "shared/math.h"
#include "shared/types.h"

PR_NAMESPACE_BEGIN

// 80 bytes.
typedef struct {
  float px, py, pz, tan_half_fov;  // position; tan(yfov / 2)
  float fx, fy, fz, aspect;        // unit forward; width / height
  float rx, ry, rz, znear;         // unit right; the near clipping plane's depth (> 0)
  float ux, uy, uz, zfar;          // unit up; the far clipping plane's depth (0: none)
  u32 width, height, pad2, pad3;
} CameraParams;

// Direction (unit) of the ray through film point (sx, sy) in pixels, e.g. (x + jitter, y + jitter).
PR_INLINE float3 camera_direction(const CameraParams* c, float sx, float sy) {
  const float ndc_x = (2.0f * sx / (float)c->width - 1.0f) * c->tan_half_fov * c->aspect;
  const float ndc_y = (1.0f - 2.0f * sy / (float)c->height) * c->tan_half_fov;
  const float3 d = make_float3(c->fx, c->fy, c->fz) + make_float3(c->rx, c->ry, c->rz) * ndc_x +
                   make_float3(c->ux, c->uy, c->uz) * ndc_y;
  return normalize(d);
}

PR_INLINE float3 camera_position(const CameraParams* c) {
  return make_float3(c->px, c->py, c->pz);
}

// The camera ray of pixel `pixel` (row-major) through its point offset by `jitter` in [0, 1)^2:
// the one generator of camera rays, for every mode.
// Its segment lies between the clipping planes (glTF's znear and zfar): what is nearer or
// farther is not seen.
PR_INLINE Ray camera_ray(const CameraParams* c, u32 pixel, float2 jitter) {
  const u32 x = pixel % c->width, y = pixel / c->width;
  const float3 d = camera_direction(c, (float)x + jitter.x, (float)y + jitter.y);
  const float cos_t = dot(d, make_float3(c->fx, c->fy, c->fz));
  Ray r;
  r.ox = c->px, r.oy = c->py, r.oz = c->pz, r.tmin = c->znear / cos_t;
  r.dx = d.x, r.dy = d.y, r.dz = d.z, r.tmax = c->zfar > 0.0f ? c->zfar / cos_t : PR_INF_F;
  return r;
}

// Whether p's depth along the camera's axis lies between its clipping planes.
PR_INLINE int camera_in_depth_range(const CameraParams* c, float3 p) {
  const float z = dot(p - make_float3(c->px, c->py, c->pz), make_float3(c->fx, c->fy, c->fz));
  return z >= c->znear && (!(c->zfar > 0.0f) || z <= c->zfar);
}

// The distance from the camera to its near plane along unit dir (dir in front of the camera).
PR_INLINE float camera_near_distance(const CameraParams* c, float3 dir) {
  return c->znear / dot(dir, make_float3(c->fx, c->fy, c->fz));
}

// The film point (in pixels, as camera_direction takes it) where camera c sees world point p;
// 0 where p is not in front of it.
PR_INLINE int camera_project(const CameraParams* c, float3 p, float2* s) {
  const float3 v = p - make_float3(c->px, c->py, c->pz);
  const float z = dot(v, make_float3(c->fx, c->fy, c->fz));
  if (!(z > 0.0f)) return 0;
  const float nx = dot(v, make_float3(c->rx, c->ry, c->rz)) / (z * c->tan_half_fov * c->aspect);
  const float ny = dot(v, make_float3(c->ux, c->uy, c->uz)) / (z * c->tan_half_fov);
  s->x = 0.5f * (nx + 1.0f) * (float)c->width;
  s->y = 0.5f * (1.0f - ny) * (float)c->height;
  return 1;
}

// The pixel of camera c that sees world point p (PR_INVALID_INDEX: behind it, outside the
// image or outside the clipping planes).
PR_INLINE u32 camera_pixel(const CameraParams* c, float3 p) {
  float2 s;
  if (!camera_in_depth_range(c, p) || !camera_project(c, p, &s)) return PR_INVALID_INDEX;
  if (!(s.x >= 0.0f && s.y >= 0.0f && s.x < (float)c->width && s.y < (float)c->height))
    return PR_INVALID_INDEX;
  return (u32)s.y * c->width + (u32)s.x;
}

// The area A of the image plane at distance 1 (both tangents of the field of view).
PR_INLINE float camera_plane_area(const CameraParams* c) {
  return 4.0f * c->tan_half_fov * c->tan_half_fov * c->aspect;
}

// cos^3 of the angle between the camera's axis and the way to p, times p's squared distance: a
// pixel's camera samples have density W H / (A x this) x |cos at p| per unit area at p (uniform
// on the pixel's part of the image plane), and a pixel's importance is its inverse likewise.
PR_INLINE float camera_cos3_d2(const CameraParams* c, float3 p) {
  const float3 v = p - make_float3(c->px, c->py, c->pz);
  const float d2 = dot(v, v);
  const float cos_t = dot(v, make_float3(c->fx, c->fy, c->fz)) / sqrt(d2);
  return cos_t * cos_t * cos_t * d2;
}

PR_NAMESPACE_END

PR_STATIC_ASSERT(sizeof(pr::dev::CameraParams) == 80, "CameraParams layout");
PR_STATIC_ASSERT(offsetof(pr::dev::CameraParams, width) == 64, "CameraParams layout");
