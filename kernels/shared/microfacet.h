// Microfacet distributions shared by the BSDFs (kernels/shared/bsdf.h) and the tool that
// tabulates their albedos (tools/tables/bsdf_tables.cpp): GGX (isotropic and anisotropic, with
// visible-normal sampling), Schlick's Fresnel weight and the dielectric Fresnel, and the
// Charlie sheen distribution.
#pragma once

#include "shared/math.h"

// What a program compiles: the host builds each with the features its scene's materials use
// (-DPR_HAS_...=1 from GpuScene::buildOptions), since every lobe adds compile time at each of a
// kernel's many call sites; host code compiles them all. Branches on a feature left out fold
// away.
#ifdef PR_DEVICE_CODE
#ifndef PR_HAS_SHEEN
#define PR_HAS_SHEEN 0
#endif
#ifndef PR_HAS_COAT
#define PR_HAS_COAT 0
#endif
#ifndef PR_HAS_ANISOTROPY
#define PR_HAS_ANISOTROPY 0
#endif
#ifndef PR_HAS_GLTF_MODEL  // materials of the glTF model
#define PR_HAS_GLTF_MODEL 0
#endif
#ifndef PR_HAS_ENERGY_MODEL  // materials of the energy model
#define PR_HAS_ENERGY_MODEL 1
#endif
#else
#define PR_HAS_SHEEN 1
#define PR_HAS_COAT 1
#define PR_HAS_ANISOTROPY 1
#define PR_HAS_GLTF_MODEL 1
#define PR_HAS_ENERGY_MODEL 1
#endif

PR_NAMESPACE_BEGIN

// The smallest GGX alpha used for non-delta surfaces: sharper lobes would be delta in practice
// and only add fireflies.
#define PR_MIN_ALPHA 0.0025f
// The smallest sheen alpha (sheen roughness^2): the Charlie lobe's exponent is 1 / alpha.
#define PR_MIN_SHEEN_ALPHA 0.0025f
// The albedo tables' smallest roughness, sqrt of both of those.
#define PR_TABLE_MIN_ROUGHNESS 0.05f
// The rough-glass albedo table's iors, uniform in (ior - 1) / (ior + 1) between these.
#define PR_GLASS_TABLE_MIN_IOR 1.05f
#define PR_GLASS_TABLE_MAX_IOR 3.0f

// ---- GGX

PR_INLINE float ggx_d(float cos_h, float a2) {
  const float c2 = cos_h * cos_h;
  const float d = c2 * (a2 - 1.0f) + 1.0f;
  return a2 / (PR_PI * d * d);
}

// Smith's Lambda for GGX, for a direction with |cos| = c.
PR_INLINE float ggx_lambda(float c, float a2) {
  const float c2 = c * c;
  const float t2 = fmax(0.0f, 1.0f - c2) / fmax(c2, 1e-12f);
  return 0.5f * (-1.0f + sqrt(1.0f + a2 * t2));
}

// The anisotropic forms (alphas along x and y); the isotropic ones above where they are equal.
PR_INLINE float ggx_d_xy(float3 h, float ax, float ay) {
  if (!PR_HAS_ANISOTROPY || ax == ay) return ggx_d(h.z, ax * ax);
  const float x = h.x / ax, y = h.y / ay;
  const float d = x * x + y * y + h.z * h.z;
  return 1.0f / (PR_PI * ax * ay * d * d);
}

PR_INLINE float ggx_lambda_xy(float3 w, float ax, float ay) {
  if (!PR_HAS_ANISOTROPY || ax == ay) return ggx_lambda(w.z, ax * ax);
  const float t2 = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / fmax(w.z * w.z, 1e-12f);
  return 0.5f * (-1.0f + sqrt(1.0f + t2));
}

PR_INLINE float schlick_weight(float c) {
  const float m = clamp(1.0f - c, 0.0f, 1.0f);
  const float m2 = m * m;
  return m2 * m2 * m;
}

// The coat's Fresnel (an ior 1.5 dielectric, as KHR_materials_clearcoat fixes it) from the
// weight of its shape: Schlick's (1 - c)^5, or fresnel_dielectric_weight at PR_COAT_IOR.
#define PR_COAT_IOR 1.5f
PR_INLINE float coat_fresnel(float w) {
  return 0.04f + 0.96f * w;
}

