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

// Emitter triangles are sampled uniformly in the solid angle they subtend from the receiving
// point (Arvo 1995) where that solid angle lies between these bounds. Below, the triangle is
// small or far and area sampling is about as good; and Arvo's construction in single precision
// moves points (measured against double precision, worst of 16,000 random triangles per band)
// by up to 140% of the triangle's size near 1e-3 sr, 13% near 3e-3, 7% near 0.02, 1.6% near
// 0.03 and under 1% from 0.056 sr up. Above, the triangle nearly surrounds the point.
#define PR_MIN_SPHERICAL_SOLID_ANGLE 0.05f
#define PR_MAX_SPHERICAL_SOLID_ANGLE 6.22f

// The triangle (v0, v0 + e1, v0 + e2) as seen from p: unit directions to its vertices and the
// cosine and sine of the spherical triangle's angle at a. Returns the solid angle it subtends
// (Van Oosterom and Strackee 1983: no cancellation for small triangles), 0 when degenerate.
typedef struct {
  float3 a, b, c;
  float cos_alpha, sin_alpha;
} SphericalTriangle;

PR_INLINE float spherical_triangle(float3 p, float3 v0, float3 e1, float3 e2,
                                   SphericalTriangle* t) {
  const float3 da = v0 - p, db = da + e1, dc = da + e2;
  const float la = length(da), lb = length(db), lc = length(dc);
  if (!(la > 0.0f && lb > 0.0f && lc > 0.0f)) return 0.0f;
  t->a = da / la;
  t->b = db / lb;
  t->c = dc / lc;
  const float3 n_ab = cross(t->a, t->b), n_ac = cross(t->a, t->c);
  const float triple = fabs(dot(t->a, cross(t->b, t->c)));
  const float l_ab = length(n_ab), l_ac = length(n_ac);
  if (!(l_ab > 0.0f && l_ac > 0.0f && triple > 0.0f)) return 0.0f;
  // The angle at a is the one between the planes through (a, b) and (a, c); the cross product
  // of their normals is a times the triple product.
  t->cos_alpha = clamp(dot(n_ab, n_ac) / (l_ab * l_ac), -1.0f, 1.0f);
  t->sin_alpha = fmin(triple / (l_ab * l_ac), 1.0f);
  const float omega =
      2.0f * atan2(triple, 1.0f + dot(t->a, t->b) + dot(t->b, t->c) + dot(t->c, t->a));
  return omega > 0.0f && isfinite_f(omega) ? omega : 0.0f;
}

// Whether light sampling from a point uses the solid angle (else the area) for this triangle.
PR_INLINE int use_solid_angle(float omega) {
  return omega >= PR_MIN_SPHERICAL_SOLID_ANGLE && omega <= PR_MAX_SPHERICAL_SOLID_ANGLE;
}

// The component of v orthogonal to unit w, normalised.
PR_INLINE float3 orthogonal_part(float3 v, float3 w) {
  return normalize(v - w * dot(v, w));
}

// A direction uniform in the spherical triangle of solid angle omega (Arvo 1995): u1 picks the
// sub-triangle (a, b, c') of area u1 * omega, u2 a point on the arc from b to c'.
PR_INLINE float3 sample_spherical_triangle(const SphericalTriangle* t, float omega, float u1,
                                           float u2) {
  // s, c: sine and cosine of (u1 omega - alpha).
  const float cos_alpha = t->cos_alpha, sin_alpha = t->sin_alpha;
  float cu;
  const float su = pr_sincos(u1 * omega, &cu);
  const float s = su * cos_alpha - cu * sin_alpha, c = cu * cos_alpha + su * sin_alpha;
  const float u = c - cos_alpha, v = s + sin_alpha * dot(t->a, t->b);
  const float den = (v * s + u * c) * sin_alpha;
  const float q = den != 0.0f ? clamp(((v * c - u * s) * cos_alpha - v) / den, -1.0f, 1.0f) : 1.0f;
  const float3 cp = t->a * q + orthogonal_part(t->c, t->a) * sqrt(fmax(0.0f, 1.0f - q * q));
  // 1 - cos(arc b c') from the chord, and 1 - z^2 = (1 - z)(1 + z): no cancellation when the
  // triangle is small.
  const float3 chord = cp - t->b;
  const float one_minus_z = u2 * 0.5f * dot(chord, chord);
  const float z = 1.0f - one_minus_z;
  return t->b * z +
         orthogonal_part(cp, t->b) * sqrt(fmax(0.0f, one_minus_z * (2.0f - one_minus_z)));
}

