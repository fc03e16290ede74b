// Lights: emissive triangles (world space, rebuilt by the host whenever a dynamic emitter moves),
// KHR_lights_punctual lights and the environment. Every light type is one entry of
// PR_LIGHT_TYPES and one set of functions (below; the environment's in shared/environment.h);
// the dispatchers (light_sample_towards, light_power, ...) and the queries on a type's flags
// (light_is_triangle, ...) are generated from the table, so no other file tests a light's type.
// A receiving point chooses a light with the light BVH (shared/light_bvh.h), by weighing every
// light from the point, or by power alone: PR_LIGHT_SAMPLER; light paths, whose origin knows no
// receiver, choose by power (docs/design.md section 6).
#pragma once

#include "shared/light_bvh.h"
#include "shared/math.h"
#include "shared/sampling.h"

// What callers may ask of a light type, instead of testing the type itself (light_is_triangle
// and the other queries below).
// An emissive triangle of the scene (prim, inst): BSDF rays hit it, its emission is its material's.
#define PR_LIGHT_ON_TRIANGLE 1u
// Delta in position (a point) or in direction: no MIS, light_sample's pdf is the pmf alone.
#define PR_LIGHT_DELTA_POSITION 2u
#define PR_LIGHT_DELTA_DIRECTION 4u
// Outside the scene: after the light BVH's lights in the table; light paths start on a disk.
#define PR_LIGHT_AT_INFINITY 8u
// Eye vertices join its light paths' vertex 0 (strategy E): light_pdf_emit_dir is not 0.
#define PR_LIGHT_JOINS_VERTEX0 16u
// Its light paths take part in --eye-paths (shared/eye_paths.h).
#define PR_LIGHT_EYE_PATHS 32u

// The light types: X(NAME, fn, flags). NAME gives PR_LIGHT_NAME (Light::type, in table order),
// fn the prefix of its function set light_<fn>_* (PR_LIGHT_DECLARE lists it). Adding a type is
// one row here and one function set; the host builds its Light (host/render/light_table.cpp).
#define PR_LIGHT_TYPES(X)                                                                   \
  X(TRIANGLE, triangle, PR_LIGHT_ON_TRIANGLE | PR_LIGHT_JOINS_VERTEX0 | PR_LIGHT_EYE_PATHS) \
  X(POINT, point, PR_LIGHT_DELTA_POSITION | PR_LIGHT_JOINS_VERTEX0 | PR_LIGHT_EYE_PATHS)    \
  X(SPOT, spot, PR_LIGHT_DELTA_POSITION | PR_LIGHT_JOINS_VERTEX0 | PR_LIGHT_EYE_PATHS)      \
  X(DIRECTIONAL, directional,                                                               \
    PR_LIGHT_DELTA_DIRECTION | PR_LIGHT_AT_INFINITY | PR_LIGHT_EYE_PATHS)                   \
  X(ENV, env, PR_LIGHT_AT_INFINITY | PR_LIGHT_EYE_PATHS) /* shared/environment.h; last */

// Outside the namespace, as the macros it replaced: host code names PR_LIGHT_POINT unqualified.
#define PR_LIGHT_ENUM_ENTRY(name, fn, flags) PR_LIGHT_##name,
enum { PR_LIGHT_TYPES(PR_LIGHT_ENUM_ENTRY) PR_LIGHT_TYPE_COUNT };
#undef PR_LIGHT_ENUM_ENTRY

// The light sampler for receivers, one compile-time value (-DPR_LIGHT_SAMPLER=n from the host's
// GpuScene::buildOptions): every sampler is compiled and type-checked in every build, and the
// compiler drops the others' branches.
#define PR_LIGHT_SAMPLER_BVH 0         // the light BVH, resampled (light_tree_resample)
#define PR_LIGHT_SAMPLER_EXHAUSTIVE 1  // every light weighed from the receiver
#define PR_LIGHT_SAMPLER_POWER 2       // by power alone
#ifndef PR_LIGHT_SAMPLER
#define PR_LIGHT_SAMPLER PR_LIGHT_SAMPLER_BVH
#endif

PR_NAMESPACE_BEGIN

// 96 bytes.
typedef struct {
  float p0x, p0y, p0z;  // triangle vertex 0, or the light's position
  u32 type;
  float e1x, e1y, e1z;  // triangle edge v1 - v0, or the unit emission axis (spot, directional)
  u32 inst;             // DSG instance of an emissive triangle, PR_INVALID_INDEX on SSG
  float e2x, e2y, e2z;  // triangle edge v2 - v0
  u32 prim;             // scene triangle of an emissive triangle (SSG index or DSG mesh triangle)
  float le_r, le_g, le_b;      // radiance factor (triangle), intensity in cd (point, spot), or lux
  float area;                  // world area (triangle)
  float cos_inner, cos_outer;  // spot cone
  float power;                 // light_power(); the environment's x GpuScene::envChoiceShare_
  u32 material;
  u32 moved;        // changed since the previous frame (for invalidation)
  u32 leaf;         // the light's node in the light BVH; PR_INVALID_INDEX for directional lights
                    // and the environment
  float disk_area;  // lights at infinity: the disk pi R^2 their light paths start on
  float pad3;
} Light;

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

