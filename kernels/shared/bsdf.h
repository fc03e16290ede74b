// BSDFs in a local shading frame (normal = +Z, the frame's tangent = +X): glTF metallic-roughness
// with KHR_materials_specular (the dielectric layer's F0 colour and F90), _clearcoat, _sheen and
// _anisotropy, in one of two material models (BsdfParams.model):
//
// - PR_MODEL_ENERGY (the default) keeps the energy of a white non-absorbing material at every
//   angle and roughness: GGX with multiple-scattering compensation from precomputed albedo
//   tables (Kulla and Conty 2017, Turquin 2019, as Cycles' multiscatter GGX does), and layers
//   combined by albedo scaling (OpenPBR, Enterprise PBR): the coat over the sheen over the base,
//   the base a conductor or a dielectric specular layer over diffuse, each lower layer weighted
//   by what the layers above leave at the view direction.
// - PR_MODEL_GLTF is the glTF 2.0 specification's model as its appendix B and the extensions
//   write it (single-scattering GGX, fresnel_mix at V.H, the clearcoat's Fresnel at N.V, the
//   sheen's albedo scaling), kept for conformance comparisons.
//
// Both are one mixture of lobes (coat, sheen, GGX, diffuse) listed once in PR_BSDF_LOBES below,
// each lobe a function set; a delta mirror and a delta dielectric stand for smooth metals and
// transmission in both.
// wo points towards the previous vertex (camera side on eye paths), wi towards the next. The
// layered models are not reciprocal (a layer's albedo is taken at the view direction), so
// evaluation takes the transport mode: radiance (wo is the view) or importance (light paths:
// wi is the view, the adjoint BSDF). Values returned by eval are f (no cosine); pdfs are per
// solid angle and do not depend on the mode.
#pragma once

#include "shared/bsdf_tables.h"
#include "shared/math.h"
#include "shared/microfacet.h"
#include "shared/sampling.h"
#include "shared/sheen_tables.h"

PR_NAMESPACE_BEGIN

#define PR_BSDF_MICROFACET 0u
#define PR_BSDF_MIRROR 1u
#define PR_BSDF_GLASS 2u
#define PR_BSDF_LAMBERT 3u      // pure Lambert (--force-diffuse: exact albedo, for furnace tests)
#define PR_BSDF_ROUGH_GLASS 4u  // GGX dielectric: reflection and refraction (Walter et al. 2007)

#define PR_MODEL_ENERGY 0u  // energy-conserving layering, multiple-scattering GGX
#define PR_MODEL_GLTF 1u    // the glTF specification's single-scattering model

// Transport mode: radiance (eye paths) or importance (light paths).
#define PR_RADIANCE 0
#define PR_IMPORTANCE 1

typedef struct {
  float3 base;    // linear base colour (glass: what each refraction multiplies)
  float3 f0;      // the dielectric layer's Fresnel at normal incidence (0.04: ior 1.5)
  float3 sheen;   // KHR_materials_sheen colour; 0: no sheen
  float3 coat_n;  // the coat's normal in this frame ((0, 0, 1): the shading normal)
  float f90;      // the dielectric layer's Fresnel at grazing incidence (1)
  float metallic;
  float alpha_x, alpha_y;  // GGX alphas along the frame's tangent and bitangent, >= PR_MIN_ALPHA
  float ior;
  float coat;         // clearcoat weight; 0: none
  float coat_alpha;   // the coat's GGX alpha, >= PR_MIN_ALPHA
  float sheen_alpha;  // the sheen's alpha (roughness^2), >= PR_MIN_SHEEN_ALPHA
  u32 kind;           // PR_BSDF_*
  u32 model;          // PR_MODEL_*
} BsdfParams;

// A rough white dielectric of the default model, every extension off: callers set what differs.
PR_INLINE BsdfParams bsdf_params_default(void) {
  BsdfParams p;
  p.base = make_float3(1.0f, 1.0f, 1.0f);
  p.f0 = make_float3(0.04f, 0.04f, 0.04f);
  p.sheen = make_float3(0.0f, 0.0f, 0.0f);
  p.coat_n = make_float3(0.0f, 0.0f, 1.0f);
  p.f90 = 1.0f;
  p.metallic = 0.0f;
  p.alpha_x = 1.0f;
  p.alpha_y = 1.0f;
  p.ior = 1.5f;
  p.coat = 0.0f;
  p.coat_alpha = PR_MIN_ALPHA;
  p.sheen_alpha = 1.0f;
  p.kind = PR_BSDF_MICROFACET;
  p.model = PR_MODEL_ENERGY;
  return p;
}

// Whether m is of the glTF model; whether it has a sheen, a coat, is anisotropic (each false
// where the program leaves the feature out).
PR_INLINE int bsdf_gltf(const BsdfParams* m) {
#if !PR_HAS_GLTF_MODEL
  (void)m;
  return 0;
#elif !PR_HAS_ENERGY_MODEL
  (void)m;
  return 1;
#else
  return m->model == PR_MODEL_GLTF;
#endif
}
PR_INLINE int bsdf_has_sheen(const BsdfParams* m) {
  return PR_HAS_SHEEN && max3(m->sheen) > 0.0f;
}
PR_INLINE int bsdf_has_coat(const BsdfParams* m) {
  return PR_HAS_COAT && m->coat > 0.0f;
}

PR_INLINE int bsdf_is_delta(const BsdfParams* m) {
  return m->kind == PR_BSDF_MIRROR || m->kind == PR_BSDF_GLASS;
}

// Whether the BSDF passes light through its surface (glass, smooth or rough): its frame keeps
// the geometric orientation, and directions on both sides carry light.
PR_INLINE int bsdf_transmits(const BsdfParams* m) {
  return m->kind == PR_BSDF_GLASS || m->kind == PR_BSDF_ROUGH_GLASS;
}

// ---- Tables (kernels/shared/bsdf_tables.h, made by tools/tables/bsdf_tables): bilinear on a grid
// uniform in sqrt(cos) from 0 to 1 and in roughness (sqrt(alpha)) from the smallest to 1.

PR_INLINE float bsdf_table_at(float x, int n, int* i) {
  const float s = (x > 0.0f ? fmin(x, 1.0f) : 0.0f) * (float)(n - 1);  // NaN: 0
  const int k = (int)s;
  *i = k < n - 1 ? k : n - 2;
  return s - (float)*i;
}

PR_INLINE float bsdf_table_roughness(float r) {
  return (r - PR_TABLE_MIN_ROUGHNESS) * (1.0f / (1.0f - PR_TABLE_MIN_ROUGHNESS));
}

// The cell and fraction of an ior on the ior axis of the glass and dielectric tables (n points
// uniform in (ior - 1) / (ior + 1) from PR_GLASS_TABLE_MIN_IOR to _MAX_IOR), ior clamped to it.
PR_INLINE float bsdf_table_ior(float ior, int n, int* k) {
  const float c = clamp(ior, PR_GLASS_TABLE_MIN_IOR, PR_GLASS_TABLE_MAX_IOR);
  const float z0 = (PR_GLASS_TABLE_MIN_IOR - 1.0f) / (PR_GLASS_TABLE_MIN_IOR + 1.0f);
  const float z1 = (PR_GLASS_TABLE_MAX_IOR - 1.0f) / (PR_GLASS_TABLE_MAX_IOR + 1.0f);
  return bsdf_table_at(((c - 1.0f) / (c + 1.0f) - z0) / (z1 - z0), n, k);
}