// Barycentrics (b1 for v0 + e1, b2 for v0 + e2) where the ray p + t w meets the triangle's
// plane, kept inside the triangle against round-off.
PR_INLINE float2 triangle_barycentrics_along(float3 p, float3 w, float3 v0, float3 e1, float3 e2) {
  const float3 s1 = cross(w, e2);
  const float det = dot(s1, e1);
  if (det == 0.0f) return make_float2(0.0f, 0.0f);
  const float3 s = p - v0, s2 = cross(s, e1);
  float b1 = clamp(dot(s, s1) / det, 0.0f, 1.0f), b2 = clamp(dot(w, s2) / det, 0.0f, 1.0f);
  if (b1 + b2 > 1.0f) {
    const float sum = b1 + b2;
    b1 /= sum;
    b2 /= sum;
  }
  return make_float2(b1, b2);
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
    const float3 v0 = make_float3(l->p0x, l->p0y, l->p0z);
    const float3 e1 = make_float3(l->e1x, l->e1y, l->e1z), e2 = make_float3(l->e2x, l->e2y, l->e2z);
    const float3 cr = cross(e1, e2);
    const float cl = length(cr);
    if (cl <= 0.0f) return 0;
    s->normal = cr / cl;
    SphericalTriangle st;
    const float omega = spherical_triangle(ref, v0, e1, e2, &st);
    const int solid = use_solid_angle(omega);
    const float2 b = solid ? triangle_barycentrics_along(
                                 ref, sample_spherical_triangle(&st, omega, u1, u2), v0, e1, e2)
                           : sample_triangle(u1, u2);
    s->pos = v0 + e1 * b.x + e2 * b.y;
    const float3 d = s->pos - ref;
    const float d2 = dot(d, d);
    if (d2 <= 0.0f) return 0;
    s->dist = sqrt(d2);
    s->wi = d / s->dist;
    const float cos_l = fabs(dot(s->wi, s->normal));
    if (cos_l <= 1e-7f) return 0;
    s->pdf = solid ? pmf / omega : pmf * d2 / (cos_l * l->area);
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

// Solid-angle pdf with which light sampling from `ref` would pick the point `pos` of the
// emissive triangle (v0, v0 + e1, v0 + e2) with emission `le`: the same choice between solid
// angle and area as light_sample makes.
PR_INLINE float light_pdf_triangle(float3 le, float total_power, float3 ref, float3 pos, float3 v0,
                                   float3 e1, float3 e2) {
  const float3 cr = cross(e1, e2);
  const float area = 0.5f * length(cr);
  if (total_power <= 0.0f || !(area > 0.0f)) return 0.0f;
  const float pmf = emitter_power(le, area) / total_power;
  const float3 d = pos - ref;
  const float d2 = dot(d, d);
  if (!(d2 > 0.0f)) return 0.0f;
  const float cos_l = fabs(dot(d, cr)) / (sqrt(d2) * 2.0f * area);
  if (cos_l <= 1e-7f) return 0.0f;
  SphericalTriangle st;
  const float omega = spherical_triangle(ref, v0, e1, e2, &st);
  return use_solid_angle(omega) ? pmf / omega : pmf * d2 / (cos_l * area);
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