// Where sample_spherical_triangle put direction w (unit, inside the triangle): the inverse of
// Arvo's construction. c' is where the great circle through b and w meets the arc from a to c;
// u1 is the share of the solid angle in (a, b, c'), u2 the share of the arc b c' up to w (in
// 1 - cos, from the chords).
PR_INLINE float2 invert_spherical_triangle(const SphericalTriangle* t, float omega, float3 w) {
  const float3 cb = w - t->b;
  float3 cp = cross(cross(t->b, w), cross(t->a, t->c));
  const float lp = length(cp);
  if (!(lp > 0.0f)) return make_float2(0.0f, 0.0f);  // w on b: u1 does not matter
  cp = cp / lp;
  if (dot(cp, t->a + t->c) < 0.0f) cp = -cp;
  const float triple = fabs(dot(t->a, cross(t->b, cp)));
  const float part = 2.0f * atan2(triple, 1.0f + dot(t->a, t->b) + dot(t->b, cp) + dot(cp, t->a));
  const float3 cc = cp - t->b;
  const float den = dot(cc, cc);
  return make_float2(clamp(part / omega, 0.0f, 1.0f),
                     den > 0.0f ? clamp(dot(cb, cb) / den, 0.0f, 1.0f) : 0.0f);
}

// The receiver's cosine at the triangle's corners, as weights of a bilinear warp of the unit
// square that sample_spherical_triangle maps onto the triangle: (0, 0) and (1, 0) go to b,
// (0, 1) to a, (1, 1) to c (pbrt-v4's warp). With them, directions follow the solid angle
// times roughly the cosine at the receiver. Floors at 0.01 keep every direction possible.
typedef struct {
  float w00, w10, w01, w11;
} CosineWarp;

PR_INLINE CosineWarp cosine_warp(const SphericalTriangle* t, float3 n) {
  CosineWarp c;
  c.w00 = c.w10 = fmax(0.01f, dot(n, t->b));
  c.w01 = fmax(0.01f, dot(n, t->a));
  c.w11 = fmax(0.01f, dot(n, t->c));
  return c;
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

// Solid-angle pdf with which light sampling from `ref` (shading normal n_ref) would pick the
// point `pos` of the emissive triangle (v0, v0 + e1, v0 + e2), chosen with probability pmf: the
// same choices (solid angle or area, cosine warp) as light_sample makes.
PR_INLINE float light_pdf_triangle(float pmf, float3 ref, float3 n_ref, float3 pos, float3 v0,
                                   float3 e1, float3 e2) {
  const float3 cr = cross(e1, e2);
  const float area = 0.5f * length(cr);
  if (!(pmf > 0.0f) || !(area > 0.0f)) return 0.0f;
  const float3 d = pos - ref;
  const float d2 = dot(d, d);
  if (!(d2 > 0.0f)) return 0.0f;
  const float cos_l = fabs(dot(d, cr)) / (sqrt(d2) * 2.0f * area);
  if (cos_l <= 1e-7f) return 0.0f;
  SphericalTriangle st;
  const float omega = spherical_triangle(ref, v0, e1, e2, &st);
  if (!use_solid_angle(omega)) return pmf * d2 / (cos_l * area);
  if (!has_normal(n_ref)) return pmf / omega;
  const CosineWarp cw = cosine_warp(&st, n_ref);
  const float2 u = invert_spherical_triangle(&st, omega, d * (1.0f / sqrt(d2)));
  return pmf * bilinear_pdf(u, cw.w00, cw.w10, cw.w01, cw.w11) / omega;
}

// Each type's function set; `data` is the light table's data buffer (LightData::env: the
// environment's map), which the other types ignore.
//  sample:      a point on the light as seen from ref (shading normal n_ref, zero: none), chosen
//               with probability pmf: LightSample's pos, wi, dist, le, pdf, normal (the
//               dispatcher sets delta, *b1, *b2). 0 where the sample carries no light.
//  pdf:         the solid-angle pdf (times pmf) with which sample gives the point pos in
//               direction wi; 0 for delta lights, which no other strategy reaches.
//  sample_emit: the direction in which a light path leaves vertex 0 (n0: the face chosen on a
//               triangle), its solid-angle pdf (1: a delta direction) and, in *le, the emission
//               along it before the falloff: radiance factor, intensity or irradiance.
//  pdf_emit:    sample_emit's pdf of dir where strategy E joins vertex 0
//               (PR_LIGHT_JOINS_VERTEX0), else 0.
//  falloff:     the share of the emission sent along dir leaving the light (a spot's cone).
//  power:       the luminance of the flux it emits (through the scene's disk, at infinity).
//  importance:  the luminance of the irradiance a receiver (p, n) can expect from it.
#define PR_LIGHT_DECLARE(name, fn, flags)                                                          \
  PR_INLINE int light_##fn##_sample(const Light* l, PR_GLOBAL const float* data, float pmf,        \
                                    float3 ref, float3 n_ref, float u1, float u2, LightSample* s,  \
                                    float* b1, float* b2);                                         \
  PR_INLINE float light_##fn##_pdf(const Light* l, PR_GLOBAL const float* data, float pmf,         \
                                   float3 ref, float3 n_ref, float3 pos, float3 wi);               \
  PR_INLINE float light_##fn##_sample_emit(const Light* l, PR_GLOBAL const float* data, float3 n0, \
                                           float u1, float u2, float3* dir, float3* le);           \
  PR_INLINE float light_##fn##_pdf_emit(const Light* l, float3 n0, float3 dir);                    \
  PR_INLINE float light_##fn##_falloff(const Light* l, float3 dir);                                \
  PR_INLINE float light_##fn##_power(const Light* l, float scene_radius);                          \
  PR_INLINE float light_##fn##_importance(PR_GLOBAL const Light* l, float3 p, float3 n);
