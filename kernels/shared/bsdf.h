// BSDFs in a local shading frame (normal = +Z): glTF metallic-roughness as Lambert + GGX
// (glTF 2.0 specification, appendix B: fresnel_mix of a dielectric layer over diffuse, and a
// conductor with Schlick's Fresnel on baseColor), with KHR_materials_specular's F0 colour and
// F90 and KHR_materials_clearcoat's GGX coat layered on top as those extensions define it;
// a delta mirror and a delta dielectric.
// wo points towards the previous vertex (camera side on eye paths), wi towards the next.
// Values returned by eval are f (no cosine); pdfs are per solid angle.
#pragma once

#include "shared/math.h"
#include "shared/sampling.h"

PR_NAMESPACE_BEGIN

#define PR_BSDF_MICROFACET 0u
#define PR_BSDF_MIRROR 1u
#define PR_BSDF_GLASS 2u
#define PR_BSDF_LAMBERT 3u  // pure Lambert (--force-diffuse: exact albedo, for furnace tests)

// Transport mode: radiance (eye paths) or importance (light paths); only refraction differs.
#define PR_RADIANCE 0
#define PR_IMPORTANCE 1

// The smallest GGX alpha used for non-delta surfaces: sharper lobes would be delta in practice
// and only add fireflies.
#define PR_MIN_ALPHA 0.0025f

typedef struct {
  float3 base;  // linear base colour
  float3 f0;    // the dielectric layer's Fresnel at normal incidence (0.04: ior 1.5)
  float f90;    // ... and at grazing incidence (1)
  float metallic;
  float alpha;  // GGX alpha = roughness^2, >= PR_MIN_ALPHA
  float ior;
  float coat;        // clearcoat weight; 0: none
  float coat_alpha;  // the coat's GGX alpha, >= PR_MIN_ALPHA
  u32 kind;          // PR_BSDF_*
} BsdfParams;

// The coat's Fresnel (an ior 1.5 dielectric, as KHR_materials_clearcoat fixes it).
PR_INLINE float coat_fresnel(float w5) {
  return 0.04f + 0.96f * w5;
}

PR_INLINE int bsdf_is_delta(const BsdfParams* m) {
  return m->kind == PR_BSDF_MIRROR || m->kind == PR_BSDF_GLASS;
}

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

PR_INLINE float schlick_weight(float c) {
  const float m = clamp(1.0f - c, 0.0f, 1.0f);
  const float m2 = m * m;
  return m2 * m2 * m;
}

// Probability of sampling the specular lobe; a function of (material, wo) only, so that
// eval and sample agree on the mixture pdf.
PR_INLINE float bsdf_spec_probability(const BsdfParams* m, float cos_o) {
  const float w5 = schlick_weight(cos_o);
  // (A grey F0, as most materials have, by its one value: luminance would round it.)
  const float fd = (m->f0.x == m->f0.y && m->f0.y == m->f0.z)
                       ? m->f0.x + (m->f90 - m->f0.x) * w5
                       : luminance(m->f0 + (make_float3(m->f90, m->f90, m->f90) - m->f0) * w5);
  const float3 fm = m->base + (make_float3(1.0f, 1.0f, 1.0f) - m->base) * w5;
  const float ws = m->metallic * luminance(fm) + (1.0f - m->metallic) * fd;
  const float wd = (1.0f - m->metallic) * (1.0f - fd) * luminance(m->base);
  if (wd <= 0.0f) return 1.0f;
  if (ws <= 0.0f) return 0.0f;
  return clamp(ws / (ws + wd), 0.1f, 0.9f);
}

// Probability of sampling the clearcoat lobe (0 without a coat); a function of (material, wo).
PR_INLINE float bsdf_coat_probability(const BsdfParams* m, float cos_o) {
  if (!(m->coat > 0.0f)) return 0.0f;
  return clamp(2.0f * m->coat * coat_fresnel(schlick_weight(cos_o)), 0.05f, 0.5f);
}

