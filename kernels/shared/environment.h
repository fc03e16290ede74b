// The environment light (docs/design.md section 3): radiance from every direction, an
// equirectangular map turned about +Y, importance-sampled by a piecewise-constant distribution
// over its texels (marginal over rows, conditional within each). Shared by the kernels and the
// host's tests.
//
// Its Light (type PR_LIGHT_ENV, always the last in the table; its function set light_env_* is
// at the end) holds: inst = map width W,
// prim = height H, (p0x, p0y) = cos and sin of the turn, le = the scale (strength times
// colour), area = the map's mean luminance over the sphere (for its power). Its data buffer:
// the texels (3 floats each, top row first: +Y), then per row W + 1 conditional cumulative
// sums (0 ... 1), then the H + 1 marginal ones.
#pragma once

#include "shared/lights.h"

PR_NAMESPACE_BEGIN

// The map's frame: +Y up; u = 0.5 looks along -Z, u = 0.75 along +X; v = 0 is +Y.
PR_INLINE float2 env_uv_of(float3 d) {
  const float v = acos(clamp(d.y, -1.0f, 1.0f)) * PR_INV_PI;
  float u = 0.5f + atan2(d.x, -d.z) * (0.5f * PR_INV_PI);
  u = u - floor(u);
  return make_float2(u, v);
}

PR_INLINE float3 env_dir_of(float u, float v) {
  const float theta = PR_PI * v, phi = 2.0f * PR_PI * (u - 0.5f);
  const float s = sin(theta);
  return make_float3(s * sin(phi), cos(theta), -s * cos(phi));
}