PR_LIGHT_TYPES(PR_LIGHT_DECLARE)
#undef PR_LIGHT_DECLARE

// A type's flags (PR_LIGHT_ON_TRIANGLE ...), and the queries callers make of them.
#define PR_LIGHT_FLAGS_CASE(name, fn, flags) \
  case PR_LIGHT_##name:                      \
    return flags;
PR_INLINE u32 light_type_flags(u32 type) {
  switch (type) { PR_LIGHT_TYPES(PR_LIGHT_FLAGS_CASE) }
  return 0u;
}
#undef PR_LIGHT_FLAGS_CASE

// An emissive triangle of the scene: its points, normal and emission come from the triangle.
PR_INLINE int light_is_triangle(u32 type) {
  return (light_type_flags(type) & PR_LIGHT_ON_TRIANGLE) != 0u;
}
// Delta in position or direction: BSDF-sampled rays never reach it, so no MIS.
PR_INLINE int light_is_delta(u32 type) {
  return (light_type_flags(type) & (PR_LIGHT_DELTA_POSITION | PR_LIGHT_DELTA_DIRECTION)) != 0u;
}
PR_INLINE int light_at_infinity(u32 type) {
  return (light_type_flags(type) & PR_LIGHT_AT_INFINITY) != 0u;
}
PR_INLINE int light_joins_vertex0(u32 type) {
  return (light_type_flags(type) & PR_LIGHT_JOINS_VERTEX0) != 0u;
}
PR_INLINE int light_in_eye_paths(u32 type) {
  return (light_type_flags(type) & PR_LIGHT_EYE_PATHS) != 0u;
}

// Emissive triangles, sampled by solid angle or area (use_solid_angle) and emitting on both
// faces, as in Blender and Cycles. (*b1, *b2): the barycentrics of the point, for emission
// textures.
PR_INLINE int light_triangle_sample(const Light* l, PR_GLOBAL const float* data, float pmf,
                                    float3 ref, float3 n_ref, float u1, float u2, LightSample* s,
                                    float* b1, float* b2) {
  (void)data;
  s->le = make_float3(l->le_r, l->le_g, l->le_b);
  const float3 v0 = make_float3(l->p0x, l->p0y, l->p0z);
  const float3 e1 = make_float3(l->e1x, l->e1y, l->e1z), e2 = make_float3(l->e2x, l->e2y, l->e2z);
  const float3 cr = cross(e1, e2);
  const float cl = length(cr);
  if (cl <= 0.0f) return 0;
  s->normal = cr / cl;
  SphericalTriangle st;
  const float omega = spherical_triangle(ref, v0, e1, e2, &st);
  const int solid = use_solid_angle(omega);
  float warp_pdf = 1.0f;
  if (solid && has_normal(n_ref)) {
    const CosineWarp cw = cosine_warp(&st, n_ref);
    const float2 uw = sample_bilinear(u1, u2, cw.w00, cw.w10, cw.w01, cw.w11);
    warp_pdf = bilinear_pdf(uw, cw.w00, cw.w10, cw.w01, cw.w11);
    u1 = uw.x;
    u2 = uw.y;
  }
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
  s->pdf = solid ? pmf * warp_pdf / omega : pmf * d2 / (cos_l * l->area);
  *b1 = b.x;
  *b2 = b.y;
  return 1;
}

PR_INLINE float light_triangle_pdf(const Light* l, PR_GLOBAL const float* data, float pmf,
                                   float3 ref, float3 n_ref, float3 pos, float3 wi) {
  (void)data;
  (void)wi;
  return light_pdf_triangle(pmf, ref, n_ref, pos, make_float3(l->p0x, l->p0y, l->p0z),
                            make_float3(l->e1x, l->e1y, l->e1z),
                            make_float3(l->e2x, l->e2y, l->e2z));
}

// Cosine-weighted about the face n0 already chosen (each face with probability 1/2: pdf
// cos / (2 pi)).
PR_INLINE float light_triangle_sample_emit(const Light* l, PR_GLOBAL const float* data, float3 n0,
                                           float u1, float u2, float3* dir, float3* le) {
  (void)data;
  float3 t, b;
  orthonormal_basis(n0, &t, &b);
  const float3 wl = sample_cosine_hemisphere(u1, u2);
  *dir = normalize(to_world(wl, t, b, n0));
  *le = make_float3(l->le_r, l->le_g, l->le_b);
  return wl.z * (0.5f * PR_INV_PI);
}

// Whichever face (n0 or -n0) the path chose.
PR_INLINE float light_triangle_pdf_emit(const Light* l, float3 n0, float3 dir) {
  (void)l;
  return fabs(dot(n0, dir)) * (0.5f * PR_INV_PI);
}

PR_INLINE float light_triangle_falloff(const Light* l, float3 dir) {
  (void)l;
  (void)dir;
  return 1.0f;
}

PR_INLINE float light_triangle_power(const Light* l, float scene_radius) {
  (void)scene_radius;
  return luminance(make_float3(l->le_r, l->le_g, l->le_b)) * PR_PI * l->area;
}