// GGX specular reflection D G2 / (4 cos_o cos_i) for alpha^2 = a2 at half vector h, and the
// visible-normal pdf of wi (G1(wo) D / (4 cos_o)).
PR_INLINE float ggx_reflection(float3 wo, float3 wi, float3 h, float a2, float* pdf) {
  const float d = ggx_d(h.z, a2);
  const float lo = ggx_lambda(wo.z, a2), li = ggx_lambda(wi.z, a2);
  *pdf = d / ((1.0f + lo) * 4.0f * wo.z);
  return d / (1.0f + lo + li) / (4.0f * wo.z * wi.z);
}

// f(wo, wi), the pdf of sampling wi given wo and (pdf_rev) that of sampling wo given wi, for
// the microfacet model: one evaluation where a path needs its density both ways.
PR_INLINE float3 bsdf_eval_both(const BsdfParams* m, float3 wo, float3 wi, float* pdf,
                                float* pdf_rev) {
  *pdf = 0.0f;
  *pdf_rev = 0.0f;
  if (bsdf_is_delta(m) || wo.z <= 0.0f || wi.z <= 0.0f) return make_float3(0.0f, 0.0f, 0.0f);
  if (m->kind == PR_BSDF_LAMBERT) {
    *pdf = wi.z * PR_INV_PI;
    *pdf_rev = wo.z * PR_INV_PI;
    return m->base * PR_INV_PI;
  }
  const float a2 = m->alpha * m->alpha;
  float3 h = wo + wi;
  const float hl = length(h);
  if (hl <= 0.0f) return make_float3(0.0f, 0.0f, 0.0f);
  h = h / hl;
  const float voh = fmax(dot(wo, h), 0.0f);
  const float d = ggx_d(h.z, a2);
  const float lo = ggx_lambda(wo.z, a2), li = ggx_lambda(wi.z, a2);
  const float g2 = 1.0f / (1.0f + lo + li);
  const float spec = d * g2 / (4.0f * wo.z * wi.z);
  const float w5 = schlick_weight(voh);
  // fresnel_mix with a coloured F: specular where reflected, diffuse where not.
  const float3 fd = m->f0 + (make_float3(m->f90, m->f90, m->f90) - m->f0) * w5;
  const float3 fm = m->base + (make_float3(1.0f, 1.0f, 1.0f) - m->base) * w5;
  const float3 dielectric =
      fd * spec + m->base * ((make_float3(1.0f, 1.0f, 1.0f) - fd) * PR_INV_PI);
  float3 f = dielectric * (1.0f - m->metallic) + fm * (spec * m->metallic);
  // VNDF pdf: G1(wo) D(h) / (4 cos_o). The reverse: the same with wo and wi swapped (h and
  // v.h are symmetric).
  const float ps = bsdf_spec_probability(m, wo.z);
  const float pdf_spec = d / ((1.0f + lo) * 4.0f * wo.z);
  const float pdf_diff = wi.z * PR_INV_PI;
  *pdf = ps * pdf_spec + (1.0f - ps) * pdf_diff;
  const float ps_rev = bsdf_spec_probability(m, wi.z);
  *pdf_rev = ps_rev * (d / ((1.0f + li) * 4.0f * wi.z)) + (1.0f - ps_rev) * (wo.z * PR_INV_PI);
  if (m->coat > 0.0f) {
    // The coat over the rest: mix(base, coat specular, coat x its Fresnel).
    const float fc = m->coat * coat_fresnel(w5);
    const float ca2 = m->coat_alpha * m->coat_alpha;
    float pdf_coat;
    const float coat_spec = ggx_reflection(wo, wi, h, ca2, &pdf_coat) * fc;
    f = f * (1.0f - fc) + make_float3(coat_spec, coat_spec, coat_spec);
    const float pc = bsdf_coat_probability(m, wo.z);
    *pdf = pc * pdf_coat + (1.0f - pc) * *pdf;
    const float pc_rev = bsdf_coat_probability(m, wi.z);
    const float pdf_coat_rev = ggx_d(h.z, ca2) / ((1.0f + ggx_lambda(wi.z, ca2)) * 4.0f * wi.z);
    *pdf_rev = pc_rev * pdf_coat_rev + (1.0f - pc_rev) * *pdf_rev;
  }
  return f;
}