// Bilinear in a table of rows of ni at the cell whose first corner is c, fractions (fx, fy).
PR_INLINE float bsdf_table_bilinear(PR_CONSTANT const float* c, int ni, float fx, float fy) {
  const float a = c[0] + (c[1] - c[0]) * fx;
  const float b = c[ni] + (c[ni + 1] - c[ni]) * fx;
  return a + (b - a) * fy;
}

PR_INLINE float bsdf_table2(PR_CONSTANT const float* t, float mu, float r) {
  int i, j;
  const float fx = bsdf_table_at(sqrt(fmax(mu, 0.0f)), PR_BSDF_TABLE_COS, &i);
  const float fy = bsdf_table_at(bsdf_table_roughness(r), PR_BSDF_TABLE_R, &j);
  return bsdf_table_bilinear(t + j * PR_BSDF_TABLE_COS + i, PR_BSDF_TABLE_COS, fx, fy);
}

// The energy model's sheen tables (kernels/shared/sheen_tables.h) at cos mu and roughness r.
PR_INLINE float sheen_table(PR_CONSTANT const float* t, float mu, float r) {
  int i, j;
  const float fx = bsdf_table_at(sqrt(fmax(mu, 0.0f)), PR_SHEEN_TABLE_COS, &i);
  const float fy = bsdf_table_at(bsdf_table_roughness(r), PR_SHEEN_TABLE_R, &j);
  return bsdf_table_bilinear(t + j * PR_SHEEN_TABLE_COS + i, PR_SHEEN_TABLE_COS, fx, fy);
}

PR_INLINE float bsdf_table1(PR_CONSTANT const float* t, float r) {
  int j;
  const float fy = bsdf_table_at(bsdf_table_roughness(r), PR_BSDF_TABLE_R, &j);
  return t[j] + (t[j + 1] - t[j]) * fy;
}

// Trilinear in a [k][j][i] table of nk x nj x ni at cell (i, j, k) and fractions (fx, fy, fz).
PR_INLINE float bsdf_table3(PR_CONSTANT const float* t, int ni, int nj, int i, int j, int k,
                            float fx, float fy, float fz) {
  PR_CONSTANT const float* c = t + (k * nj + j) * ni + i;
  const float a0 = c[0] + (c[1] - c[0]) * fx, a1 = c[ni] + (c[ni + 1] - c[ni]) * fx;
  c += ni * nj;
  const float b0 = c[0] + (c[1] - c[0]) * fx, b1 = c[ni] + (c[ni + 1] - c[ni]) * fx;
  const float a = a0 + (a1 - a0) * fy, b = b0 + (b1 - b0) * fy;
  return a + (b - a) * fz;
}

// A GGX lobe's albedos seen from cos mu: e with F = 1, es weighted by Schlick's (1 - v.h)^5, and
// eavg, e's hemispherical average; anisotropic lobes from their azimuth-averaged tables.
PR_INLINE void ggx_albedo(float ax, float ay, float mu, float* e, float* es, float* eavg) {
  if (!PR_HAS_ANISOTROPY || ax == ay) {
    const float r = sqrt(ax);
    *e = bsdf_table2(pr_ggx_e, mu, r);
    *es = bsdf_table2(pr_ggx_es, mu, r);
    *eavg = bsdf_table1(pr_ggx_eavg, r);
    return;
  }
  const float amax = fmax(ax, ay), amin = fmin(ax, ay);
  int i, j, k;
  const float fx = bsdf_table_at(sqrt(fmax(mu, 0.0f)), PR_BSDF_ANISO_COS, &i);
  const float fy = bsdf_table_at(bsdf_table_roughness(sqrt(amax)), PR_BSDF_ANISO_R, &j);
  const float fz = bsdf_table_at(bsdf_table_roughness(sqrt(amin / amax)), PR_BSDF_ANISO_Q, &k);
  *e = bsdf_table3(pr_ggx_e_aniso, PR_BSDF_ANISO_COS, PR_BSDF_ANISO_R, i, j, k, fx, fy, fz);
  *es = bsdf_table3(pr_ggx_es_aniso, PR_BSDF_ANISO_COS, PR_BSDF_ANISO_R, i, j, k, fx, fy, fz);
  *eavg = bsdf_table_bilinear(pr_ggx_eavg_aniso + k * PR_BSDF_ANISO_R + j, PR_BSDF_ANISO_R, fy, fz);
}

// The energy model's dielectric layer of ior `ior` (alpha the lobe's): the GGX albedo seen from
// cos mu weighted by the exact Fresnel's shape (fresnel_dielectric_weight), and in *wavg the
// shape's hemispherical average; from the tables, ior and roughness clamped to their range.
PR_INLINE float dielectric_albedo(float alpha, float mu, float ior, float* wavg) {
  int i, j, k;
  const float fx = bsdf_table_at(sqrt(fmax(mu, 0.0f)), PR_BSDF_DIELECTRIC_COS, &i);
  const float fy = bsdf_table_at(bsdf_table_roughness(sqrt(alpha)), PR_BSDF_DIELECTRIC_R, &j);
  const float fz = bsdf_table_ior(ior, PR_BSDF_DIELECTRIC_IOR, &k);
  *wavg = pr_fresnel_wavg[k] + (pr_fresnel_wavg[k + 1] - pr_fresnel_wavg[k]) * fz;
  return bsdf_table3(pr_ggx_ed, PR_BSDF_DIELECTRIC_COS, PR_BSDF_DIELECTRIC_R, i, j, k, fx, fy, fz);
}

// ---- Layers

// The multiple-scattering factor of a GGX lobe with Fresnel f0 + (f90 - f0) w (w's hemispherical
// average wavg) seen at a direction whose single-scattering albedo with F = 1 is e (average
// eavg): 1 + Fms (1 - e) / e, Fms the Fresnel of the bounces after the first (Kulla and Conty's
// appendix, one Fresnel taken out since it multiplies a lobe that has it): a white conductor's
// albedo is then 1.
PR_INLINE float3 ggx_ms_factor_w(float3 f0, float f90, float wavg, float e, float eavg) {
  const float3 favg = f0 + (make_float3(f90, f90, f90) - f0) * wavg;
  const float3 one = make_float3(1.0f, 1.0f, 1.0f);
  const float3 fms = favg * eavg / (one - favg * (1.0f - eavg));
  return one + fms * ((1.0f - e) / e);
}

// The same with Schlick's Fresnel, whose shape averages 1/21 over the hemisphere.
PR_INLINE float3 ggx_ms_factor(float3 f0, float f90, float e, float eavg) {
  return ggx_ms_factor_w(f0, f90, 1.0f / 21.0f, e, eavg);
}

