// Lights: emissive triangles (world space, rebuilt by the host whenever a dynamic emitter moves)
// and KHR_lights_punctual lights. Selection is proportional to power: the probability of a
// light is light_power(light) / total_power, and an emissive triangle's power is computed from
// its material's emission factor and world area, so that the pdf of a triangle hit by a BSDF
// ray (for MIS) needs no table lookup.
#pragma once

#include "shared/math.h"
#include "shared/sampling.h"

PR_NAMESPACE_BEGIN

#define PR_LIGHT_TRIANGLE 0u
#define PR_LIGHT_POINT 1u
#define PR_LIGHT_SPOT 2u
#define PR_LIGHT_DIRECTIONAL 3u

// 96 bytes.
typedef struct {
  float p0x, p0y, p0z;  // triangle vertex 0, or the light's position
  u32 type;
  float e1x, e1y, e1z;  // triangle edge v1 - v0, or the unit emission axis (spot, directional)
  u32 inst;             // DSG instance of an emissive triangle, PR_INVALID_INDEX on SSG
  float e2x, e2y, e2z;  // triangle edge v2 - v0
  u32 prim;             // scene triangle of an emissive triangle (SSG index or DSG mesh triangle)
  float le_r, le_g, le_b;  // radiance factor (triangle), intensity in cd (point, spot), or lux
  float area;              // world area (triangle)
  float cos_inner, cos_outer;  // spot cone
  float power;                 // selection weight, the same formula as light_power()
  u32 material;
  u32 moved;  // changed since the previous frame (for invalidation)
  float pad1, pad2, pad3;
} Light;

// The selection weight of an emissive triangle: luminance(Le) * pi * area.
PR_INLINE float emitter_power(float3 le, float area) { return luminance(le) * PR_PI * area; }

// A sampled point on a light, as seen from a reference point.
typedef struct {
  float3 pos;     // point on the light (position for point/spot; far away for directional)
  float3 wi;      // unit direction from the reference point to the light
  float dist;     // distance to the light (PR_INF_F for directional)
  float3 le;      // emitted radiance towards the reference point (or intensity / irradiance)
  float pdf;      // solid-angle pdf including the selection probability (delta: the pmf only)
  int delta;      // punctual light: no MIS, the pdf is a pmf
  float3 normal;  // light surface normal (triangles)
} LightSample;

// Spot falloff of KHR_lights_punctual (smooth between the outer and inner cone).
PR_INLINE float spot_attenuation(float cos_angle, float cos_inner, float cos_outer) {
  const float scale = 1.0f / fmax(0.001f, cos_inner - cos_outer);
  const float t = clamp((cos_angle - cos_outer) * scale, 0.0f, 1.0f);
  return t * t;
}

// Binary search of the cumulative power table: the light whose interval holds u * total.
PR_INLINE u32 light_select(PR_GLOBAL const float* cdf, u32 count, float u) {
  const float target = u * cdf[count - 1];
  u32 lo = 0, hi = count - 1;
  while (lo < hi) {
    const u32 mid = (lo + hi) / 2u;
    if (cdf[mid] <= target)
      lo = mid + 1u;
    else
      hi = mid;
  }
  return lo;
}

// Samples a point on light `l` (selected with probability `pmf`) as seen from `ref`. Emissive
// triangles emit on both faces, as in Blender and Cycles. Returns 0 when the sample carries no
// light. For triangles, (*b1, *b2) are the barycentrics of the point, for emission textures.
PR_INLINE int light_sample(const Light* l, float pmf, float3 ref, float u1, float u2,
                           LightSample* s, float* b1, float* b2) {
  s->delta = l->type != PR_LIGHT_TRIANGLE;
  s->le = make_float3(l->le_r, l->le_g, l->le_b);
  *b1 = 0.0f;
  *b2 = 0.0f;
  if (l->type == PR_LIGHT_TRIANGLE) {
    const float2 b = sample_triangle(u1, u2);
    const float3 e1 = make_float3(l->e1x, l->e1y, l->e1z), e2 = make_float3(l->e2x, l->e2y, l->e2z);
    const float3 cr = cross(e1, e2);
    const float cl = length(cr);
    if (cl <= 0.0f) return 0;
    s->normal = cr / cl;
    s->pos = make_float3(l->p0x, l->p0y, l->p0z) + e1 * b.x + e2 * b.y;
    const float3 d = s->pos - ref;
    const float d2 = dot(d, d);
    if (d2 <= 0.0f) return 0;
    s->dist = sqrt(d2);
    s->wi = d / s->dist;
    const float cos_l = fabs(dot(s->wi, s->normal));
    if (cos_l <= 1e-7f) return 0;
    s->pdf = pmf * d2 / (cos_l * l->area);
    *b1 = b.x;
    *b2 = b.y;
    return 1;
  }
  s->normal = make_float3(0.0f, 0.0f, 0.0f);
  s->pdf = pmf;
  if (l->type == PR_LIGHT_DIRECTIONAL) {
    // e1 is the direction the light travels.
    s->wi = -make_float3(l->e1x, l->e1y, l->e1z);
    s->dist = PR_INF_F;
    s->pos = ref + s->wi * 1e7f;
    return 1;
  }
  s->pos = make_float3(l->p0x, l->p0y, l->p0z);
  const float3 d = s->pos - ref;
  const float d2 = dot(d, d);
  if (d2 <= 0.0f) return 0;
  s->dist = sqrt(d2);
  s->wi = d / s->dist;
  float att = 1.0f / d2;
  if (l->type == PR_LIGHT_SPOT)
    att *= spot_attenuation(dot(-s->wi, make_float3(l->e1x, l->e1y, l->e1z)), l->cos_inner,
                            l->cos_outer);
  s->le = s->le * att;  // intensity / r^2 = irradiance at ref, normal to wi
  return att > 0.0f;
}

// Solid-angle pdf with which light sampling would pick the point `pos` of an emissive triangle
// with emission `le` and world area `area`, seen from a point at `dist` with |cos| = cos_l.
PR_INLINE float light_pdf_triangle(float3 le, float area, float total_power, float dist,
                                   float cos_l) {
  if (total_power <= 0.0f || cos_l <= 1e-7f || area <= 0.0f) return 0.0f;
  const float pmf = emitter_power(le, area) / total_power;
  return pmf * dist * dist / (cos_l * area);
}

// The light table as kernels see it (built from PR_LIGHT_PARAMS).
typedef struct {
  PR_GLOBAL const Light* lights;
  PR_GLOBAL const float* cdf;  // running sum of power; cdf[count - 1] == total_power
  u32 count;
  float total_power;
} LightData;

PR_NAMESPACE_END

#ifdef PR_DEVICE_CODE
#define PR_LIGHT_PARAMS                                                                  \
  __global const Light *pr_lights, __global const float *pr_light_cdf, uint pr_light_count, \
      float pr_total_power
PR_INLINE LightData pr_light_data(__global const Light* l, __global const float* cdf, uint count,
                                  float total) {
  LightData d;
  d.lights = l;
  d.cdf = cdf;
  d.count = count;
  d.total_power = total;
  return d;
}
#define PR_LIGHTS() pr_light_data(pr_lights, pr_light_cdf, pr_light_count, pr_total_power)
#endif

PR_STATIC_ASSERT(sizeof(pr::dev::Light) == 96, "Light layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Light, le_r) == 48, "Light layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Light, material) == 76, "Light layout");