// GGX specular reflection D G2 / (4 cos_o cos_i) for alpha^2 = a2, given the cosines of wo, wi
// and the half vector with the lobe's normal, and the visible-normal pdf of wi (G1(wo) D /
// (4 cos_o)).
PR_INLINE float ggx_reflection(float co, float ci, float ch, float a2, float* pdf) {
  const float d = ggx_d(ch, a2);
  const float lo = ggx_lambda(co, a2), li = ggx_lambda(ci, a2);
  *pdf = d / ((1.0f + lo) * 4.0f * co);
  return d / (1.0f + lo + li) / (4.0f * co * ci);
}

// Visible-normal sampling of GGX (Heitz 2018), alphas ax and ay along x and y.
PR_INLINE float3 ggx_sample_vndf(float3 wo, float ax, float ay, float u1, float u2) {
  const float3 vh = normalize(make_float3(ax * wo.x, ay * wo.y, wo.z));
  const float lensq = vh.x * vh.x + vh.y * vh.y;
  const float3 t1 =
      lensq > 0.0f ? make_float3(-vh.y, vh.x, 0.0f) / sqrt(lensq) : make_float3(1.0f, 0.0f, 0.0f);
  const float3 t2 = cross(vh, t1);
  const float r = sqrt(u1), phi = 2.0f * PR_PI * u2;
  const float p1 = r * cos(phi);
  float p2 = r * sin(phi);
  const float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * sqrt(fmax(0.0f, 1.0f - p1 * p1)) + s * p2;
  const float3 nh = t1 * p1 + t2 * p2 + vh * sqrt(fmax(0.0f, 1.0f - p1 * p1 - p2 * p2));
  return normalize(make_float3(ax * nh.x, ay * nh.y, fmax(1e-6f, nh.z)));
}

// ---- Sheen: the Charlie distribution with its fitted shadowing (Estevez and Kulla 2017), as
// KHR_materials_sheen defines it.

PR_INLINE float sheen_d(float cos_h, float a) {
  const float inv = 1.0f / a;
  const float sin2 = fmax(0.0f, 1.0f - cos_h * cos_h);
  return (2.0f + inv) * pow(sin2, 0.5f * inv) * (0.5f * PR_INV_PI);
}

PR_INLINE float sheen_l(float x, float a) {
  const float t = (1.0f - a) * (1.0f - a);
  const float pa = mix(21.5473f, 25.3245f, t), pb = mix(3.82987f, 3.32435f, t);
  const float pc = mix(0.19823f, 0.16801f, t), pd = mix(-1.97760f, -1.27393f, t);
  const float pe = mix(-4.32054f, -4.85967f, t);
  return pa / (1.0f + pb * pow(x, pc)) + pd * x + pe;
}

PR_INLINE float sheen_lambda(float c, float a) {
  return c < 0.5f ? exp(sheen_l(c, a)) : exp(2.0f * sheen_l(0.5f, a) - sheen_l(1.0f - c, a));
}

// The sheen lobe D V (white): V = 1 / ((1 + Lambda(o) + Lambda(i)) 4 cos_o cos_i).
PR_INLINE float sheen_lobe(float co, float ci, float ch, float a) {
  const float g = 1.0f / (1.0f + sheen_lambda(co, a) + sheen_lambda(ci, a));
  return sheen_d(ch, a) * g / (4.0f * co * ci);
}

PR_INLINE float fresnel_dielectric(float cos_i, float eta) {
  // eta = n_t / n_i; cos_i >= 0 on the incident side.
  const float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return 1.0f;
  const float cos_t = sqrt(1.0f - sin2_t);
  const float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5f * (rs * rs + rp * rp);
}

// The energy model's dielectric layers take the exact Fresnel's shape where Schlick's (1 - c)^5
// would stand (F = f0 + (f90 - f0) w), as Cycles' Principled BSDF does: the exact Fresnel of
// relative ior eta (clamped to the tables' PR_GLASS_TABLE_*_IOR) at cos c, run from 0 at normal
// incidence to 1 at grazing. At ior 1.5 and 45 degrees it is 5x Schlick's weight: a dark rough
// dielectric seen at 45 degrees reflected 14% less than Cycles' with Schlick's.
PR_INLINE float fresnel_dielectric_weight(float c, float eta) {
  const float n = clamp(eta, PR_GLASS_TABLE_MIN_IOR, PR_GLASS_TABLE_MAX_IOR);
  const float r = (n - 1.0f) / (n + 1.0f);
  const float f0 = r * r;
  return clamp((fresnel_dielectric(clamp(c, 0.0f, 1.0f), n) - f0) / (1.0f - f0), 0.0f, 1.0f);
}

PR_NAMESPACE_END