// What the layering needs of one direction w: the layers' directional albedos and the
// multiple-scattering factors (PR_MODEL_ENERGY); the coat's and sheen's weights (PR_MODEL_GLTF).
typedef struct {
  float3 metal_ms, spec_ms;          // multiple-scattering factors of the base's lobes
  float3 metal_albedo, spec_albedo;  // their albedos
  float coat_ms, coat_albedo;        // the coat's factor, and its albedo x weight (PR_MODEL_GLTF:
                                     // weight x Fresnel at N.V)
  float sheen_albedo;                // max(sheen colour) x the sheen's albedo
} BsdfLayers;

PR_INLINE BsdfLayers bsdf_layers(const BsdfParams* m, float3 w) {
  BsdfLayers l;
  const float3 zero = make_float3(0.0f, 0.0f, 0.0f), one = make_float3(1.0f, 1.0f, 1.0f);
  l.metal_ms = one;
  l.spec_ms = one;
  l.metal_albedo = zero;
  l.spec_albedo = zero;
  l.coat_ms = 1.0f;
  l.coat_albedo = 0.0f;
  l.sheen_albedo = 0.0f;
  if (bsdf_has_sheen(m)) {
    const float sheen = max3(m->sheen);
    if (bsdf_gltf(m)) {
      l.sheen_albedo = sheen * bsdf_table2(pr_sheen_e, w.z, sqrt(m->sheen_alpha));
    } else {
      l.sheen_albedo = sheen * sheen_table(pr_sheen_r, w.z, sqrt(m->sheen_alpha));
    }
  }
  const float cc = dot(w, m->coat_n);
  if (bsdf_gltf(m)) {
    if (bsdf_has_coat(m) && cc > 0.0f) l.coat_albedo = m->coat * coat_fresnel(schlick_weight(cc));
    return l;
  }
  float e, es, eavg;
  ggx_albedo(m->alpha_x, m->alpha_y, w.z, &e, &es, &eavg);
  e = fmax(e, 1e-3f);
  if (m->metallic > 0.0f) {
    l.metal_ms = ggx_ms_factor(m->base, 1.0f, e, eavg);
    l.metal_albedo = (m->base * e + (one - m->base) * es) * l.metal_ms;
  }
  if (m->metallic < 1.0f) {
    // The dielectric layer: the exact Fresnel's shape at the material's ior.
    float wavg;
    const float ed = dielectric_albedo(sqrt(m->alpha_x * m->alpha_y), w.z, m->ior, &wavg);
    l.spec_ms = ggx_ms_factor_w(m->f0, m->f90, wavg, e, eavg);
    l.spec_albedo = (m->f0 * e + (make_float3(m->f90, m->f90, m->f90) - m->f0) * ed) * l.spec_ms;
  }
  if (bsdf_has_coat(m) && cc > 0.0f) {
    const float rc = sqrt(m->coat_alpha);
    const float ec = fmax(bsdf_table2(pr_ggx_e, cc, rc), 1e-3f);
    float wavg;
    const float edc = dielectric_albedo(m->coat_alpha, cc, PR_COAT_IOR, &wavg);
    l.coat_ms = ggx_ms_factor_w(make_float3(0.04f, 0.04f, 0.04f), 1.0f, wavg, ec,
                                bsdf_table1(pr_ggx_eavg, rc))
                    .x;
    l.coat_albedo = m->coat * (0.04f * ec + 0.96f * edc) * l.coat_ms;
  }
  return l;
}

// The reflectance an auxiliary albedo image shows (--aov albedo): the layers' directional albedos
// at w, tinted as they reflect. The glTF model keeps no albedos: its base colour stands in.
PR_INLINE float3 bsdf_albedo(const BsdfParams* m, float3 w) {
  const float3 one = make_float3(1.0f, 1.0f, 1.0f);
  if (m->kind == PR_BSDF_LAMBERT || m->kind == PR_BSDF_ROUGH_GLASS || bsdf_gltf(m)) return m->base;
  const BsdfLayers l = bsdf_layers(m, w);
  const float3 dielectric =
      l.spec_albedo + m->base * fmax(one - l.spec_albedo, make_float3(0.0f, 0.0f, 0.0f));
  const float3 base = l.metal_albedo * m->metallic + dielectric * (1.0f - m->metallic);
  const float3 sheen = m->sheen * (l.sheen_albedo > 0.0f ? l.sheen_albedo / max3(m->sheen) : 0.0f);
  const float3 below = sheen + base * (1.0f - l.sheen_albedo);
  return clamp(one * l.coat_albedo + below * (1.0f - l.coat_albedo), 0.0f, 1.0f);
}

// ---- The lobe table. A microfacet material is a mixture of lobes, each with one function set:
//
//   float  lobe_<name>_weight(m, wo, l)        its weight for lobe choice at wo (the model's:
//                                              PR_MODEL_ENERGY its share of the albedo,
//                                              unnormalized; PR_MODEL_GLTF its share of what the
//                                              lobes above it leave, the last lobe's 1)
//   float  lobe_<name>_choice(m, wo, p, rest)  PR_MODEL_GLTF's chance of taking it once the lobes
//                                              above were passed over (rest: what they leave)
//   float3 lobe_<name>_sample(m, wo, u1, u2)   a direction (z <= 0: none)
//   float  lobe_<name>_pdf(m, wo, wi, h)       that sampling's solid-angle pdf
//   float3 lobe_<name>_eval(m, e, below)       f of this layer over `below`, the lobes under it
//
// The table lists them top layer first: X(NAME, name, feature), feature the PR_HAS_ flag that
// compiles the lobe in (1: always). The last lobe is the opaque base: it takes what u0 leaves.
// The mixture (bsdf_lobes, bsdf_choose_lobe, bsdf_mixture_pdf, bsdf_value) expands the table;
// adding a lobe is its function set here, an entry below and one in PR_BSDF_LOBE_SUM_ORDER.
#define PR_BSDF_LOBES(X)        \
  X(COAT, coat, PR_HAS_COAT)    \
  X(SHEEN, sheen, PR_HAS_SHEEN) \
  X(SPEC, spec, 1)              \
  X(DIFFUSE, diffuse, 1)

// The order in which the mixture pdf adds the lobes and the energy model's u0 walks them (the
// GGX lobe before the sheen, which came later): floats do not add associatively, so frames
// depend on it. A new lobe goes last.
#define PR_BSDF_LOBE_SUM_ORDER(X) X(COAT, coat) X(SPEC, spec) X(SHEEN, sheen) X(DIFFUSE, diffuse)

#define PR_LOBE_ENUM(N, n, on) PR_LOBE_##N,
#define PR_LOBE_ON(N, n, on) PR_LOBE_##N##_ON = (on),
#define PR_LOBE_BIT(N, n, on) | (1 << PR_LOBE_##N)
#define PR_LOBE_SUM_BIT(N, n) | (1 << PR_LOBE_##N)
#define PR_LOBE_SUM_ONE(N, n) +1
enum { PR_BSDF_LOBES(PR_LOBE_ENUM) PR_LOBE_COUNT };
enum { PR_BSDF_LOBES(PR_LOBE_ON) };
PR_STATIC_ASSERT((0 PR_BSDF_LOBES(PR_LOBE_BIT)) == (0 PR_BSDF_LOBE_SUM_ORDER(PR_LOBE_SUM_BIT)) &&
                     (0 PR_BSDF_LOBE_SUM_ORDER(PR_LOBE_SUM_ONE)) == PR_LOBE_COUNT,
                 "PR_BSDF_LOBE_SUM_ORDER must list every lobe of PR_BSDF_LOBES once");