// The radiance times the solid angle the triangle subtends times the receiver's cosine: near
// it (the squared distance to its centroid under twice the sum of two edges' squares), the
// exact solid angle times the cosine averaged over its corners and centroid; farther, its area
// projected from the centroid, which is close to the solid angle there and costs a fraction of
// it. Zero only behind the receiver's normal or in the triangle's plane.
PR_INLINE float light_triangle_importance(PR_GLOBAL const Light* l, float3 p, float3 n) {
  // The mean radiance, its emission texture's included (the host's power: le x share x pi A).
  if (!(l->area > 0.0f)) return 0.0f;
  const float lum = l->power * PR_INV_PI / l->area;
  const int normal = has_normal(n);
  const float3 v0 = make_float3(l->p0x, l->p0y, l->p0z);
  const float3 e1 = make_float3(l->e1x, l->e1y, l->e1z), e2 = make_float3(l->e2x, l->e2y, l->e2z);
  const float3 d = v0 + (e1 + e2) * (1.0f / 3.0f) - p;  // to the centroid
  const float d2 = dot(d, d);
  if (!(d2 > 0.0f)) return 0.0f;
  if (normal) {  // the whole triangle below n (its points are blends of its corners)
    const float h0 = dot(n, v0 - p);
    if (!(fmax(h0, fmax(h0 + dot(n, e1), h0 + dot(n, e2))) > 0.0f)) return 0.0f;
  }
  float omega = 0.0f, cos_r = 1.0f;
  if (d2 < 2.0f * (dot(e1, e1) + dot(e2, e2))) {
    SphericalTriangle st;
    omega = spherical_triangle(p, v0, e1, e2, &st);
    if (omega > 0.0f && normal)
      cos_r = 0.25f * (fmax(dot(n, st.a), 0.0f) + fmax(dot(n, st.b), 0.0f) +
                       fmax(dot(n, st.c), 0.0f) + fmax(dot(n, d) * rsqrt(d2), 0.0f));
  }
  if (!(omega > 0.0f)) {
    omega = 0.5f * fabs(dot(cross(e1, e2), d)) / (d2 * sqrt(d2));
    // A corner above n where the centroid is not: a small cosine keeps the light possible.
    if (normal) {
      const float c = dot(n, d) * rsqrt(d2);
      cos_r = c > 0.0f ? c : 0.01f;
    }
  }
  return omega > 0.0f && isfinite_f(omega) ? fmax(lum * omega * cos_r, 0.0f) : 0.0f;
}

// Point and spot lights: the light's position as seen from ref, and the intensity unattenuated.
// Returns the squared distance (s->dist and s->wi set where it is > 0).
PR_INLINE float light_position_sample(const Light* l, float pmf, float3 ref, LightSample* s) {
  s->le = make_float3(l->le_r, l->le_g, l->le_b);
  s->normal = make_float3(0.0f, 0.0f, 0.0f);
  s->pdf = pmf;
  s->pos = make_float3(l->p0x, l->p0y, l->p0z);
  const float3 d = s->pos - ref;
  const float d2 = dot(d, d);
  if (d2 <= 0.0f) return d2;
  s->dist = sqrt(d2);
  s->wi = d / s->dist;
  return d2;
}

// The intensity (spot falloff included) times the receiver's cosine over the squared distance:
// exact for point and spot lights.
PR_INLINE float light_position_importance(PR_GLOBAL const Light* l, float3 p, float3 n, int spot) {
  const float lum = luminance(make_float3(l->le_r, l->le_g, l->le_b));
  const int normal = has_normal(n);
  const float3 v0 = make_float3(l->p0x, l->p0y, l->p0z);
  const float3 d = v0 - p;
  const float d2 = dot(d, d);
  if (!(d2 > 0.0f)) return 0.0f;
  const float3 wi = d * rsqrt(d2);
  float importance = lum / d2;
  if (spot)
    importance *=
        spot_attenuation(dot(-wi, make_float3(l->e1x, l->e1y, l->e1z)), l->cos_inner, l->cos_outer);
  if (normal) importance *= fmax(dot(n, wi), 0.0f);
  return isfinite_f(importance) ? importance : 0.0f;
}

// Point lights: isotropic intensity le.
PR_INLINE int light_point_sample(const Light* l, PR_GLOBAL const float* data, float pmf, float3 ref,
                                 float3 n_ref, float u1, float u2, LightSample* s, float* b1,
                                 float* b2) {
  (void)data, (void)n_ref, (void)u1, (void)u2, (void)b1, (void)b2;
  const float d2 = light_position_sample(l, pmf, ref, s);
  if (d2 <= 0.0f) return 0;
  const float att = 1.0f / d2;
  s->le = s->le * att;  // intensity / r^2 = irradiance at ref, normal to wi
  return att > 0.0f;
}

PR_INLINE float light_point_pdf(const Light* l, PR_GLOBAL const float* data, float pmf, float3 ref,
                                float3 n_ref, float3 pos, float3 wi) {
  (void)l, (void)data, (void)pmf, (void)ref, (void)n_ref, (void)pos, (void)wi;
  return 0.0f;
}

// Uniform on the sphere.
PR_INLINE float light_point_sample_emit(const Light* l, PR_GLOBAL const float* data, float3 n0,
                                        float u1, float u2, float3* dir, float3* le) {
  (void)data, (void)n0;
  *dir = sample_uniform_sphere(u1, u2);
  *le = make_float3(l->le_r, l->le_g, l->le_b);
  return 0.25f * PR_INV_PI;
}

