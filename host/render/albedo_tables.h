// The directional-albedo tables that the BSDFs' energy compensation and layering read
// (kernels/shared/bsdf_tables.h): computed here from the same microfacet code the kernels run,
// written out by tools/tables/bsdf_tables.cpp, and recomputed by the tests to check the committed
// copy.
#pragma once

#include <string>
#include <vector>

namespace pr {

// The committed tables' grid (cosines x roughnesses) and integration accuracy.
constexpr int kBsdfTableCos = 64;
constexpr int kBsdfTableRoughness = 32;
constexpr int kBsdfTableSamples = 128;
// Anisotropic GGX: cosines x roughnesses (the larger alpha's) x ratios (of the roughnesses).
constexpr int kBsdfAnisoCos = 16;
constexpr int kBsdfAnisoRoughness = 12;
constexpr int kBsdfAnisoRatio = 8;
// Rough glass: cosines x roughnesses x iors, for each side of the surface.
constexpr int kBsdfGlassCos = 16;
constexpr int kBsdfGlassRoughness = 16;
constexpr int kBsdfGlassIor = 8;
// The dielectric layer's Fresnel (fresnel_dielectric_weight): cosines x roughnesses x iors.
constexpr int kBsdfDielectricCos = 16;
constexpr int kBsdfDielectricRoughness = 12;
constexpr int kBsdfDielectricIor = 8;

struct BsdfTables {
  int cosines = 0, roughnesses = 0;  // grid points, uniform in sqrt(cos) and in roughness
  std::vector<float> ggxE;           // GGX albedo with F = 1: [roughness][cos]
  std::vector<float> ggxEs;          // ... weighted by Schlick's (1 - v.h)^5: [roughness][cos]
  std::vector<float> ggxEavg;        // 2 \int E(mu) mu dmu: [roughness]
  std::vector<float> sheenE;         // the white Charlie sheen lobe's albedo: [roughness][cos]
  // Anisotropic GGX averaged over the view's azimuth, on a grid uniform in sqrt(cos), in the
  // larger roughness and in the ratio of the smaller to it (both from PR_TABLE_MIN_ROUGHNESS).
  int anisoCosines = 0, anisoRoughnesses = 0, anisoRatios = 0;
  std::vector<float> anisoE;     // [ratio][roughness][cos]
  std::vector<float> anisoEs;    // [ratio][roughness][cos]
  std::vector<float> anisoEavg;  // [ratio][roughness]
  // White rough glass (reflection and refraction, no 1/eta^2) seen from outside (side 0, relative
  // ior eta = ior) and inside (side 1, 1 / ior), on a grid uniform in sqrt(cos), in roughness
  // from PR_TABLE_MIN_ROUGHNESS and in (ior - 1) / (ior + 1) over PR_GLASS_TABLE_*_IOR.
  int glassCosines = 0, glassRoughnesses = 0, glassIors = 0;
  std::vector<float> glassE;     // [side][ior][roughness][cos]
  std::vector<float> glassEavg;  // 2 \int E(mu) mu dmu: [side][ior][roughness]
  // GGX albedo weighted by the exact dielectric Fresnel's shape (fresnel_dielectric_weight), on a
  // grid uniform in sqrt(cos), in roughness and in (ior - 1) / (ior + 1) as the glass tables.
  int dielectricCosines = 0, dielectricRoughnesses = 0, dielectricIors = 0;
  std::vector<float> dielectricE;       // [ior][roughness][cos]
  std::vector<float> dielectricWeight;  // the shape's 2 \int w(mu) mu dmu: [ior]
};

// The tables on a grid of `cosines` x `roughnesses` points (both ends included); `samples` is
// the side of each integral's stratified grid. With a stride, only every stride-th entry of each
// table is computed (the others are 0): a check of part of them in less time.
BsdfTables computeBsdfTables(int cosines, int roughnesses, int samples, int stride = 1);

// The header kernels/shared/bsdf_tables.h holding t.
std::string bsdfTablesHeader(const BsdfTables& t);

}  // namespace pr