#undef PR_LOBE_ENUM
#undef PR_LOBE_ON
#undef PR_LOBE_BIT
#undef PR_LOBE_SUM_BIT
#undef PR_LOBE_SUM_ONE

// One number per lobe (its weight or probability), a function of (material, wo) only.
#define PR_LOBE_FIELD(N, n, on) float n;
typedef struct {
  PR_BSDF_LOBES(PR_LOBE_FIELD)
} BsdfLobes;
#undef PR_LOBE_FIELD

// What evaluation shares between the lobes.
typedef struct {
  float3 wo, wi, h;
  float3 fd;  // the dielectric layer's Fresnel at wo.h, f0 to f90 (fresnel_dielectric_weight)
  float w5;   // Schlick's weight at wo.h
  int mode;
  BsdfLayers lo, li;  // the layers of wo and wi
} BsdfEval;

// The view's layers: wo's for radiance, wi's for importance.
PR_INLINE const BsdfLayers* bsdf_view(const BsdfEval* e) {
  return e->mode == PR_RADIANCE ? &e->lo : &e->li;
}

// What the coat and the sheen leave to the base at the view (PR_MODEL_ENERGY).
PR_INLINE float bsdf_below_sheen(const BsdfLayers* l) {
  return (1.0f - l->coat_albedo) * (1.0f - l->sheen_albedo);
}

// PR_MODEL_GLTF's usual choice: a lobe's probability over what the lobes above leave.
PR_INLINE float bsdf_share_of_rest(float p, float rest) {
  return rest > 0.0f ? p / rest : 0.0f;
}

// ---- Coat: GGX about the coat's normal, Fresnel of ior 1.5 (KHR_materials_clearcoat).

PR_INLINE float bsdf_coat_probability(const BsdfParams* m, float cos_o) {
  if (!bsdf_has_coat(m)) return 0.0f;
  return clamp(2.0f * m->coat * coat_fresnel(schlick_weight(cos_o)), 0.05f, 0.5f);
}

PR_INLINE float lobe_coat_weight(const BsdfParams* m, float3 wo, const BsdfLayers* l) {
  return bsdf_gltf(m) ? bsdf_coat_probability(m, dot(wo, m->coat_n)) : l->coat_albedo;
}

PR_INLINE float lobe_coat_choice(const BsdfParams* m, float3 wo, const BsdfLobes* p, float rest) {
  (void)m;
  (void)wo;
  return bsdf_share_of_rest(p->coat, rest);
}

// Visible normals about the coat's own normal.
PR_INLINE float3 lobe_coat_sample(const BsdfParams* m, float3 wo, float u1, float u2) {
  if (m->coat_n.z >= 1.0f) {
    const float3 h = ggx_sample_vndf(wo, m->coat_alpha, m->coat_alpha, u1, u2);
    return h * (2.0f * dot(wo, h)) - wo;
  }
  float3 t, b;
  orthonormal_basis(m->coat_n, &t, &b);
  const float3 wc = to_local(wo, t, b, m->coat_n);
  if (!(wc.z > 0.0f)) return make_float3(0.0f, 0.0f, -1.0f);
  const float3 h =
      to_world(ggx_sample_vndf(wc, m->coat_alpha, m->coat_alpha, u1, u2), t, b, m->coat_n);
  return h * (2.0f * dot(wo, h)) - wo;
}

PR_INLINE float lobe_coat_pdf(const BsdfParams* m, float3 wo, float3 wi, float3 h) {
  const float co = dot(wo, m->coat_n), ci = dot(wi, m->coat_n);
  if (!(co > 0.0f) || !(ci > 0.0f)) return 0.0f;
  const float a2 = m->coat_alpha * m->coat_alpha;
  return ggx_d(dot(h, m->coat_n), a2) / ((1.0f + ggx_lambda(co, a2)) * 4.0f * co);
}

// The coat's reflection over what it leaves of `below`.
PR_INLINE float3 lobe_coat_eval(const BsdfParams* m, const BsdfEval* e, float3 below) {
  if (!bsdf_has_coat(m)) return below;
  const BsdfLayers* lv = bsdf_view(e);
  const float co = dot(e->wo, m->coat_n), ci = dot(e->wi, m->coat_n);
  float coat_spec = 0.0f;
  if (co > 0.0f && ci > 0.0f) {
    float unused;
    coat_spec =
        ggx_reflection(co, ci, dot(e->h, m->coat_n), m->coat_alpha * m->coat_alpha, &unused);
    // glTF: the coat's lobe weighted by its Fresnel at N.V; energy: the microfacet's Fresnel
    // with the multiple-scattering factor.
    coat_spec *= bsdf_gltf(m) ? lv->coat_albedo
                              : m->coat *
                                    coat_fresnel(fresnel_dielectric_weight(
                                        fmax(dot(e->wo, e->h), 0.0f), PR_COAT_IOR)) *
                                    lv->coat_ms;
    // The caller weights by the cosine to the shading normal; a tilted coat reflects by the
    // cosine to its own, on the light's side (wi, or wo for importance).
    if (m->coat_n.z < 1.0f) coat_spec *= e->mode == PR_RADIANCE ? ci / e->wi.z : co / e->wo.z;
  }
  return below * fmax(1.0f - lv->coat_albedo, 0.0f) + make_float3(coat_spec, coat_spec, coat_spec);
}

// ---- Sheen. PR_MODEL_GLTF: the Charlie lobe (KHR_materials_sheen), sampled uniformly over the
// hemisphere (it peaks at grazing directions, which cosine-weighted samples reach too rarely).
// PR_MODEL_ENERGY: a layer of fibres along the normal (Zeltner, Burley and Chiang 2022; Cycles'
// and OpenPBR's sheen), f cos = R D: R its reflectance at the view and D a linearly transformed
// cosine about the view, both from sheen_tables.h (host/render/sheen_volume.cpp). D is sampled
// exactly; f is not reciprocal, so the view is wo for radiance and wi for importance.

// The LTC about view v (v.z > 0) of a sheen of roughness r: its a and b, and v's azimuth (c, s).
typedef struct {
  float a, b, c, s;
} SheenLtc;

PR_INLINE SheenLtc sheen_ltc(float r, float3 v) {
  SheenLtc t;
  t.a = sheen_table(pr_sheen_ltc_a, v.z, r);
  t.b = sheen_table(pr_sheen_ltc_b, v.z, r);
  const float l = sqrt(v.x * v.x + v.y * v.y);
  t.c = l > 1e-7f ? v.x / l : 1.0f;
  t.s = l > 1e-7f ? v.y / l : 0.0f;
  return t;
}