PR_INLINE float light_point_pdf_emit(const Light* l, float3 n0, float3 dir) {
  (void)l, (void)n0, (void)dir;
  return 0.25f * PR_INV_PI;
}

PR_INLINE float light_point_falloff(const Light* l, float3 dir) {
  (void)l, (void)dir;
  return 1.0f;
}

PR_INLINE float light_point_power(const Light* l, float scene_radius) {
  (void)scene_radius;
  return 4.0f * PR_PI * luminance(make_float3(l->le_r, l->le_g, l->le_b));
}

PR_INLINE float light_point_importance(PR_GLOBAL const Light* l, float3 p, float3 n) {
  return light_position_importance(l, p, n, 0);
}

// Spot lights: intensity le about the axis e1, with KHR_lights_punctual's falloff between the
// outer and inner cone.
PR_INLINE int light_spot_sample(const Light* l, PR_GLOBAL const float* data, float pmf, float3 ref,
                                float3 n_ref, float u1, float u2, LightSample* s, float* b1,
                                float* b2) {
  (void)data, (void)n_ref, (void)u1, (void)u2, (void)b1, (void)b2;
  const float d2 = light_position_sample(l, pmf, ref, s);
  if (d2 <= 0.0f) return 0;
  float att = 1.0f / d2;
  att *= spot_attenuation(dot(-s->wi, make_float3(l->e1x, l->e1y, l->e1z)), l->cos_inner,
                          l->cos_outer);
  s->le = s->le * att;
  return att > 0.0f;
}

PR_INLINE float light_spot_pdf(const Light* l, PR_GLOBAL const float* data, float pmf, float3 ref,
                               float3 n_ref, float3 pos, float3 wi) {
  (void)l, (void)data, (void)pmf, (void)ref, (void)n_ref, (void)pos, (void)wi;
  return 0.0f;
}

// Uniform in the outer cone.
PR_INLINE float light_spot_sample_emit(const Light* l, PR_GLOBAL const float* data, float3 n0,
                                       float u1, float u2, float3* dir, float3* le) {
  (void)data, (void)n0;
  const float3 axis = make_float3(l->e1x, l->e1y, l->e1z);
  float3 t, b;
  orthonormal_basis(axis, &t, &b);
  *dir = normalize(to_world(sample_uniform_cone(u1, u2, l->cos_outer), t, b, axis));
  *le = make_float3(l->le_r, l->le_g, l->le_b);
  return 1.0f / (2.0f * PR_PI * (1.0f - l->cos_outer));
}

// Uniform in the outer cone about the axis, 0 outside it; dir leaves the light.
PR_INLINE float light_spot_pdf_emit(const Light* l, float3 n0, float3 dir) {
  (void)n0;
  if (!(dot(dir, make_float3(l->e1x, l->e1y, l->e1z)) >= l->cos_outer)) return 0.0f;
  return 1.0f / (2.0f * PR_PI * (1.0f - l->cos_outer));
}

PR_INLINE float light_spot_falloff(const Light* l, float3 dir) {
  return spot_attenuation(dot(dir, make_float3(l->e1x, l->e1y, l->e1z)), l->cos_inner,
                          l->cos_outer);
}

PR_INLINE float light_spot_power(const Light* l, float scene_radius) {
  (void)scene_radius;
  const float lum = luminance(make_float3(l->le_r, l->le_g, l->le_b));
  return 2.0f * PR_PI * (1.0f - 0.5f * (l->cos_inner + l->cos_outer)) * lum;
}

PR_INLINE float light_spot_importance(PR_GLOBAL const Light* l, float3 p, float3 n) {
  return light_position_importance(l, p, n, 1);
}

// Directional lights: irradiance le travelling along e1, from far away.
PR_INLINE int light_directional_sample(const Light* l, PR_GLOBAL const float* data, float pmf,
                                       float3 ref, float3 n_ref, float u1, float u2, LightSample* s,
                                       float* b1, float* b2) {
  (void)data, (void)n_ref, (void)u1, (void)u2, (void)b1, (void)b2;
  s->le = make_float3(l->le_r, l->le_g, l->le_b);
  s->normal = make_float3(0.0f, 0.0f, 0.0f);
  s->pdf = pmf;
  s->wi = -make_float3(l->e1x, l->e1y, l->e1z);
  s->dist = PR_INF_F;
  s->pos = ref + s->wi * 1e7f;
  return 1;
}

PR_INLINE float light_directional_pdf(const Light* l, PR_GLOBAL const float* data, float pmf,
                                      float3 ref, float3 n_ref, float3 pos, float3 wi) {
  (void)l, (void)data, (void)pmf, (void)ref, (void)n_ref, (void)pos, (void)wi;
  return 0.0f;
}

// Along its direction: a delta, pdf 1.
PR_INLINE float light_directional_sample_emit(const Light* l, PR_GLOBAL const float* data,
                                              float3 n0, float u1, float u2, float3* dir,
                                              float3* le) {
  (void)data, (void)n0, (void)u1, (void)u2;
  *dir = make_float3(l->e1x, l->e1y, l->e1z);
  *le = make_float3(l->le_r, l->le_g, l->le_b);
  return 1.0f;
}

PR_INLINE float light_directional_pdf_emit(const Light* l, float3 n0, float3 dir) {
  (void)l, (void)n0, (void)dir;
  return 0.0f;
}

PR_INLINE float light_directional_falloff(const Light* l, float3 dir) {
  (void)l, (void)dir;
  return 1.0f;
}

