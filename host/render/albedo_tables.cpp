#include "render/albedo_tables.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "shared/microfacet.h"
#include "shared/sampling.h"
#include "render/table_text.h"
#include "util/parallel.h"

namespace pr {

using namespace pr::dev;

namespace {

// The grid's cosines, uniform in sqrt(mu) (the albedos change fastest at grazing angles); mu = 0
// stands for its limit (a view this close to grazing).
float gridCos(int i, int n) {
  const float x = float(i) / float(n - 1);
  return std::fmax(x * x, 1e-5f);
}

// Albedo integrals of GGX with F = 1 seen from wo: E = E[G2 / G1] over visible normals (f cos /
// pdf of visible-normal sampling), and the same weighted by (1 - v.h)^5.
// Each reflection of wo off a GGX microfacet, on a stratified grid of samples x samples visible
// normals: visit(wo.h, G2 / G1), the sample's share of the albedo with F = 1.
template <class Visit>
void ggxReflections(float3 wo, float ax, float ay, int samples, Visit visit) {
  const double lo = ggx_lambda_xy(wo, ax, ay);
  for (int a = 0; a < samples; ++a)
    for (int b = 0; b < samples; ++b) {
      const float u1 = (float(a) + 0.5f) / float(samples), u2 = (float(b) + 0.5f) / float(samples);
      const float3 h = ggx_sample_vndf(wo, ax, ay, u1, u2);
      const float voh = dot(wo, h);
      const float3 wi = h * (2.0f * voh) - wo;
      if (!(wi.z > 0.0f)) continue;
      visit(voh, (1.0 + lo) / (1.0 + lo + ggx_lambda_xy(wi, ax, ay)));
    }
}

void ggxAlbedo(float3 wo, float ax, float ay, int samples, double* e, double* es) {
  double se = 0.0, ses = 0.0;
  ggxReflections(wo, ax, ay, samples, [&](float voh, double w) {
    se += w;
    ses += w * schlick_weight(voh);
  });
  const double count = double(samples) * double(samples);
  *e = se / count;
  *es = ses / count;
}

float3 viewAt(float mu, float phi) {
  const float s = std::sqrt(std::fmax(0.0f, 1.0f - mu * mu));
  return make_float3(s * std::cos(phi), s * std::sin(phi), mu);
}

// The same averaged over the view's azimuth (a quarter turn holds every case by symmetry).
void ggxAlbedoAniso(float mu, float ax, float ay, int samples, double* e, double* es) {
  constexpr int kAzimuths = 8;
  *e = *es = 0.0;
  for (int k = 0; k < kAzimuths; ++k) {
    double ek, esk;
    ggxAlbedo(viewAt(mu, 0.5f * PR_PI * (float(k) + 0.5f) / kAzimuths), ax, ay, samples, &ek, &esk);
    *e += ek / kAzimuths;
    *es += esk / kAzimuths;
  }
}

// A grid's roughness: from the tables' smallest to 1.
float gridRoughness(int j, int n) {
  return PR_TABLE_MIN_ROUGHNESS + (1.0f - PR_TABLE_MIN_ROUGHNESS) * float(j) / float(n - 1);
}

// The hemispherical average 2 \int E(mu) mu dmu of an albedo E(mu), by the midpoint rule on
// `points` cosines (a grid finer than the table's).
template <class Albedo>
double hemisphereAverage(int points, Albedo albedo) {
  double avg = 0.0;
  for (int k = 0; k < points; ++k) {
    const float mu = (float(k) + 0.5f) / float(points);
    avg += 2.0 * albedo(mu) * mu / points;
  }
  return avg;
}

// The white sheen lobe's albedo from cos mu, by the midpoint rule in (cos, azimuth): the lobe
// peaks at grazing directions, where cosine-weighted samples are too sparse.
double sheenAlbedo(float mu, float alpha, int samples) {
  const float3 wo = make_float3(std::sqrt(std::fmax(0.0f, 1.0f - mu * mu)), 0.0f, mu);
  const int nz = 2 * samples, nphi = samples;
  double s = 0.0;
  for (int a = 0; a < nz; ++a) {
    const float z = (float(a) + 0.5f) / float(nz), rz = std::sqrt(std::fmax(0.0f, 1.0f - z * z));
    for (int b = 0; b < nphi; ++b) {
      // The lobe is symmetric about wo's plane: half the azimuths, twice.
      const float phi = PR_PI * (float(b) + 0.5f) / float(nphi);
      const float3 wi = make_float3(rz * std::cos(phi), rz * std::sin(phi), z);
      const float3 h = normalize(wo + wi);
      s += double(sheen_lobe(mu, z, h.z, alpha)) * z;
    }
  }
  return s * 2.0 * PR_PI / (double(nz) * double(nphi));
}

// The single-scattering albedo of white rough glass seen from wo (z > 0) with relative ior eta
// (the other side's over wo's): over visible normals, both the reflection and the refraction
// each microfacet gives, weighted by its Fresnel, each G2 / G1 (f cos / pdf of the sampling
// rough_glass_sample does, kernels/shared/bsdf.h).
double glassAlbedo(float mu, float alpha, float eta, int samples) {
  const float3 wo = viewAt(mu, 0.0f);
  const float a2 = alpha * alpha;
  const double lo = ggx_lambda(mu, a2);
  double s = 0.0;
  for (int a = 0; a < samples; ++a)
    for (int b = 0; b < samples; ++b) {
      const float u1 = (float(a) + 0.5f) / float(samples), u2 = (float(b) + 0.5f) / float(samples);
      const float3 h = ggx_sample_vndf(wo, alpha, alpha, u1, u2);
      const float c = dot(wo, h);
      if (!(c > 0.0f)) continue;
      const double fr = fresnel_dielectric(c, eta);
      const float3 wr = h * (2.0f * c) - wo;
      if (wr.z > 0.0f) s += fr * (1.0 + lo) / (1.0 + lo + ggx_lambda(wr.z, a2));
      const float sin2_t = (1.0f - c * c) / (eta * eta);
      if (sin2_t >= 1.0f) continue;
      const float3 wt = -wo / eta + h * (c / eta - std::sqrt(1.0f - sin2_t));
      if (wt.z < 0.0f) s += (1.0 - fr) * (1.0 + lo) / (1.0 + lo + ggx_lambda(-wt.z, a2));
    }
  return s / (double(samples) * double(samples));
}

// The GGX albedo seen from wo, each microfacet weighted by the exact dielectric Fresnel's
// shape at ior eta (fresnel_dielectric_weight).
double ggxDielectricAlbedo(float3 wo, float alpha, float eta, int samples) {
  double s = 0.0;
  ggxReflections(wo, alpha, alpha, samples,
                 [&](float voh, double w) { s += w * fresnel_dielectric_weight(voh, eta); });
  return s / (double(samples) * double(samples));
}

// The glass table's ior at grid point k of n.
float gridIor(int k, int n) {
  auto z = [](float ior) { return (ior - 1.0f) / (ior + 1.0f); };
  const float lo = z(PR_GLASS_TABLE_MIN_IOR), hi = z(PR_GLASS_TABLE_MAX_IOR);
  const float zk = lo + (hi - lo) * float(k) / float(n - 1);
  return (1.0f + zk) / (1.0f - zk);
}

}  // namespace

BsdfTables computeBsdfTables(int cosines, int roughnesses, int samples, int stride) {
  BsdfTables t;
  t.cosines = cosines;
  t.roughnesses = roughnesses;
  const size_t n2 = size_t(cosines) * size_t(roughnesses);
  t.ggxE.resize(n2);
  t.ggxEs.resize(n2);
  t.ggxEavg.resize(size_t(roughnesses));
  t.sheenE.resize(n2);
  parallelFor(roughnesses, [&](int j) {
    const float r = gridRoughness(j, roughnesses), alpha = r * r;
    for (int i = 0; i < cosines; ++i) {
      const size_t k = size_t(j) * size_t(cosines) + size_t(i);
      if (k % size_t(stride) != 0) continue;
      const float mu = gridCos(i, cosines);
      double e, es;
      ggxAlbedo(viewAt(mu, 0.0f), alpha, alpha, samples, &e, &es);
      t.ggxE[k] = float(e);
      t.ggxEs[k] = float(es);
      t.sheenE[k] = float(sheenAlbedo(mu, alpha, samples));
    }
    if (j % stride != 0) return;
    t.ggxEavg[size_t(j)] = float(hemisphereAverage(2 * cosines, [&](float mu) {
      double e, es;
      ggxAlbedo(viewAt(mu, 0.0f), alpha, alpha, samples / 2, &e, &es);
      return e;
    }));
  });
  t.anisoCosines = kBsdfAnisoCos;
  t.anisoRoughnesses = kBsdfAnisoRoughness;
  t.anisoRatios = kBsdfAnisoRatio;
  const int rows = t.anisoRatios * t.anisoRoughnesses;
  t.anisoE.resize(size_t(rows) * size_t(t.anisoCosines));
  t.anisoEs.resize(t.anisoE.size());
  t.anisoEavg.resize(size_t(rows));
  parallelFor(rows, [&](int row) {
    const float r = gridRoughness(row % t.anisoRoughnesses, t.anisoRoughnesses);
    const float q = gridRoughness(row / t.anisoRoughnesses, t.anisoRatios);
    const float ax = r * r, ay = std::fmax(r * q * r * q, PR_MIN_ALPHA);
    const int s = samples / 2;
    for (int i = 0; i < t.anisoCosines; ++i) {
      if ((size_t(row) * size_t(t.anisoCosines) + size_t(i)) % size_t(stride) != 0) continue;
      double e, es;
      ggxAlbedoAniso(gridCos(i, t.anisoCosines), ax, ay, s, &e, &es);
      t.anisoE[size_t(row) * size_t(t.anisoCosines) + size_t(i)] = float(e);
      t.anisoEs[size_t(row) * size_t(t.anisoCosines) + size_t(i)] = float(es);
    }
    if (row % stride != 0) return;
    t.anisoEavg[size_t(row)] = float(hemisphereAverage(2 * t.anisoCosines, [&](float mu) {
      double e, es;
      ggxAlbedoAniso(mu, ax, ay, s / 2, &e, &es);
      return e;
    }));
  });
  t.glassCosines = kBsdfGlassCos;
  t.glassRoughnesses = kBsdfGlassRoughness;
  t.glassIors = kBsdfGlassIor;
  const int glassRows = 2 * t.glassIors * t.glassRoughnesses;
  t.glassE.resize(size_t(glassRows) * size_t(t.glassCosines));
  t.glassEavg.resize(size_t(glassRows));
  parallelFor(glassRows, [&](int row) {
    const int j = row % t.glassRoughnesses, k = (row / t.glassRoughnesses) % t.glassIors;
    const float r = gridRoughness(j, t.glassRoughnesses), ior = gridIor(k, t.glassIors);
    const float eta = row < glassRows / 2 ? ior : 1.0f / ior;
    for (int i = 0; i < t.glassCosines; ++i) {
      const size_t at = size_t(row) * size_t(t.glassCosines) + size_t(i);
      if (at % size_t(stride) != 0) continue;
      t.glassE[at] = float(glassAlbedo(gridCos(i, t.glassCosines), r * r, eta, samples / 2));
    }
    if (row % stride != 0) return;
    t.glassEavg[size_t(row)] = float(hemisphereAverage(
        2 * t.glassCosines, [&](float mu) { return glassAlbedo(mu, r * r, eta, samples / 4); }));
  });
  t.dielectricCosines = kBsdfDielectricCos;
  t.dielectricRoughnesses = kBsdfDielectricRoughness;
  t.dielectricIors = kBsdfDielectricIor;
  const int dielectricRows = t.dielectricIors * t.dielectricRoughnesses;
  t.dielectricE.resize(size_t(dielectricRows) * size_t(t.dielectricCosines));
  t.dielectricWeight.resize(size_t(t.dielectricIors));
  parallelFor(dielectricRows, [&](int row) {
    const int j = row % t.dielectricRoughnesses, k = row / t.dielectricRoughnesses;
    const float r = gridRoughness(j, t.dielectricRoughnesses);
    const float ior = gridIor(k, t.dielectricIors);
    for (int i = 0; i < t.dielectricCosines; ++i) {
      const size_t at = size_t(row) * size_t(t.dielectricCosines) + size_t(i);
      if (at % size_t(stride) != 0) continue;
      t.dielectricE[at] = float(ggxDielectricAlbedo(viewAt(gridCos(i, t.dielectricCosines), 0.0f),
                                                    r * r, ior, samples / 2));
    }
  });
  for (int k = 0; k < t.dielectricIors; k += stride)
    t.dielectricWeight[size_t(k)] = float(hemisphereAverage(4096, [&](float mu) {
      return fresnel_dielectric_weight(mu, gridIor(k, t.dielectricIors));
    }));
  return t;
}

std::string bsdfTablesHeader(const BsdfTables& t) {
  std::string s =
      "// Generated by tools/tables/bsdf_tables (build/bsdf_tables > "
      "kernels/shared/bsdf_tables.h); do "
      "not\n"
      "// edit. Directional albedos for the BSDFs' energy compensation and layering\n"
      "// (kernels/shared/bsdf.h): index [roughness][cos], on a grid of PR_BSDF_TABLE_R x\n"
      "// PR_BSDF_TABLE_COS points uniform in roughness = sqrt(alpha) from\n"
      "// PR_TABLE_MIN_ROUGHNESS to 1 and in sqrt(cos) from 0 to 1.\n"
      "#pragma once\n\n#include \"shared/common.h\"\n\nPR_NAMESPACE_BEGIN\n\n";
  // A table's grid: one #define per axis, then a blank line.
  auto grid = [&](const std::vector<std::pair<const char*, int>>& axes) {
    for (const auto& [name, n] : axes)
      s += std::string("#define ") + name + " " + std::to_string(n) + "\n";
    s += "\n";
  };
  grid({{"PR_BSDF_TABLE_COS", t.cosines}, {"PR_BSDF_TABLE_R", t.roughnesses}});
  auto table = [&](const char* name, const char* what, const std::vector<float>& v) {
    appendKernelTable(s, name, what, v);
  };
  table("pr_ggx_e", "GGX albedo with F = 1.", t.ggxE);
  table("pr_ggx_es", "GGX albedo weighted by Schlick's (1 - v.h)^5.", t.ggxEs);
  table("pr_ggx_eavg", "GGX albedo averaged over the hemisphere (cosine-weighted).", t.ggxEavg);
  table("pr_sheen_e", "The white Charlie sheen lobe's albedo.", t.sheenE);
  s += "// Anisotropic GGX, averaged over the view's azimuth: index [ratio][roughness][cos] on a\n"
       "// grid uniform in sqrt(cos) (PR_BSDF_ANISO_COS points from 0 to 1), in the larger\n"
       "// roughness and in the ratio of the smaller to it (PR_BSDF_ANISO_R and\n"
       "// PR_BSDF_ANISO_Q points from PR_TABLE_MIN_ROUGHNESS to 1).\n";
  grid({{"PR_BSDF_ANISO_COS", t.anisoCosines},
        {"PR_BSDF_ANISO_R", t.anisoRoughnesses},
        {"PR_BSDF_ANISO_Q", t.anisoRatios}});
  table("pr_ggx_e_aniso", "GGX albedo with F = 1.", t.anisoE);
  table("pr_ggx_es_aniso", "GGX albedo weighted by Schlick's (1 - v.h)^5.", t.anisoEs);
  table("pr_ggx_eavg_aniso", "GGX albedo averaged over the hemisphere: [ratio][roughness].",
        t.anisoEavg);
  s += "// White rough glass (GGX reflection and refraction, no 1/eta^2): index\n"
       "// [side][ior][roughness][cos], side 0 seen from outside (eta = ior), 1 from inside; a "
       "grid\n"
       "// uniform in sqrt(cos) from 0 to 1 (PR_BSDF_GLASS_COS points), in roughness from\n"
       "// PR_TABLE_MIN_ROUGHNESS to 1 (PR_BSDF_GLASS_R) and in (ior - 1) / (ior + 1) from\n"
       "// PR_GLASS_TABLE_MIN_IOR to PR_GLASS_TABLE_MAX_IOR (PR_BSDF_GLASS_IOR).\n";
  grid({{"PR_BSDF_GLASS_COS", t.glassCosines},
        {"PR_BSDF_GLASS_R", t.glassRoughnesses},
        {"PR_BSDF_GLASS_IOR", t.glassIors}});
  table("pr_glass_e", "Rough glass albedo.", t.glassE);
  table("pr_glass_eavg", "Rough glass albedo averaged over the hemisphere: [side][ior][roughness].",
        t.glassEavg);
  s +=
      "// The dielectric layer's GGX albedo weighted by the exact Fresnel's shape\n"
      "// (fresnel_dielectric_weight): index [ior][roughness][cos] on a grid uniform in sqrt(cos)\n"
      "// (PR_BSDF_DIELECTRIC_COS points), in roughness (PR_BSDF_DIELECTRIC_R) and in\n"
      "// (ior - 1) / (ior + 1) (PR_BSDF_DIELECTRIC_IOR) as the glass tables.\n";
  grid({{"PR_BSDF_DIELECTRIC_COS", t.dielectricCosines},
        {"PR_BSDF_DIELECTRIC_R", t.dielectricRoughnesses},
        {"PR_BSDF_DIELECTRIC_IOR", t.dielectricIors}});
  table("pr_ggx_ed", "GGX albedo weighted by the dielectric Fresnel's shape.", t.dielectricE);
  table("pr_fresnel_wavg", "The shape averaged over the hemisphere (cosine-weighted): [ior].",
        t.dielectricWeight);
  s += "PR_NAMESPACE_END\n";
  return s;
}

}  // namespace pr