// D at w (solid-angle density over the upper hemisphere): the cosine lobe at M^-1 w, with
// M^-1 = [[a, 0, b], [0, a, 0], [0, 0, 1]] in the frame where the view's azimuth is 0.
PR_INLINE float sheen_ltc_eval(const SheenLtc* t, float3 w) {
  if (!(w.z > 0.0f)) return 0.0f;
  const float x = t->c * w.x + t->s * w.y, y = t->c * w.y - t->s * w.x;
  const float px = t->a * x + t->b * w.z, py = t->a * y;
  const float l2 = px * px + py * py + w.z * w.z;
  return w.z * t->a * t->a * PR_INV_PI / (l2 * l2);
}

PR_INLINE float3 sheen_ltc_sample(const SheenLtc* t, float u1, float u2) {
  const float3 c = sample_cosine_hemisphere(u1, u2);
  const float x = (c.x - t->b * c.z) / t->a, y = c.y / t->a;
  return normalize(make_float3(t->c * x - t->s * y, t->s * x + t->c * y, c.z));
}

PR_INLINE float lobe_sheen_weight(const BsdfParams* m, float3 wo, const BsdfLayers* l) {
  (void)wo;
  if (bsdf_gltf(m)) return l->sheen_albedo > 0.0f ? clamp(l->sheen_albedo, 0.05f, 0.5f) : 0.0f;
  return (1.0f - l->coat_albedo) * l->sheen_albedo;
}

PR_INLINE float lobe_sheen_choice(const BsdfParams* m, float3 wo, const BsdfLobes* p, float rest) {
  (void)m;
  (void)wo;
  return bsdf_share_of_rest(p->sheen, rest);
}

PR_INLINE float3 lobe_sheen_sample(const BsdfParams* m, float3 wo, float u1, float u2) {
  if (bsdf_gltf(m)) return sample_uniform_hemisphere(u1, u2);
  const SheenLtc t = sheen_ltc(sqrt(m->sheen_alpha), wo);
  return sheen_ltc_sample(&t, u1, u2);
}

PR_INLINE float lobe_sheen_pdf(const BsdfParams* m, float3 wo, float3 wi, float3 h) {
  (void)h;
  if (bsdf_gltf(m)) return 0.5f * PR_INV_PI;
  const SheenLtc t = sheen_ltc(sqrt(m->sheen_alpha), wo);
  return sheen_ltc_eval(&t, wi);
}

PR_INLINE float3 lobe_sheen_eval(const BsdfParams* m, const BsdfEval* e, float3 below) {
  if (!bsdf_has_sheen(m)) return below;
  const BsdfLayers* lv = bsdf_view(e);
  if (bsdf_gltf(m)) {
    // The glTF model's scaling is the smaller of both directions' (reciprocal).
    const float s = sheen_lobe(e->wo.z, e->wi.z, e->h.z, m->sheen_alpha);
    const float keep = fmin(1.0f - e->lo.sheen_albedo, 1.0f - e->li.sheen_albedo);
    return m->sheen * s + below * fmax(keep, 0.0f);
  }
  const int radiance = e->mode == PR_RADIANCE;
  const float3 view = radiance ? e->wo : e->wi, light = radiance ? e->wi : e->wo;
  float f = 0.0f;
  if (view.z > 0.0f && light.z > 0.0f) {
    const SheenLtc t = sheen_ltc(sqrt(m->sheen_alpha), view);
    const float r = lv->sheen_albedo / max3(m->sheen);
    f = r * sheen_ltc_eval(&t, light) / light.z;
  }
  return m->sheen * f + below * fmax(1.0f - lv->sheen_albedo, 0.0f);
}

// ---- Spec: the base's GGX lobe, a conductor (metallic) and a dielectric specular layer over
// the diffuse.

// The glTF model's choice of its specular lobe over the diffuse one (luminance of the
// fresnel_mix weights at N.V).
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

PR_INLINE float lobe_spec_weight(const BsdfParams* m, float3 wo, const BsdfLayers* l) {
  if (bsdf_gltf(m)) return bsdf_spec_probability(m, wo.z);
  return bsdf_below_sheen(l) * (m->metallic * luminance(l->metal_albedo) +
                                (1.0f - m->metallic) * luminance(l->spec_albedo));
}

// Its weight again: p->spec / rest would round otherwise than the glTF model always has.
PR_INLINE float lobe_spec_choice(const BsdfParams* m, float3 wo, const BsdfLobes* p, float rest) {
  (void)p;
  (void)rest;
  return bsdf_spec_probability(m, wo.z);
}

PR_INLINE float3 lobe_spec_sample(const BsdfParams* m, float3 wo, float u1, float u2) {
  const float3 h = ggx_sample_vndf(wo, m->alpha_x, m->alpha_y, u1, u2);
  return h * (2.0f * dot(wo, h)) - wo;
}

PR_INLINE float lobe_spec_pdf(const BsdfParams* m, float3 wo, float3 wi, float3 h) {
  (void)wi;
  return ggx_d_xy(h, m->alpha_x, m->alpha_y) /
         ((1.0f + ggx_lambda_xy(wo, m->alpha_x, m->alpha_y)) * 4.0f * wo.z);
}

// The conductor, plus the dielectric layer over `below` (the diffuse, its Fresnel applied).
PR_INLINE float3 lobe_spec_eval(const BsdfParams* m, const BsdfEval* e, float3 below) {
  const BsdfLayers* lv = bsdf_view(e);
  // The GGX lobe without Fresnel (symmetric in wo and wi).
  const float ax = m->alpha_x, ay = m->alpha_y;
  const float d = ggx_d_xy(e->h, ax, ay);
  const float g2 = 1.0f / (1.0f + ggx_lambda_xy(e->wo, ax, ay) + ggx_lambda_xy(e->wi, ax, ay));
  const float spec = d * g2 / (4.0f * e->wo.z * e->wi.z);
  const float3 fm = m->base + (make_float3(1.0f, 1.0f, 1.0f) - m->base) * e->w5;
  // fresnel_mix with a coloured F: specular where reflected, diffuse where not.
  if (bsdf_gltf(m))
    return (e->fd * spec + below) * (1.0f - m->metallic) + fm * (spec * m->metallic);
  float3 f = make_float3(0.0f, 0.0f, 0.0f);
  if (m->metallic > 0.0f) f = fm * lv->metal_ms * (spec * m->metallic);
  if (m->metallic < 1.0f) f += (e->fd * lv->spec_ms * spec + below) * (1.0f - m->metallic);
  return f;
}

// ---- Diffuse: Lambert, under the dielectric layer (its Fresnel here, so that the products
// keep their grouping).

PR_INLINE float lobe_diffuse_weight(const BsdfParams* m, float3 wo, const BsdfLayers* l) {
  (void)wo;
  if (bsdf_gltf(m)) return 1.0f;  // the rest
  return bsdf_below_sheen(l) * (1.0f - m->metallic) *
         luminance(m->base * (make_float3(1.0f, 1.0f, 1.0f) - l->spec_albedo));
}

