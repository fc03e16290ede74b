// Emitter sampling (kernels/shared/lights.h) on the CPU reference: the solid angle a triangle
// subtends, chi-square tests of the points light_sample draws against the density it claims
// (uniform in solid angle where it samples by solid angle, uniform in area elsewhere), and the
// pdf of a given point (what MIS uses) equal to the pdf of drawing it.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "shared/lights.h"
#include "shared/rng.h"
#include "shared/types.h"
#include "support/chi_square.h"

namespace pr {
namespace {

using dev::float3;
using dev::make_float3;

struct Tri {
  float3 v0, e1, e2;
};

// The solid angle of (a, b, c) from p in double precision (Van Oosterom and Strackee 1983).
double solidAngle(float3 p, float3 a, float3 b, float3 c) {
  double r[3][3] = {{a.x - p.x, a.y - p.y, a.z - p.z},
                    {b.x - p.x, b.y - p.y, b.z - p.z},
                    {c.x - p.x, c.y - p.y, c.z - p.z}};
  double len[3];
  for (int i = 0; i < 3; ++i)
    len[i] = std::sqrt(r[i][0] * r[i][0] + r[i][1] * r[i][1] + r[i][2] * r[i][2]);
  auto dotd = [&](int i, int j) {
    return r[i][0] * r[j][0] + r[i][1] * r[j][1] + r[i][2] * r[j][2];
  };
  const double triple = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) -
                        r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
                        r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
  const double den =
      len[0] * len[1] * len[2] + dotd(0, 1) * len[2] + dotd(1, 2) * len[0] + dotd(2, 0) * len[1];
  double omega = 2.0 * std::atan2(std::fabs(triple), den);
  if (omega < 0) omega += 2.0 * M_PI;
  return omega;
}

float3 at(const Tri& t, double b1, double b2) {
  return make_float3(float(t.v0.x + t.e1.x * b1 + t.e2.x * b2),
                     float(t.v0.y + t.e1.y * b1 + t.e2.y * b2),
                     float(t.v0.z + t.e1.z * b1 + t.e2.z * b2));
}

dev::Light triangleLight(const Tri& t) {
  dev::Light l{};
  l.type = PR_LIGHT_TRIANGLE;
  l.p0x = t.v0.x, l.p0y = t.v0.y, l.p0z = t.v0.z;
  l.e1x = t.e1.x, l.e1y = t.e1.y, l.e1z = t.e1.z;
  l.e2x = t.e2.x, l.e2y = t.e2.y, l.e2z = t.e2.z;
  l.area = 0.5f * dev::length(dev::cross(t.e1, t.e2));
  l.le_r = l.le_g = l.le_b = 1.0f;
  l.inst = PR_INVALID_INDEX;
  return l;
}

// The triangle cut into kGrid^2 similar cells in barycentric space: square (i, j) of the grid,
// lower or upper half. Index (j * kGrid + i) * 2 + upper; squares past the hypotenuse unused.
constexpr int kGrid = 8;
constexpr int kCells = 2 * kGrid * kGrid;
int cellOf(double b1, double b2) {
  const double x = b1 * kGrid, y = b2 * kGrid;
  int i = std::min(int(x), kGrid - 1), j = std::min(int(y), kGrid - 1);
  int upper = (x - i) + (y - j) > 1.0;
  if (i + j > kGrid - 1 || (i + j == kGrid - 1 && upper)) upper = 0, i = std::max(0, kGrid - 1 - j);
  return (j * kGrid + i) * 2 + upper;
}

// Probability of each cell: by solid angle or by area.
std::vector<double> cellProbabilities(const Tri& t, float3 p, bool solid) {
  std::vector<double> prob(kCells, 0.0);
  for (int j = 0; j < kGrid; ++j)
    for (int i = 0; i + j < kGrid; ++i) {
      const double g = 1.0 / kGrid;
      const float3 a = at(t, i * g, j * g), b = at(t, (i + 1) * g, j * g),
                   c = at(t, i * g, (j + 1) * g);
      prob[(j * kGrid + i) * 2] = solid ? solidAngle(p, a, b, c) : 1.0;
      if (i + j < kGrid - 1) {
        const float3 d = at(t, (i + 1) * g, (j + 1) * g);
        prob[(j * kGrid + i) * 2 + 1] = solid ? solidAngle(p, b, d, c) : 1.0;
      }
    }
  double sum = 0.0;
  for (double v : prob) sum += v;
  for (double& v : prob) v /= sum;
  return prob;
}

// Cell probabilities of the density light_pdf_triangle reports from p (shading normal n),
// integrated over the triangle on a fine grid (solid angle = area x cos / d^2).
std::vector<double> cellProbabilitiesOfPdf(const Tri& t, float3 p, float3 n) {
  constexpr int kFine = 192;
  std::vector<double> prob(kCells, 0.0);
  const float3 cr = dev::cross(t.e1, t.e2);
  const double subArea = 0.5 * dev::length(cr) / (double(kFine) * kFine);
  const float3 nl = dev::normalize(cr);
  for (int j = 0; j < kFine; ++j)
    for (int i = 0; i + j < kFine; ++i)
      for (int upper = 0; upper < 2 && (upper == 0 || i + j < kFine - 1); ++upper) {
        const double off = upper ? 2.0 / 3.0 : 1.0 / 3.0;
        const double b1 = (i + off) / kFine, b2 = (j + off) / kFine;
        const float3 x = at(t, b1, b2), d = x - p;
        const double d2 = dev::dot(d, d), cosL = std::fabs(dev::dot(d, nl)) / std::sqrt(d2);
        const float pdf = dev::light_pdf_triangle(1.0f, p, n, x, t.v0, t.e1, t.e2);
        prob[cellOf(b1, b2)] += pdf * subArea * cosL / d2;
      }
  return prob;
}

// Draws `n` points with light_sample from p (shading normal nRef) and returns the chi-square
// tail probability of their cells against `prob`, by default the cells' probabilities by
// solid angle (solid) or by area.
double samplingPValue(const Tri& t, float3 p, bool expectSolid, int n, uint32_t seed,
                      bool forceArea = false, float3 nRef = make_float3(0, 0, 0),
                      const std::vector<double>* expected = nullptr) {
  const dev::Light l = triangleLight(t);
  const std::vector<double> prob = expected ? *expected : cellProbabilities(t, p, expectSolid);
  std::vector<double> count(kCells, 0.0);
  dev::Rng rng = dev::rng_make(seed, PR_RNG_TEST, 0u, 0u, 0u);
  for (int s = 0; s < n; ++s) {
    const float u1 = dev::rng_next(&rng), u2 = dev::rng_next(&rng);
    dev::LightSample ls;
    float b1 = 0, b2 = 0;
    if (forceArea) {
      const auto b = dev::sample_triangle(u1, u2);
      b1 = b.x, b2 = b.y;
    } else if (!dev::light_sample(&l, 1.0f, p, nRef, u1, u2, &ls, &b1, &b2)) {
      continue;
    }
    count[cellOf(b1, b2)] += 1.0;
  }
  std::vector<double> expectedCounts(kCells);
  for (int c = 0; c < kCells; ++c) expectedCounts[c] = prob[c] * n;
  return test::chiSquarePValue(count, expectedCounts);
}

float omegaOf(const Tri& t, float3 p) {
  dev::SphericalTriangle st;
  return dev::spherical_triangle(p, t.v0, t.e1, t.e2, &st);
}

const Tri kBig = {make_float3(-1, 1, -1), make_float3(2, 0, 0), make_float3(0.5f, 0, 2)};

TEST(SphericalTriangle, SolidAngleMatchesTheClosedForm) {
  dev::Rng rng = dev::rng_make(3u, PR_RNG_TEST, 0u, 1u, 0u);
  int checked = 0;
  for (int k = 0; k < 2000; ++k) {
    float r[12];
    for (float& v : r) v = 4.0f * dev::rng_next(&rng) - 2.0f;
    const Tri t = {make_float3(r[0], r[1], r[2]), make_float3(r[3], r[4], r[5]),
                   make_float3(r[6], r[7], r[8])};
    const float3 p = make_float3(r[9], r[10], r[11]);
    const double want = solidAngle(p, t.v0, at(t, 1, 0), at(t, 0, 1));
    if (want < PR_MIN_SPHERICAL_SOLID_ANGLE) continue;
    ++checked;
    EXPECT_NEAR(omegaOf(t, p), want, 2e-3 * want + 1e-5) << "case " << k;
  }
  EXPECT_GT(checked, 1000);
}

TEST(SphericalTriangle, SamplesAreUniformInSolidAngle) {
  // Near a large triangle (solid angle ~1.2 sr, far from uniform in area), and from just above
  // its plane near an edge (grazing).
  for (const float3 p : {make_float3(0.1f, 0.2f, 0.3f), make_float3(1.2f, 1.15f, 0.3f)}) {
    const float omega = omegaOf(kBig, p);
    ASSERT_TRUE(dev::use_solid_angle(omega)) << omega;
    EXPECT_GT(samplingPValue(kBig, p, true, 200000, 11), 1e-4) << "from " << p.x << " " << p.y;
    // The test can tell: area-uniform points fail it, as a sampler whose pdf said solid angle
    // while it drew by area would.
    EXPECT_LT(samplingPValue(kBig, p, true, 200000, 12, true), 1e-6);
  }
}

TEST(SphericalTriangle, SmallOrFarTrianglesAreSampledByArea) {
  const float3 far = make_float3(0.0f, 200.0f, 0.0f);
  ASSERT_FALSE(dev::use_solid_angle(omegaOf(kBig, far)));
  EXPECT_GT(samplingPValue(kBig, far, false, 100000, 13), 1e-4);
}

// With the receiver's normal, directions follow the cosine-warped density (pbrt-v4's bilinear
// warp): checked against the pdf light_pdf_triangle reports for a point, which must also
// integrate to 1 over the triangle; a receiver facing the triangle and one at a grazing angle.
TEST(SphericalTriangle, CosineWarpedSamplesFollowTheReportedPdf) {
  const float3 p = make_float3(0.1f, 0.2f, 0.3f);
  for (const float3 n : {make_float3(0, 1, 0), dev::normalize(make_float3(1.0f, 0.15f, 0.2f))}) {
    const std::vector<double> prob = cellProbabilitiesOfPdf(kBig, p, n);
    double total = 0.0;
    for (double v : prob) total += v;
    EXPECT_NEAR(total, 1.0, 2e-3) << "the pdf does not integrate to 1 for n.x " << n.x;
    EXPECT_GT(samplingPValue(kBig, p, true, 200000, 14, false, n, &prob), 1e-4) << n.x;
    // Not the unwarped density: the grazing receiver tells them apart.
    if (n.x > 0.5f) {
      const std::vector<double> flat = cellProbabilities(kBig, p, true);
      EXPECT_LT(samplingPValue(kBig, p, true, 200000, 15, false, n, &flat), 1e-6);
    }
  }
}

// MIS needs the pdf of a point reached another way: it must be the density light_sample drew
// it with, in both regimes, with and without the cosine warp.
TEST(SphericalTriangle, PdfOfAPointEqualsThePdfOfDrawingIt) {
  const dev::Light l = triangleLight(kBig);
  for (const float3 n :
       {make_float3(0, 0, 0), make_float3(0, 1, 0), dev::normalize(make_float3(1.0f, 0.15f, 0.2f))})
    for (const float3 p : {make_float3(0.1f, 0.2f, 0.3f), make_float3(1.2f, 1.15f, 0.3f),
                           make_float3(0.0f, 200.0f, 0.0f)}) {
      dev::Rng rng = dev::rng_make(5u, PR_RNG_TEST, 0u, 2u, 0u);
      for (int s = 0; s < 2000; ++s) {
        const float u1 = dev::rng_next(&rng), u2 = dev::rng_next(&rng);
        dev::LightSample ls;
        float b1, b2;
        if (!dev::light_sample(&l, 0.25f, p, n, u1, u2, &ls, &b1, &b2)) continue;
        const float pdf = dev::light_pdf_triangle(0.25f, p, n, ls.pos, kBig.v0, kBig.e1, kBig.e2);
        ASSERT_NEAR(pdf, ls.pdf, 2e-3f * ls.pdf) << "sample " << s << " from y " << p.y;
      }
    }
}

}  // namespace
}  // namespace pr