// Through the disk of radius scene_radius that covers the scene.
PR_INLINE float light_directional_power(const Light* l, float scene_radius) {
  const float lum = luminance(make_float3(l->le_r, l->le_g, l->le_b));
  return PR_PI * scene_radius * scene_radius * lum;
}

// 0: directional lights are chosen by power, outside the light BVH.
PR_INLINE float light_directional_importance(PR_GLOBAL const Light* l, float3 p, float3 n) {
  (void)l, (void)p, (void)n;
  return 0.0f;
}

// The dispatchers: one switch over PR_LIGHT_TYPES each, calling PR_LIGHT_CALL(fn) for the type.
#define PR_LIGHT_CASE(name, fn, flags) \
  case PR_LIGHT_##name:                \
    return PR_LIGHT_CALL(fn);

// Samples a point on light l (chosen with probability pmf) as seen from ref, whose shading
// normal is n_ref (zero: none, no cosine warp). Returns 0 when the sample carries no light. For
// triangles, (*b1, *b2) are the barycentrics of the point, for emission textures.
PR_INLINE int light_sample_towards(const Light* l, PR_GLOBAL const float* data, float pmf,
                                   float3 ref, float3 n_ref, float u1, float u2, LightSample* s,
                                   float* b1, float* b2) {
  s->delta = light_is_delta(l->type);
  *b1 = 0.0f;
  *b2 = 0.0f;
#define PR_LIGHT_CALL(fn) light_##fn##_sample(l, data, pmf, ref, n_ref, u1, u2, s, b1, b2)
  switch (l->type) { PR_LIGHT_TYPES(PR_LIGHT_CASE) }
#undef PR_LIGHT_CALL
  return 0;
}

// light_sample_towards for a light that needs no data buffer (all but the environment).
PR_INLINE int light_sample(const Light* l, float pmf, float3 ref, float3 n_ref, float u1, float u2,
                           LightSample* s, float* b1, float* b2) {
  return light_sample_towards(l, (PR_GLOBAL const float*)0, pmf, ref, n_ref, u1, u2, s, b1, b2);
}

// The solid-angle pdf with which light_sample_towards from ref (shading normal n_ref) gives the
// point pos of l, in unit direction wi from ref; 0 for delta lights.
PR_INLINE float light_pdf_towards(const Light* l, PR_GLOBAL const float* data, float pmf,
                                  float3 ref, float3 n_ref, float3 pos, float3 wi) {
#define PR_LIGHT_CALL(fn) light_##fn##_pdf(l, data, pmf, ref, n_ref, pos, wi)
  switch (l->type) { PR_LIGHT_TYPES(PR_LIGHT_CASE) }
#undef PR_LIGHT_CALL
  return 0.0f;
}

// The direction in which a light path leaves vertex 0 of l (n0: the face chosen on a
// triangle), its solid-angle pdf (1: a delta direction), and in *le the emission along it
// before light_falloff.
PR_INLINE float light_sample_emit(const Light* l, PR_GLOBAL const float* data, float3 n0, float u1,
                                  float u2, float3* dir, float3* le) {
#define PR_LIGHT_CALL(fn) light_##fn##_sample_emit(l, data, n0, u1, u2, dir, le)
  switch (l->type) { PR_LIGHT_TYPES(PR_LIGHT_CASE) }
#undef PR_LIGHT_CALL
  *dir = make_float3(0.0f, 0.0f, 1.0f);
  *le = make_float3(0.0f, 0.0f, 0.0f);
  return 0.0f;
}

// light_sample_emit's direction and pdf, for a light that needs no data buffer.
PR_INLINE float light_sample_emit_dir(const Light* l, float3 n0, float u1, float u2, float3* dir) {
  float3 le;
  return light_sample_emit(l, (PR_GLOBAL const float*)0, n0, u1, u2, dir, &le);
}

// The solid-angle pdf with which a light path leaves vertex 0 of l along dir where strategy E
// joins that vertex (light_joins_vertex0), whichever face of a triangle (n0 or -n0) it chose;
// 0 for the other lights.
PR_INLINE float light_pdf_emit_dir(const Light* l, float3 n0, float3 dir) {
#define PR_LIGHT_CALL(fn) light_##fn##_pdf_emit(l, n0, dir)
  switch (l->type) { PR_LIGHT_TYPES(PR_LIGHT_CASE) }
#undef PR_LIGHT_CALL
  return 0.0f;
}

// The share of its emission that l sends along dir, leaving it: a spot's cone; 1 elsewhere.
PR_INLINE float light_falloff(const Light* l, float3 dir) {
#define PR_LIGHT_CALL(fn) light_##fn##_falloff(l, dir)
  switch (l->type) { PR_LIGHT_TYPES(PR_LIGHT_CASE) }
#undef PR_LIGHT_CALL
  return 0.0f;
}

// The selection weight of a light by power: the luminance of the flux it emits (a directional
// light's or the environment's through the disk of radius scene_radius that covers the scene).
// The host builds the power tables and the light BVH from it.
PR_INLINE float light_power(const Light* l, float scene_radius) {
#define PR_LIGHT_CALL(fn) light_##fn##_power(l, scene_radius)
  switch (l->type) { PR_LIGHT_TYPES(PR_LIGHT_CASE) }
#undef PR_LIGHT_CALL
  return 0.0f;
}