PR_INLINE float lobe_diffuse_choice(const BsdfParams* m, float3 wo, const BsdfLobes* p,
                                    float rest) {
  (void)m;
  (void)wo;
  return bsdf_share_of_rest(p->diffuse, rest);
}

PR_INLINE float3 lobe_diffuse_sample(const BsdfParams* m, float3 wo, float u1, float u2) {
  (void)m;
  (void)wo;
  return sample_cosine_hemisphere(u1, u2);
}

PR_INLINE float lobe_diffuse_pdf(const BsdfParams* m, float3 wo, float3 wi, float3 h) {
  (void)m;
  (void)wo;
  (void)h;
  return wi.z * PR_INV_PI;
}

// Opaque: nothing below it shows.
PR_INLINE float3 lobe_diffuse_eval(const BsdfParams* m, const BsdfEval* e, float3 below) {
  (void)below;
  const float3 one = make_float3(1.0f, 1.0f, 1.0f);
  if (bsdf_gltf(m)) return m->base * ((one - e->fd) * PR_INV_PI);
  return m->base *
         (fmax(one - bsdf_view(e)->spec_albedo, make_float3(0.0f, 0.0f, 0.0f)) * PR_INV_PI);
}

// ---- Rough glass: a GGX dielectric interface (Walter et al. 2007), isotropic, in a frame that
// keeps the surface's orientation (wo.z < 0: wo inside). Reflection is untinted; refraction
// multiplies by base and, for radiance, by 1/eta^2 (as the smooth glass). What single scattering
// loses is given back at the view (rough_glass_compensation). Sampling: a visible normal from
// wo's side, then reflection with the Fresnel's probability.

// n on wi's side of a refraction over n on wo's.
PR_INLINE float rough_glass_eta(const BsdfParams* m, float3 wo) {
  return wo.z > 0.0f ? m->ior : 1.0f / m->ior;
}

// The single-scattering albedo of white rough glass seen from the view w, from the table, and in
// *avg its average over the hemisphere of w's side.
PR_INLINE float rough_glass_albedo(const BsdfParams* m, float3 w, float* avg) {
  int i, j, k;
  const float fx = bsdf_table_at(sqrt(fabs(w.z)), PR_BSDF_GLASS_COS, &i);
  const float fy = bsdf_table_at(bsdf_table_roughness(sqrt(m->alpha_x)), PR_BSDF_GLASS_R, &j);
  const float fz = bsdf_table_ior(m->ior, PR_BSDF_GLASS_IOR, &k);
  const int side = w.z > 0.0f ? 0 : 1;
  *avg = bsdf_table_bilinear(pr_glass_eavg + (side * PR_BSDF_GLASS_IOR + k) * PR_BSDF_GLASS_R + j,
                             PR_BSDF_GLASS_R, fy, fz);
  PR_CONSTANT const float* t =
      pr_glass_e + side * PR_BSDF_GLASS_IOR * PR_BSDF_GLASS_R * PR_BSDF_GLASS_COS;
  return bsdf_table3(t, PR_BSDF_GLASS_COS, PR_BSDF_GLASS_R, i, j, k, fx, fy, fz);
}

// What divides out single scattering's loss at the view w, per channel: 1 / E for white glass;
// for tinted glass the light lost to further bounces between the microfacets is tinted as
// often as they refract (Kulla and Conty's multiple-scattering Fresnel with the refraction's
// tint for F, as Cycles' multiscatter glass takes it).
PR_INLINE float3 rough_glass_compensation(const BsdfParams* m, float3 w) {
  float avg;
  const float e = fmax(rough_glass_albedo(m, w, &avg), 0.05f);
  const float3 one = make_float3(1.0f, 1.0f, 1.0f);
  const float3 fms = m->base * avg / (one - m->base * (1.0f - avg));
  return one + fms * ((1.0f - e) / e);
}

// The microfacet normal that takes wo to wi (facing +z), 0 where none does from the sides
// each direction is on.
PR_INLINE int rough_glass_half(float3 wo, float3 wi, float eta, float3* h) {
  float3 v = wo.z * wi.z > 0.0f ? wo + wi : wo + wi * eta;
  const float len = length(v);
  if (!(len > 0.0f)) return 0;
  v = v / len;
  if (v.z < 0.0f) v = -v;
  if (!(dot(wo, v) * wo.z > 0.0f) || !(dot(wi, v) * wi.z > 0.0f)) return 0;
  *h = v;
  return 1;
}

// f(wo, wi) for `mode`, with the pdfs of sampling wi from wo (*pdf) and wo from wi (*pdf_rev):
// one half vector, D, Lambdas and Fresnel for the three (the Fresnel of a refraction is the same
// from either side).
PR_INLINE float3 rough_glass_eval(const BsdfParams* m, float3 wo, float3 wi, int mode, float* pdf,
                                  float* pdf_rev) {
  *pdf = 0.0f;
  *pdf_rev = 0.0f;
  const float eta = rough_glass_eta(m, wo);
  float3 h;
  if (wo.z == 0.0f || wi.z == 0.0f || !rough_glass_half(wo, wi, eta, &h))
    return make_float3(0.0f, 0.0f, 0.0f);
  const float a2 = m->alpha_x * m->alpha_x;
  const float co = fabs(wo.z), ci = fabs(wi.z), ho = fabs(dot(wo, h)), hi = fabs(dot(wi, h));
  const float d = ggx_d(h.z, a2), lo = ggx_lambda(co, a2), li = ggx_lambda(ci, a2);
  const float dg = d / (1.0f + lo + li);
  const float fr = fresnel_dielectric(ho, eta);
  // Visible-normal densities of h from wo and from wi.
  const float vo = d * ho / ((1.0f + lo) * co), vi = d * hi / ((1.0f + li) * ci);
  const float3 ms = rough_glass_compensation(m, mode == PR_RADIANCE ? wo : wi);
  if (wo.z * wi.z > 0.0f) {
    *pdf = vo * fr / (4.0f * ho);
    *pdf_rev = vi * fr / (4.0f * hi);
    return ms * (fr * dg / (4.0f * co * ci));
  }
  const float s = dot(wi, h) + dot(wo, h) / eta;  // the dots' signs differ
  *pdf = vo * (1.0f - fr) * hi / (s * s);
  *pdf_rev = vi * (1.0f - fr) * ho / (eta * eta * s * s);  // wi's s is eta x wo's
  float v = (1.0f - fr) * dg * hi * ho / (co * ci * s * s);
  if (mode == PR_RADIANCE) v /= eta * eta;
  return m->base * ms * v;
}

