#include "render/sheen_volume.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

#include "shared/microfacet.h"
#include "render/table_text.h"
#include "util/parallel.h"

namespace pr {

namespace {

constexpr double kPi = 3.14159265358979323846;
// Scattering orders followed; a walk still inside after them is dropped.
constexpr int kMaxBounces = 64;
// Walks that must come back before their density is fitted.
constexpr int64_t kMinReflected = 2000;

struct Vec {
  double x, y, z;
};
Vec operator*(const Vec& v, double s) {
  return {v.x * s, v.y * s, v.z * s};
}
Vec operator+(const Vec& a, const Vec& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
double dotv(const Vec& a, const Vec& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
Vec unit(const Vec& v) {
  return v * (1.0 / std::sqrt(dotv(v, v)));
}
Vec crossv(const Vec& a, const Vec& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// splitmix64: a fixed, portable sequence (the tables must not depend on the standard library).
struct Random {
  uint64_t s;
  double next() {
    uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return double(z >> 11) * (1.0 / 9007199254740992.0);
  }
};

// The fibres' SGGX matrix is diag(1, 1, r^4) (cross-section sigma = r^2 along the normal). A
// propagation direction's extinction is the fibres' projected area sqrt(d^T S d); a scattering
// reflects wi off a visible microflake normal, sampled as a sphere's visible points mapped by
// S^(1/2) = diag(1, 1, r^2).
double extinction(const Vec& d, double r4) {
  return std::sqrt(d.x * d.x + d.y * d.y + r4 * d.z * d.z);
}

Vec scatter(const Vec& wi, double r2, Random& rng) {
  const Vec s = unit({wi.x, wi.y, r2 * wi.z});
  const Vec t = unit(crossv(std::fabs(s.x) > 0.9 ? Vec{0, 1, 0} : Vec{1, 0, 0}, s));
  const Vec b = crossv(s, t);
  const double rad = std::sqrt(rng.next()), phi = 2.0 * kPi * rng.next();
  const double u = rad * std::cos(phi), v = rad * std::sin(phi);
  const Vec p = t * u + b * v + s * std::sqrt(std::max(0.0, 1.0 - u * u - v * v));
  const Vec m = unit({p.x, p.y, r2 * p.z});
  return m * (2.0 * dotv(m, wi)) + wi * -1.0;
}

int binOf(double v, int n) {
  return std::min(n - 1, std::max(0, int(v * n)));
}

}  // namespace

SheenWalks sheenWalks(double mu, double roughness, int64_t walks, uint64_t seed) {
  const double r2 = roughness * roughness, r4 = r2 * r2;
  const double sin_o = std::sqrt(std::max(0.0, 1.0 - mu * mu));
  Random rng{seed};
  SheenWalks out;
  out.density.assign(kSheenBins * kSheenBins, 0.0);
  for (int64_t k = 0; k < walks; ++k) {
    Vec d{-sin_o, 0.0, -mu};  // propagation, entering through the top
    double depth = 0.0;       // below the top, in units of the layer's thickness
    for (int bounce = 0; bounce < kMaxBounces; ++bounce) {
      const double st = extinction(d, r4);
      const double t =
          st > 0.0 ? -std::log(1.0 - rng.next()) / st : std::numeric_limits<double>::infinity();
      depth -= t * d.z;
      if (depth > 1.0) break;
      if (depth < 0.0) {
        const double phi = std::atan2(std::fabs(d.y), d.x);
        out.density[binOf(d.z, kSheenBins) * kSheenBins + binOf(phi / kPi, kSheenBins)] += 1.0;
        ++out.reflected;
        break;
      }
      d = scatter(d * -1.0, r2, rng);
    }
  }
  // Each cell covers (1 / n) (pi / n) of the half the azimuths fold into: twice that in all.
  const double cell = 2.0 * (1.0 / kSheenBins) * (kPi / kSheenBins);
  for (double& v : out.density) v /= double(walks) * cell;
  out.reflectance = double(out.reflected) / double(walks);
  return out;
}

double sheenLtc(double a, double b, double x, double y, double z) {
  if (!(z > 0.0)) return 0.0;
  const double px = a * x + b * z, py = a * y, pz = z;
  const double l2 = px * px + py * py + pz * pz;
  const double l = std::sqrt(l2);
  return (pz / l) / kPi * (a * a) / (l2 * l);
}

namespace {

// The LTC's mean over each density cell (a 4 x 4 midpoint grid in cos and azimuth).
std::array<double, kSheenBins * kSheenBins> ltcCells(double a, double b) {
  constexpr int kSub = 4;
  std::array<double, kSheenBins * kSheenBins> c{};
  for (int i = 0; i < kSheenBins; ++i)
    for (int j = 0; j < kSheenBins; ++j) {
      double s = 0.0;
      for (int p = 0; p < kSub; ++p)
        for (int q = 0; q < kSub; ++q) {
          const double z = (i + (p + 0.5) / kSub) / kSheenBins;
          const double phi = kPi * (j + (q + 0.5) / kSub) / kSheenBins;
          const double sz = std::sqrt(std::max(0.0, 1.0 - z * z));
          s += sheenLtc(a, b, sz * std::cos(phi), sz * std::sin(phi), z);
        }
      c[i * kSheenBins + j] = s / (kSub * kSub);
    }
  return c;
}

// Nelder and Mead's simplex in two dimensions, from x0 with steps h, for `iterations` steps.
template <class F>
std::array<double, 2> minimise(F f, std::array<double, 2> x0, double h, int iterations) {
  using P = std::array<double, 2>;
  std::array<P, 3> s = {x0, P{x0[0] + h, x0[1]}, P{x0[0], x0[1] + h}};
  std::array<double, 3> v = {f(s[0]), f(s[1]), f(s[2])};
  auto mix = [](const P& a, const P& b, double t) {
    return P{a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t};
  };
  for (int it = 0; it < iterations; ++it) {
    std::array<int, 3> o = {0, 1, 2};
    std::sort(o.begin(), o.end(), [&](int i, int j) { return v[i] < v[j]; });
    const int best = o[0], mid = o[1], worst = o[2];
    const P c = mix(s[best], s[mid], 0.5);
    const P r = mix(s[worst], c, 2.0);
    const double fr = f(r);
    if (fr < v[best]) {
      const P e = mix(s[worst], c, 3.0);
      const double fe = f(e);
      if (fe < fr)
        s[worst] = e, v[worst] = fe;
      else
        s[worst] = r, v[worst] = fr;
    } else if (fr < v[mid]) {
      s[worst] = r, v[worst] = fr;
    } else {
      const P k = mix(s[worst], c, fr < v[worst] ? 1.5 : 0.5);
      const double fk = f(k);
      if (fk < std::min(fr, v[worst])) {
        s[worst] = k, v[worst] = fk;
      } else {
        for (int i : {mid, worst}) s[i] = mix(s[best], s[i], 0.5), v[i] = f(s[i]);
      }
    }
  }
  const int best = int(std::min_element(v.begin(), v.end()) - v.begin());
  return s[best];
}

}  // namespace

void fitSheenLtc(const SheenWalks& w, double* a, double* b) {
  *a = 1.0;
  *b = 0.0;
  if (w.reflected < kMinReflected) return;
  const double cell = (1.0 / kSheenBins) * (kPi / kSheenBins);
  auto error = [&](const std::array<double, 2>& p) {
    const std::array<double, kSheenBins* kSheenBins> c = ltcCells(std::exp(p[0]), p[1]);
    double e = 0.0;
    for (size_t i = 0; i < c.size(); ++i) {
      const double d = c[i] - w.density[i] / w.reflectance;
      e += d * d * cell;
    }
    return e;
  };
  const std::array<double, 2> p = minimise(error, {0.0, 0.0}, 0.5, 160);
  *a = std::exp(p[0]);
  *b = p[1];
}

SheenTables computeSheenTables(int cosines, int roughnesses, int64_t walks, int stride) {
  SheenTables t;
  t.cosines = cosines;
  t.roughnesses = roughnesses;
  const size_t n = size_t(cosines) * size_t(roughnesses);
  t.a.assign(n, 0.0f);
  t.b.assign(n, 0.0f);
  t.r.assign(n, 0.0f);
  std::vector<int64_t> reflected(n, 0);
  const int jobs = int((n + size_t(stride) - 1) / size_t(stride));
  parallelFor(jobs, [&](int job) {
    const size_t k = size_t(job) * size_t(stride);
    const int i = int(k % size_t(cosines)), j = int(k / size_t(cosines));
    const double x = double(i) / double(cosines - 1);
    const double mu = std::max(x * x, 1e-4);
    const double rough = PR_TABLE_MIN_ROUGHNESS +
                         (1.0 - PR_TABLE_MIN_ROUGHNESS) * double(j) / double(roughnesses - 1);
    const SheenWalks w = sheenWalks(mu, rough, walks, 0x5EED0000ull + k);
    double a, b;
    fitSheenLtc(w, &a, &b);
    t.a[k] = float(a);
    t.b[k] = float(b);
    t.r[k] = float(w.reflectance);
    reflected[k] = w.reflected;
  });
  // Where too few walks came back to fit a lobe (fewer than kMinReflected), the nearest
  // fitted one at a more grazing view stands in, so that interpolation meets no cosine between
  // stretched lobes; with a stride, those points keep the cosine.
  if (stride == 1)
    for (int j = 0; j < roughnesses; ++j)
      for (int i = 1; i < cosines; ++i) {
        const size_t k = size_t(j) * size_t(cosines) + size_t(i);
        if (reflected[k] < kMinReflected) {
          t.a[k] = t.a[k - 1];
          t.b[k] = t.b[k - 1];
        }
      }
  return t;
}

std::string sheenTablesHeader(const SheenTables& t) {
  std::string s =
      "// Generated by tools/tables/sheen_tables (host/render/sheen_volume.cpp); do not edit.\n"
      "// The energy model's sheen, a layer of fibres along the normal: its reflectance and the\n"
      "// linearly transformed cosine of its lobe, index [roughness][cos] on a grid of\n"
      "// PR_SHEEN_TABLE_R points uniform in roughness from PR_TABLE_MIN_ROUGHNESS to 1 and\n"
      "// PR_SHEEN_TABLE_COS points uniform in sqrt(cos) from 0 to 1.\n"
      "#pragma once\n\n#include \"shared/common.h\"\n\nPR_NAMESPACE_BEGIN\n\n";
  s += "#define PR_SHEEN_TABLE_COS " + std::to_string(t.cosines) + "\n";
  s += "#define PR_SHEEN_TABLE_R " + std::to_string(t.roughnesses) + "\n\n";
  auto table = [&](const char* name, const char* what, const std::vector<float>& v) {
    appendKernelTable(s, name, what, v);
  };
  // (Negative values would have clang-format align the columns, so the file would differ from
  // what this writes.)
  s += "// clang-format off\n";
  table("pr_sheen_r", "The layer's reflectance seen from the cos.", t.r);
  table("pr_sheen_ltc_a", "The LTC's a (M^-1 = [[a, 0, b], [0, a, 0], [0, 0, 1]]).", t.a);
  table("pr_sheen_ltc_b", "The LTC's b.", t.b);
  s += "// clang-format on\n\nPR_NAMESPACE_END\n";
  return s;
}

}  // namespace pr