// What a receiver at p with shading normal n (zero: none) can expect from light l were nothing
// in between, as the luminance of its irradiance: exact for punctual lights and close for
// triangles; 0 for lights outside the light BVH. Zero only where l sends p nothing: behind the
// receiver's normal (every non-delta BSDF only reflects) or in a triangle's plane.
PR_INLINE float light_receiver_importance(PR_GLOBAL const Light* l, float3 p, float3 n) {
#define PR_LIGHT_CALL(fn) light_##fn##_importance(l, p, n)
  switch (l->type) { PR_LIGHT_TYPES(PR_LIGHT_CASE) }
#undef PR_LIGHT_CALL
  return 0.0f;
}
#undef PR_LIGHT_CASE

// One step of weighted reservoir sampling driven by a single uniform *u: adds w (> 0) to *w_sum
// and says whether this item replaces the kept one (probability w / *w_sum), rescaling *u so
// that it stays uniform for the next step.
PR_INLINE int reservoir_keep(float w, float* w_sum, float* u) {
  *w_sum += w;
  const float keep = w / *w_sum;
  if (*u < keep) {
    *u = fmin(*u / keep, PR_ONE_MINUS_EPSILON);
    return 1;
  }
  *u = fmin((*u - keep) / (1.0f - keep), PR_ONE_MINUS_EPSILON);
  return 0;
}

// Chooses one of lights[0, count) for the receiver (p, n) in proportion to
// light_receiver_importance, in one pass (reservoir_keep); *pmf is the probability of the
// choice. Every light is weighed, so this is for few
// lights. PR_INVALID_INDEX where none reaches p.
PR_INLINE u32 light_exhaustive_sample(PR_GLOBAL const Light* lights, u32 count, float3 p, float3 n,
                                      float u, float* pmf) {
  u32 chosen = PR_INVALID_INDEX;
  float sum = 0.0f, chosen_w = 0.0f;
  for (u32 i = 0u; i < count; ++i) {
    const float w = light_receiver_importance(lights + i, p, n);
    if (w > 0.0f && reservoir_keep(w, &sum, &u)) {
      chosen = i;
      chosen_w = w;
    }
  }
  *pmf = chosen != PR_INVALID_INDEX && sum > 0.0f && isfinite_f(sum) ? chosen_w / sum : 0.0f;
  return *pmf > 0.0f ? chosen : PR_INVALID_INDEX;
}

// The probability that light_exhaustive_sample chooses `light` for the receiver (p, n).
PR_INLINE float light_exhaustive_pmf(PR_GLOBAL const Light* lights, u32 count, u32 light, float3 p,
                                     float3 n) {
  if (light >= count) return 0.0f;
  float sum = 0.0f, w = 0.0f;
  for (u32 i = 0u; i < count; ++i) {
    const float wi = light_receiver_importance(lights + i, p, n);
    if (!(wi > 0.0f)) continue;
    sum += wi;
    if (i == light) w = wi;
  }
  return sum > 0.0f && isfinite_f(sum) ? w / sum : 0.0f;
}

// Tree candidates per choice: the light BVH's bounds are loose where a point is among many
// lights, so PR_LIGHT_CANDIDATES lights are drawn through it (stratified in u) and one is kept in
// proportion to light_receiver_importance over its tree pmf (resampled importance sampling,
// Talbot 2005). Measured on the many-lights atrium: docs/experiments/light-bvh.md.
#ifndef PR_LIGHT_CANDIDATES
#define PR_LIGHT_CANDIDATES 2u
#endif

// The resampled choice through the tree: ut draws the candidates, ur keeps one
// (reservoir_keep). Returns the light and, in *weight, the inverse of its contribution
// weight: an estimate over which 1 / *weight is unbiased for the light's share (*weight is
// not a pmf, but 1{chosen = l} / *weight has expectation 1 for every light l that can reach
// p). *tree_pmf is the tree's own pmf of the chosen light, for MIS weights.
PR_INLINE u32 light_tree_resample(PR_GLOBAL const LightNode* nodes, PR_GLOBAL const Light* lights,
                                  float3 p, float3 n, float ut, float ur, float* weight,
                                  float* tree_pmf) {
  u32 chosen = PR_INVALID_INDEX;
  float w_sum = 0.0f, chosen_importance = 0.0f, chosen_pmf = 0.0f;
  for (u32 m = 0u; m < PR_LIGHT_CANDIDATES; ++m) {
    float pm;
    const float um =
        fmin(((float)m + ut) * (1.0f / (float)PR_LIGHT_CANDIDATES), PR_ONE_MINUS_EPSILON);
    const u32 c = light_bvh_sample(nodes, p, n, um, &pm);
    if (c == PR_INVALID_INDEX || !(pm > 0.0f)) continue;
    const float importance = light_receiver_importance(lights + c, p, n);
    if (!(importance > 0.0f)) continue;
    if (reservoir_keep(importance / pm, &w_sum, &ur)) {
      chosen = c;
      chosen_importance = importance;
      chosen_pmf = pm;
    }
  }
  const int ok = chosen != PR_INVALID_INDEX && w_sum > 0.0f && isfinite_f(w_sum);
  *weight = ok ? chosen_importance * (float)PR_LIGHT_CANDIDATES / w_sum : 0.0f;
  *tree_pmf = ok ? chosen_pmf : 0.0f;
  return ok && *weight > 0.0f ? chosen : PR_INVALID_INDEX;
}