// A direction from wo (z == 0: none).
PR_INLINE float3 rough_glass_sample(const BsdfParams* m, float3 wo, float u0, float u1, float u2) {
  const float3 none = make_float3(0.0f, 0.0f, 0.0f);
  const float sign = wo.z < 0.0f ? -1.0f : 1.0f;
  const float3 h = ggx_sample_vndf(wo * sign, m->alpha_x, m->alpha_x, u1, u2) * sign;
  const float c = dot(wo, h);  // > 0: h is on wo's side
  if (!(c > 0.0f)) return none;
  const float eta = rough_glass_eta(m, wo);
  float3 wi;
  if (u0 < fresnel_dielectric(c, eta)) {
    wi = h * (2.0f * c) - wo;
    if (!(wi.z * wo.z > 0.0f)) return none;
  } else {
    const float sin2_t = (1.0f - c * c) / (eta * eta);
    if (sin2_t >= 1.0f) return none;
    wi = -wo / eta + h * (c / eta - sqrt(1.0f - sin2_t));
    if (!(wi.z * wo.z < 0.0f)) return none;
  }
  return wi;
}

// A clear coat over rough glass (KHR_materials_clearcoat on a transmissive material): the coat
// reflects on the outside and passes on what it does not reflect there (lobe_coat_eval, its
// albedo at the view); inside the object there is no coat between the directions. Sampled
// with the coat's probability at wo where wo is outside.
PR_INLINE float rough_glass_coat_choice(const BsdfParams* m, float3 wo) {
  return bsdf_has_coat(m) && wo.z > 0.0f ? bsdf_coat_probability(m, dot(wo, m->coat_n)) : 0.0f;
}

// The same as rough_glass_eval with the coat over the glass.
PR_INLINE float3 rough_glass_coated_eval(const BsdfParams* m, float3 wo, float3 wi, int mode,
                                         float* pdf, float* pdf_rev) {
  const float3 glass = rough_glass_eval(m, wo, wi, mode, pdf, pdf_rev);
  if (!bsdf_has_coat(m)) return glass;
  BsdfEval e;
  e.wo = wo;
  e.wi = wi;
  e.h = normalize(wo + wi);
  e.w5 = schlick_weight(fmax(dot(wo, e.h), 0.0f));
  e.mode = mode;
  // The coat reads the view's layers alone (bsdf_view).
  e.lo = bsdf_layers(m, mode == PR_RADIANCE ? wo : wi);
  e.li = e.lo;
  const float po = rough_glass_coat_choice(m, wo), pi = rough_glass_coat_choice(m, wi);
  if (po > 0.0f) *pdf = po * lobe_coat_pdf(m, wo, wi, e.h) + (1.0f - po) * *pdf;
  if (pi > 0.0f) *pdf_rev = pi * lobe_coat_pdf(m, wi, wo, e.h) + (1.0f - pi) * *pdf_rev;
  return lobe_coat_eval(m, &e, glass);
}

PR_INLINE float3 rough_glass_coated_sample(const BsdfParams* m, float3 wo, float u0, float u1,
                                           float u2) {
  const float pc = rough_glass_coat_choice(m, wo);
  if (u0 < pc) {
    const float3 wi = lobe_coat_sample(m, wo, u1, u2);
    return wi.z > 0.0f && dot(wi, m->coat_n) > 0.0f ? wi : make_float3(0.0f, 0.0f, 0.0f);
  }
  return rough_glass_sample(m, wo, pc > 0.0f ? (u0 - pc) / (1.0f - pc) : u0, u1, u2);
}

// ---- The mixture, from the table