// f(wo, wi) and the pdf of sampling wi given wo.
PR_INLINE float3 bsdf_eval(const BsdfParams* m, float3 wo, float3 wi, float* pdf) {
  float pdf_rev;  // unused: the compiler drops its arithmetic
  return bsdf_eval_both(m, wo, wi, pdf, &pdf_rev);
}

// Visible-normal sampling of GGX (Heitz 2018, isotropic).
PR_INLINE float3 ggx_sample_vndf(float3 wo, float alpha, float u1, float u2) {
  const float3 vh = normalize(make_float3(alpha * wo.x, alpha * wo.y, wo.z));
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
  return normalize(make_float3(alpha * nh.x, alpha * nh.y, fmax(1e-6f, nh.z)));
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

// Samples wi given wo. Returns 0 when no direction is produced. *weight = f * |cos| / pdf (for
// delta lobes the same ratio with the delta cancelled), *pdf the solid-angle pdf (0 for delta).
PR_INLINE int bsdf_sample(const BsdfParams* m, float3 wo, float u0, float u1, float u2, int mode,
                          float3* wi, float3* weight, float* pdf, int* delta) {
  *delta = 0;
  *pdf = 0.0f;
  *weight = make_float3(0.0f, 0.0f, 0.0f);
  if (m->kind == PR_BSDF_MIRROR) {
    if (wo.z <= 0.0f) return 0;
    *wi = make_float3(-wo.x, -wo.y, wo.z);
    const float w5 = schlick_weight(wo.z);
    *weight = m->base + (make_float3(1.0f, 1.0f, 1.0f) - m->base) * w5;
    *delta = 1;
    return 1;
  }
  if (m->kind == PR_BSDF_GLASS) {
    const int entering = wo.z > 0.0f;
    const float eta = entering ? m->ior : 1.0f / m->ior;  // n_t / n_i
    const float cos_o = fabs(wo.z);
    const float fr = fresnel_dielectric(cos_o, eta);
    *delta = 1;
    if (u0 < fr) {
      *wi = make_float3(-wo.x, -wo.y, wo.z);
      *weight = make_float3(1.0f, 1.0f, 1.0f);
      return 1;
    }
    const float sin2_t = (1.0f - cos_o * cos_o) / (eta * eta);
    const float cos_t = sqrt(fmax(0.0f, 1.0f - sin2_t));
    // Refract in the frame flipped to the incident side, then flip back.
    const float3 wol = make_float3(wo.x, wo.y, cos_o);
    const float3 t = -wol / eta + make_float3(0.0f, 0.0f, cos_o / eta - cos_t);
    *wi = entering ? t : make_float3(t.x, t.y, -t.z);
    // Radiance is compressed by 1/eta^2 on entering a denser medium; importance is not.
    const float scale = mode == PR_RADIANCE ? 1.0f / (eta * eta) : 1.0f;
    *weight = m->base * scale;
    return 1;
  }
  if (wo.z <= 0.0f) return 0;
  if (m->kind == PR_BSDF_LAMBERT) {
    *wi = sample_cosine_hemisphere(u1, u2);
    if (wi->z <= 0.0f) return 0;
    *pdf = wi->z * PR_INV_PI;
    *weight = m->base;
    return 1;
  }
  const float pc = bsdf_coat_probability(m, wo.z);
  float3 dir;
  if (u0 < pc) {
    const float3 h = ggx_sample_vndf(wo, m->coat_alpha, u1, u2);
    dir = h * (2.0f * dot(wo, h)) - wo;
  } else {
    // The rest of u0 chooses between the base's lobes.
    const float ub = pc > 0.0f ? (u0 - pc) / (1.0f - pc) : u0;
    const float ps = bsdf_spec_probability(m, wo.z);
    if (ub < ps) {
      const float3 h = ggx_sample_vndf(wo, m->alpha, u1, u2);
      dir = h * (2.0f * dot(wo, h)) - wo;
    } else {
      dir = sample_cosine_hemisphere(u1, u2);
    }
  }
  if (dir.z <= 0.0f) return 0;
  float p = 0.0f;
  const float3 f = bsdf_eval(m, wo, dir, &p);
  if (p <= 0.0f) return 0;
  *wi = dir;
  *pdf = p;
  *weight = f * (dir.z / p);
  return 1;
}

PR_NAMESPACE_END