// World direction to the map's frame (turned back by the light's turn about +Y), and back.
PR_INLINE float3 env_to_map(const Light* l, float3 d) {
  const float c = l->p0x, s = l->p0y;
  return make_float3(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
}
PR_INLINE float3 env_to_world(const Light* l, float3 d) {
  const float c = l->p0x, s = l->p0y;
  return make_float3(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
}

PR_INLINE u32 env_texel_index(float x, u32 n) {
  const u32 i = (u32)clamp(x * (float)n, 0.0f, (float)n - 1.0f);
  return i < n ? i : n - 1u;
}

// The index k with cdf[k] <= u < cdf[k + 1] among cdf[0 .. n] (cdf[0] = 0, cdf[n] = 1),
// skipping empty intervals.
PR_INLINE u32 env_find(PR_GLOBAL const float* cdf, u32 n, float u) {
  u32 lo = 0u, hi = n;  // answer in [lo, hi)
  while (hi - lo > 1u) {
    const u32 mid = (lo + hi) / 2u;
    if (cdf[mid] <= u)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

// Radiance arriving from world direction dir (nearest texel, so that the pdf below matches it).
PR_INLINE float3 env_radiance(const Light* l, PR_GLOBAL const float* env, float3 dir) {
  const u32 w = l->inst, h = l->prim;
  const float2 uv = env_uv_of(env_to_map(l, dir));
  const u32 t = env_texel_index(uv.y, h) * w + env_texel_index(uv.x, w);
  return make_float3(env[3u * t], env[3u * t + 1u], env[3u * t + 2u]) *
         make_float3(l->le_r, l->le_g, l->le_b);
}

// Solid-angle pdf with which env_sample picks world direction dir.
PR_INLINE float env_pdf(const Light* l, PR_GLOBAL const float* env, float3 dir) {
  const u32 w = l->inst, h = l->prim;
  const float3 m = env_to_map(l, dir);
  const float sin_theta = sqrt(fmax(0.0f, 1.0f - m.y * m.y));
  if (!(sin_theta > 0.0f)) return 0.0f;
  const float2 uv = env_uv_of(m);
  const u32 i = env_texel_index(uv.x, w), j = env_texel_index(uv.y, h);
  PR_GLOBAL const float* cond = env + 3u * w * h + j * (w + 1u);
  PR_GLOBAL const float* marg = env + 3u * w * h + h * (w + 1u);
  const float p_uv = (marg[j + 1u] - marg[j]) * (cond[i + 1u] - cond[i]) * (float)w * (float)h;
  return p_uv / (2.0f * PR_PI * PR_PI * sin_theta);
}

// Samples a world direction towards the environment with (u1, u2): *dir, its solid-angle pdf
// and the radiance from it. 0 where nothing is sampled (a black map).
PR_INLINE int env_sample(const Light* l, PR_GLOBAL const float* env, float u1, float u2,
                         float3* dir, float* pdf, float3* le) {
  const u32 w = l->inst, h = l->prim;
  PR_GLOBAL const float* marg = env + 3u * w * h + h * (w + 1u);
  if (!(marg[h] > 0.0f)) return 0;
  const u32 j = env_find(marg, h, u2);
  PR_GLOBAL const float* cond = env + 3u * w * h + j * (w + 1u);
  const u32 i = env_find(cond, w, u1);
  const float pj = marg[j + 1u] - marg[j], pi = cond[i + 1u] - cond[i];
  if (!(pj > 0.0f) || !(pi > 0.0f)) return 0;
  // Where in the texel: the remainders of u1 and u2 within their intervals.
  const float fu = clamp((u1 - cond[i]) / pi, 0.0f, PR_ONE_MINUS_EPSILON);
  const float fv = clamp((u2 - marg[j]) / pj, 0.0f, PR_ONE_MINUS_EPSILON);
  const float u = ((float)i + fu) / (float)w, v = ((float)j + fv) / (float)h;
  const float3 m = env_dir_of(u, v);
  const float sin_theta = sin(PR_PI * v);
  if (!(sin_theta > 0.0f)) return 0;
  *dir = env_to_world(l, m);
  *pdf = pj * pi * (float)w * (float)h / (2.0f * PR_PI * PR_PI * sin_theta);
  const u32 t = j * w + i;
  *le = make_float3(env[3u * t], env[3u * t + 1u], env[3u * t + 2u]) *
        make_float3(l->le_r, l->le_g, l->le_b);
  return *pdf > 0.0f;
}

// The environment's light function set (shared/lights.h, PR_LIGHT_TYPES); data is its buffer
// above (none: it emits nothing).
PR_INLINE int light_env_sample(const Light* l, PR_GLOBAL const float* data, float pmf, float3 ref,
                               float3 n_ref, float u1, float u2, LightSample* s, float* b1,
                               float* b2) {
  (void)n_ref, (void)b1, (void)b2;
  float pdf_w;
  if (!data || !env_sample(l, data, u1, u2, &s->wi, &pdf_w, &s->le)) return 0;
  s->pdf = pmf * pdf_w;
  s->dist = PR_INF_F;
  s->pos = ref + s->wi * 1e7f;
  s->normal = make_float3(0.0f, 0.0f, 0.0f);
  return 1;
}

PR_INLINE float light_env_pdf(const Light* l, PR_GLOBAL const float* data, float pmf, float3 ref,
                              float3 n_ref, float3 pos, float3 wi) {
  (void)ref, (void)n_ref, (void)pos;
  if (!data || !(pmf > 0.0f)) return 0.0f;
  return pmf * env_pdf(l, data, wi);
}

// Towards -wi for a direction wi sampled from the map; *le its radiance.
PR_INLINE float light_env_sample_emit(const Light* l, PR_GLOBAL const float* data, float3 n0,
                                      float u1, float u2, float3* dir, float3* le) {
  (void)n0;
  float3 wi = make_float3(0.0f, 1.0f, 0.0f);
  float pdf_w;
  *le = make_float3(0.0f, 0.0f, 0.0f);
  if (!data || !env_sample(l, data, u1, u2, &wi, &pdf_w, le)) pdf_w = 0.0f;
  *dir = -wi;
  return pdf_w;
}

// 0: no strategy joins the environment's vertex 0.
PR_INLINE float light_env_pdf_emit(const Light* l, float3 n0, float3 dir) {
  (void)l, (void)n0, (void)dir;
  return 0.0f;
}

PR_INLINE float light_env_falloff(const Light* l, float3 dir) {
  (void)l, (void)dir;
  return 1.0f;
}

// Radiance over all directions through the scene's disk.
PR_INLINE float light_env_power(const Light* l, float scene_radius) {
  const float lum = luminance(make_float3(l->le_r, l->le_g, l->le_b));
  return 4.0f * PR_PI * PR_PI * scene_radius * scene_radius * lum * l->area;
}

// 0: chosen by power, outside the light BVH.
PR_INLINE float light_env_importance(PR_GLOBAL const Light* l, float3 p, float3 n) {
  (void)l, (void)p, (void)n;
  return 0.0f;
}

PR_NAMESPACE_END