// The lobes' probabilities at wo. glTF: each lobe its weight's share of what the lobes above
// leave. Energy: in proportion to the weights, then a tenth spread evenly over the lobes that
// reflect anything, so a poor estimate (a textured base) cannot starve one.
PR_INLINE BsdfLobes bsdf_lobes(const BsdfParams* m, float3 wo, const BsdfLayers* l) {
  BsdfLobes p, w;
#define PR_LOBE_ZERO(N, n, on) p.n = 0.0f;
  PR_BSDF_LOBES(PR_LOBE_ZERO)
#undef PR_LOBE_ZERO
  if (bsdf_gltf(m)) {
    float rest = 1.0f;
#define PR_LOBE_SHARE(N, n, on)                  \
  if (on) {                                      \
    const float s = lobe_##n##_weight(m, wo, l); \
    p.n = rest * s;                              \
    rest *= 1.0f - s;                            \
  }
    PR_BSDF_LOBES(PR_LOBE_SHARE)
#undef PR_LOBE_SHARE
    return p;
  }
  int n = 0;
  float sum = 0.0f;
#define PR_LOBE_WEIGHT(N, name, on)                                \
  w.name = on ? fmax(lobe_##name##_weight(m, wo, l), 0.0f) : 0.0f; \
  n += w.name > 0.0f;                                              \
  sum += w.name;
  PR_BSDF_LOBES(PR_LOBE_WEIGHT)
#undef PR_LOBE_WEIGHT
  if (!(sum > 0.0f)) {
    p.spec = 1.0f;  // nothing reflects (a black base): sample the GGX lobe
    return p;
  }
  const float k = 0.9f / sum, floor_share = 0.1f / (float)n;
#define PR_LOBE_FLOOR(N, n, on) p.n = w.n > 0.0f ? w.n * k + floor_share : 0.0f;
  PR_BSDF_LOBES(PR_LOBE_FLOOR)
#undef PR_LOBE_FLOOR
  return p;
}

// The lobe u0 takes (PR_LOBE_*). glTF: down the layers, each taking its chance of what u0
// leaves, u0 rescaled after each (the order of the glTF model's images); energy: u0 against
// the lobes' running sum in PR_BSDF_LOBE_SUM_ORDER.
PR_INLINE int bsdf_choose_lobe(const BsdfParams* m, float3 wo, const BsdfLobes* p, float u0) {
  int lobe = -1;
  if (bsdf_gltf(m)) {
    float rest = 1.0f;
#define PR_LOBE_CHOOSE_GLTF(N, n, on)                  \
  if (on && lobe < 0) {                                \
    const float q = lobe_##n##_choice(m, wo, p, rest); \
    if (u0 < q) {                                      \
      lobe = PR_LOBE_##N;                              \
    } else {                                           \
      if (q > 0.0f) u0 = (u0 - q) / (1.0f - q);        \
      rest *= 1.0f - q;                                \
    }                                                  \
  }
    PR_BSDF_LOBES(PR_LOBE_CHOOSE_GLTF)
#undef PR_LOBE_CHOOSE_GLTF
  } else {
    float c = 0.0f;
#define PR_LOBE_CHOOSE_SUM(N, n)                \
  if (PR_LOBE_##N##_ON) {                       \
    c += p->n;                                  \
    if (lobe < 0 && u0 < c) lobe = PR_LOBE_##N; \
  }
    PR_BSDF_LOBE_SUM_ORDER(PR_LOBE_CHOOSE_SUM)
#undef PR_LOBE_CHOOSE_SUM
  }
  return lobe < 0 ? PR_LOBE_COUNT - 1 : lobe;
}

// A direction from lobe `lobe`.
PR_INLINE float3 bsdf_lobe_sample(const BsdfParams* m, int lobe, float3 wo, float u1, float u2) {
#define PR_LOBE_SAMPLE(N, n, on) \
  if (on && lobe == PR_LOBE_##N) return lobe_##n##_sample(m, wo, u1, u2);
  PR_BSDF_LOBES(PR_LOBE_SAMPLE)
#undef PR_LOBE_SAMPLE
  return make_float3(0.0f, 0.0f, -1.0f);
}

// The mixture's pdf of sampling wi from wo with lobe probabilities p (h: their half vector):
// sum of p x lobe pdf in PR_BSDF_LOBE_SUM_ORDER.
PR_INLINE float bsdf_mixture_pdf(const BsdfParams* m, const BsdfLobes* p, float3 wo, float3 wi,
                                 float3 h) {
  float pdf = 0.0f;
#define PR_LOBE_PDF(N, n) \
  if (PR_LOBE_##N##_ON && p->n > 0.0f) pdf += p->n * lobe_##n##_pdf(m, wo, wi, h);
  PR_BSDF_LOBE_SUM_ORDER(PR_LOBE_PDF)
#undef PR_LOBE_PDF
  return pdf;
}

// f: each layer over the ones below it, from the base up (the expansion nests the calls as
// coat(sheen(spec(diffuse(0))))).
PR_INLINE float3 bsdf_value(const BsdfParams* m, const BsdfEval* e) {
#define PR_LOBE_EVAL_OPEN(N, n, on) lobe_##n##_eval(m, e,
#define PR_LOBE_EVAL_CLOSE(N, n, on) )
  return PR_BSDF_LOBES(PR_LOBE_EVAL_OPEN) make_float3(0.0f, 0.0f, 0.0f)
      PR_BSDF_LOBES(PR_LOBE_EVAL_CLOSE);
#undef PR_LOBE_EVAL_OPEN
#undef PR_LOBE_EVAL_CLOSE
}

// bsdf_eval_mode's body.
PR_INLINE float3 bsdf_eval_impl(const BsdfParams* m, float3 wo, float3 wi, int mode, int want_rev,
                                float* pdf, float* pdf_rev) {
  *pdf = 0.0f;
  *pdf_rev = 0.0f;
  if (m->kind == PR_BSDF_ROUGH_GLASS) return rough_glass_coated_eval(m, wo, wi, mode, pdf, pdf_rev);
  if (bsdf_is_delta(m) || wo.z <= 0.0f || wi.z <= 0.0f) return make_float3(0.0f, 0.0f, 0.0f);
  if (m->kind == PR_BSDF_LAMBERT) {
    *pdf = wi.z * PR_INV_PI;
    *pdf_rev = wo.z * PR_INV_PI;
    return m->base * PR_INV_PI;
  }
  BsdfEval e;
  e.wo = wo;
  e.wi = wi;
  e.h = wo + wi;
  const float hl = length(e.h);
  if (hl <= 0.0f) return make_float3(0.0f, 0.0f, 0.0f);
  e.h = e.h / hl;
  e.w5 = schlick_weight(fmax(dot(wo, e.h), 0.0f));
  // The dielectric layer's Fresnel: Schlick's in the glTF model, the exact one's shape in the
  // energy model.
  const float wd =
      bsdf_gltf(m) ? e.w5 : fresnel_dielectric_weight(fmax(dot(wo, e.h), 0.0f), m->ior);
  e.fd = m->f0 + (make_float3(m->f90, m->f90, m->f90) - m->f0) * wd;
  e.mode = mode;
  // wi's layers where the value (seen from wi, or the glTF sheen's scaling) or pdf_rev needs
  // them.
  e.lo = bsdf_layers(m, wo);
  const int need_li = want_rev || mode == PR_IMPORTANCE || (bsdf_gltf(m) && bsdf_has_sheen(m));
  e.li = need_li ? bsdf_layers(m, wi) : e.lo;
  const float3 f = bsdf_value(m, &e);
  const BsdfLobes po = bsdf_lobes(m, wo, &e.lo);
  *pdf = bsdf_mixture_pdf(m, &po, wo, wi, e.h);
  if (want_rev) {
    const BsdfLobes pi = bsdf_lobes(m, wi, &e.li);
    *pdf_rev = bsdf_mixture_pdf(m, &pi, wi, wo, e.h);
  }
  return f;
}

// bsdf_sample's body.
PR_INLINE int bsdf_sample_impl(const BsdfParams* m, float3 wo, float u0, float u1, float u2,
                               int mode, float3* wi, float3* weight, float* pdf, int* delta) {
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
  if (m->kind == PR_BSDF_ROUGH_GLASS) {
    const float3 dir = rough_glass_coated_sample(m, wo, u0, u1, u2);
    if (dir.z == 0.0f) return 0;
    float p_fwd = 0.0f, p_rev;
    const float3 f = bsdf_eval_impl(m, wo, dir, mode, 0, &p_fwd, &p_rev);
    if (!(p_fwd > 0.0f)) return 0;
    *wi = dir;
    *pdf = p_fwd;
    *weight = f * (fabs(dir.z) / p_fwd);
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
  const BsdfLayers lo = bsdf_layers(m, wo);
  const BsdfLobes p = bsdf_lobes(m, wo, &lo);
  const float3 dir = bsdf_lobe_sample(m, bsdf_choose_lobe(m, wo, &p, u0), wo, u1, u2);
  if (dir.z <= 0.0f) return 0;
  float p_fwd = 0.0f, p_rev;
  const float3 f = bsdf_eval_impl(m, wo, dir, mode, 0, &p_fwd, &p_rev);
  if (p_fwd <= 0.0f) return 0;
  *wi = dir;
  *pdf = p_fwd;
  *weight = f * (dir.z / p_fwd);
  return 1;
}

// f(wo, wi) in transport mode `mode`, the pdf of sampling wi given wo and (pdf_rev) that of
// sampling wo given wi: one evaluation where a path needs its density both ways.
PR_INLINE float3 bsdf_eval_mode(const BsdfParams* m, float3 wo, float3 wi, int mode, float* pdf,
                                float* pdf_rev) {
  return bsdf_eval_impl(m, wo, wi, mode, 1, pdf, pdf_rev);
}

// f(wo, wi) for radiance (wo the view) with both pdfs.
PR_INLINE float3 bsdf_eval_both(const BsdfParams* m, float3 wo, float3 wi, float* pdf,
                                float* pdf_rev) {
  return bsdf_eval_impl(m, wo, wi, PR_RADIANCE, 1, pdf, pdf_rev);
}

// f(wo, wi) for radiance and the pdf of sampling wi given wo.
PR_INLINE float3 bsdf_eval(const BsdfParams* m, float3 wo, float3 wi, float* pdf) {
  float pdf_rev;
  return bsdf_eval_impl(m, wo, wi, PR_RADIANCE, 0, pdf, &pdf_rev);
}

// Samples wi given wo. Returns 0 when no direction is produced. *weight = f * |cos| / pdf (for
// delta lobes the same ratio with the delta cancelled) in transport mode `mode`, *pdf the
// solid-angle pdf (0 for delta).
PR_INLINE int bsdf_sample(const BsdfParams* m, float3 wo, float u0, float u1, float u2, int mode,
                          float3* wi, float3* weight, float* pdf, int* delta) {
  return bsdf_sample_impl(m, wo, u0, u1, u2, mode, wi, weight, pdf, delta);
}

PR_NAMESPACE_END
