// The energy model's sheen (kernels/shared/sheen_tables.h): a layer of fibres standing along the
// normal, of unit thickness and density, that scatters without absorbing (Zeltner, Burley and
// Chiang 2022, the model of Blender's Cycles and OpenPBR). Its reflectance R and the linearly
// transformed cosine that stands for its lobe are computed here by random walks through the layer
// and a fit, written out by tools/tables/sheen_tables.cpp and recomputed in part by the tests.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pr {

// The committed grid: cosines (uniform in sqrt(cos) from 0 to 1) x roughnesses (uniform from
// PR_TABLE_MIN_ROUGHNESS to 1), and the walks per grid point.
constexpr int kSheenTableCos = 16;
constexpr int kSheenTableRoughness = 16;
constexpr int kSheenWalks = 2000000;

// What the walks from one view direction give: the share that leaves through the top (R) and
// the density over solid angle of where it leaves, on a grid of kSheenBins x kSheenBins cells
// uniform in cos and in azimuth from 0 to pi (the lobe is symmetric about the view's plane; the
// view's azimuth is 0). density[i * kSheenBins + j]: cos cell i, azimuth cell j; it integrates to
// R over the hemisphere.
constexpr int kSheenBins = 16;
struct SheenWalks {
  double reflectance = 0.0;
  int64_t reflected = 0;
  std::vector<double> density;
};
SheenWalks sheenWalks(double mu, double roughness, int64_t walks, uint64_t seed);

// The lobe's linearly transformed cosine in the frame where the view lies in the xz-plane
// (x >= 0): D(w) = D_cos(w') |det M^-1| / |M^-1 w|^3 with w' = M^-1 w / |M^-1 w| and
// M^-1 = [[a, 0, b], [0, a, 0], [0, 0, 1]]. f cos = R D.
double sheenLtc(double a, double b, double x, double y, double z);

// a and b fitted to the walks' density (least squares over solid angle); a cosine (1, 0) where
// too few walks came back to fit.
void fitSheenLtc(const SheenWalks& w, double* a, double* b);

struct SheenTables {
  int cosines = 0, roughnesses = 0;
  std::vector<float> a, b, r;  // [roughness][cos]
};

// The tables; with a stride only every stride-th grid point is computed (the others 0).
SheenTables computeSheenTables(int cosines, int roughnesses, int64_t walks, int stride = 1);

// The header kernels/shared/sheen_tables.h holding t.
std::string sheenTablesHeader(const SheenTables& t);

}  // namespace pr