// The light table as kernels see it (built from PR_ARGS_LIGHTS, shared/kernel_args.h).
typedef struct {
  PR_GLOBAL const Light* lights;
  PR_GLOBAL const float* cdf;        // running sum of power; cdf[count - 1] == total_power
  PR_GLOBAL const LightNode* nodes;  // the light BVH over lights [0, tree_count)
  // Per shading triangle: its light (SSG), or its rank among its mesh's emissive triangles (DSG,
  // added to the instance's first_light); PR_INVALID_INDEX where it is no light.
  PR_GLOBAL const u32* prim_light;
  PR_GLOBAL const float* env;  // the environment's map and tables (shared/environment.h)
  u32 count;
  u32 tree_count;  // directional lights and the environment come after the tree's
  float total_power;
  u32 env_light;  // the environment's index, or PR_INVALID_INDEX
  // --shutter: the punctual lights [motion_first, motion_first + motion_count) at each of
  // motion_steps times over the interval (shared/motion.h), light by light.
  PR_GLOBAL const Light* motion;
  u32 motion_first, motion_count, motion_steps;
  // --shutter: sweep_count records (a box, lo xyz hi xyz, and its count of part records that
  // follow; host/render/sweeps.h) that hold what moves while the shutter is open, which stored
  // light paths must not meet to be joined at any time (sweep_clear).
  PR_GLOBAL const float* sweeps;
  u32 sweep_count;
  // --shutter: 1 where the camera moves while the shutter is open (camera_segment_still).
  u32 camera_moves;
} LightData;

// The receiver-aware choice among lights [0, tree_count) with ut (and ur, the tree's
// resampling), by PR_LIGHT_SAMPLER: *choice divides the light's contribution, *tree_pmf is the
// pmf for MIS weights (light_choose).
PR_INLINE u32 light_choose_in_tree(const LightData* d, float3 p, float3 n, float ut, float ur,
                                   float* choice, float* tree_pmf) {
  if (PR_LIGHT_SAMPLER == PR_LIGHT_SAMPLER_EXHAUSTIVE) {
    const u32 j = light_exhaustive_sample(d->lights, d->tree_count, p, n, ut, choice);
    *tree_pmf = *choice;
    return j;
  }
  return light_tree_resample(d->nodes, d->lights, p, n, ut, ur, choice, tree_pmf);
}

// Chooses a light for the receiver at p with shading normal n (zero: none) with u (and ur, for
// the tree's resampling). *pmf divides the light's contribution: the probability of the choice,
// or through the tree the inverse contribution weight of its resampling. *mis_pmf is what
// light_choice_pmf gives the light, for MIS weights against BSDF sampling (any pmf that both
// sides use keeps the weights adding to 1). A light at infinity is chosen by its share of the
// power, the tree (or the exhaustive choice) as a whole by the share of the others; by power
// alone, every light by its share. PR_INVALID_INDEX where no light can reach p.
PR_INLINE u32 light_choose(const LightData* d, float3 p, float3 n, float u, float ur, float* pmf,
                           float* mis_pmf) {
  *pmf = 0.0f;
  *mis_pmf = 0.0f;
  if (d->count == 0u || !(d->total_power > 0.0f)) return PR_INVALID_INDEX;
  const int by_receiver = PR_LIGHT_SAMPLER != PR_LIGHT_SAMPLER_POWER;
  const float share =
      by_receiver && d->tree_count > 0u ? d->cdf[d->tree_count - 1u] / d->total_power : 0.0f;
  if (u < share) {
    const float ut = fmin(u / share, PR_ONE_MINUS_EPSILON);
    float choice, tree_pmf;
    const u32 j = light_choose_in_tree(d, p, n, ut, ur, &choice, &tree_pmf);
    *pmf = share * choice;
    *mis_pmf = share * tree_pmf;
    return j;
  }
  // By power: with a receiver-aware sampler, a light at infinity (the rounding of u * total at
  // the boundary aside).
  const u32 found = light_select(d->cdf, d->count, u);
  const u32 i = by_receiver && found < d->tree_count ? d->tree_count : found;
  *pmf = *mis_pmf = d->lights[i].power / d->total_power;
  return i;
}

// The probability that light_choose picks `light` for the receiver (p, n).
PR_INLINE float light_choice_pmf(const LightData* d, u32 light, float3 p, float3 n) {
  if (light >= d->count || !(d->total_power > 0.0f)) return 0.0f;
  if (PR_LIGHT_SAMPLER != PR_LIGHT_SAMPLER_POWER && light < d->tree_count) {
    const float share = d->cdf[d->tree_count - 1u] / d->total_power;
    if (PR_LIGHT_SAMPLER == PR_LIGHT_SAMPLER_EXHAUSTIVE)
      return share * light_exhaustive_pmf(d->lights, d->tree_count, light, p, n);
    return share * light_bvh_pmf(d->nodes, d->lights[light].leaf, p, n);
  }
  return d->lights[light].power / d->total_power;
}

PR_NAMESPACE_END

#ifdef PR_DEVICE_CODE
PR_ARG_GATHER(LightData, pr_light_data, PR_ARGS_LIGHTS)
#endif

PR_STATIC_ASSERT(sizeof(pr::dev::Light) == 96, "Light layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Light, le_r) == 48, "Light layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Light, material) == 76, "Light layout");

// The environment's function set, declared above from PR_LIGHT_TYPES (its header includes this
// one: either may come first).
#include "shared/environment.h"
