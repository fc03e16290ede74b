// Emitter sampling (kernels/shared/lights.h) on the CPU reference: the solid angle a triangle
// subtends, chi-square tests of the points light_sample draws against the density it claims
// (uniform in solid angle where it samples by solid angle, uniform in area elsewhere), and the
// pdf of a given point (what MIS uses) equal to the pdf of drawing it. The light-type table:
// each type's flags, its dispatch reaching its own function set, and per type the pdfs of its
// samples and the receiver importance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "scene/environment_map.h"
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

// The light-type table (PR_LIGHT_TYPES): what each type says of itself.
TEST(LightTable, EveryTypeHasItsFlags) {
  EXPECT_EQ(PR_LIGHT_TYPE_COUNT, 5);
  const struct {
    uint32_t type, flags;
  } want[] = {
      {PR_LIGHT_TRIANGLE, PR_LIGHT_ON_TRIANGLE | PR_LIGHT_JOINS_VERTEX0 | PR_LIGHT_EYE_PATHS},
      {PR_LIGHT_POINT, PR_LIGHT_DELTA_POSITION | PR_LIGHT_JOINS_VERTEX0 | PR_LIGHT_EYE_PATHS},
      {PR_LIGHT_SPOT, PR_LIGHT_DELTA_POSITION | PR_LIGHT_JOINS_VERTEX0 | PR_LIGHT_EYE_PATHS},
      {PR_LIGHT_DIRECTIONAL, PR_LIGHT_DELTA_DIRECTION | PR_LIGHT_AT_INFINITY | PR_LIGHT_EYE_PATHS},
      {PR_LIGHT_ENV, PR_LIGHT_AT_INFINITY | PR_LIGHT_EYE_PATHS},
  };
  for (const auto& w : want) EXPECT_EQ(dev::light_type_flags(w.type), w.flags) << w.type;
  EXPECT_EQ(dev::light_type_flags(PR_LIGHT_TYPE_COUNT), 0u);
  // What the callers rely on, for any type added later.
  for (uint32_t t = 0; t < PR_LIGHT_TYPE_COUNT; ++t) {
    EXPECT_FALSE(dev::light_is_triangle(t) && dev::light_is_delta(t)) << t;
    EXPECT_FALSE(dev::light_is_triangle(t) && dev::light_at_infinity(t)) << t;
    EXPECT_FALSE(dev::light_joins_vertex0(t) && dev::light_at_infinity(t)) << t;
    // The eye paths' first light density: the emission's pdf at vertex 0, or a disk's.
    EXPECT_TRUE(!dev::light_in_eye_paths(t) || dev::light_joins_vertex0(t) ||
                dev::light_at_infinity(t))
        << t;
    const uint32_t f = dev::light_type_flags(t);
    EXPECT_FALSE((f & PR_LIGHT_DELTA_POSITION) && (f & PR_LIGHT_DELTA_DIRECTION)) << t;
  }
}

// One light of each type, and the environment's data buffer.
struct LightsOfEveryType {
  std::vector<dev::Light> lights;
  std::vector<float> env;
  LightsOfEveryType() {
    lights.push_back(triangleLight(kBig));
    lights.back().le_r = 2.0f, lights.back().le_b = 0.5f;
    dev::Light point{};
    point.type = PR_LIGHT_POINT;
    point.p0x = 0.3f, point.p0y = 2.0f, point.p0z = -0.2f;
    point.le_r = 3.0f, point.le_g = 2.0f, point.le_b = 1.0f;
    lights.push_back(point);
    dev::Light spot = point;
    spot.type = PR_LIGHT_SPOT;
    const float3 axis = dev::normalize(make_float3(0.2f, -1.0f, 0.1f));
    spot.e1x = axis.x, spot.e1y = axis.y, spot.e1z = axis.z;
    spot.cos_inner = std::cos(0.3f), spot.cos_outer = std::cos(0.7f);
    lights.push_back(spot);
    dev::Light sun = spot;
    sun.type = PR_LIGHT_DIRECTIONAL;
    lights.push_back(sun);
    Environment e;
    e.width = 8, e.height = 4;
    e.rgb.resize(3 * 8 * 4);
    for (size_t i = 0; i < e.rgb.size(); ++i) e.rgb[i] = 0.1f + float(i % 7);
    float mean = 0.0f;
    env = environmentTables(e, &mean);
    dev::Light sky{};
    sky.type = PR_LIGHT_ENV;
    sky.inst = 8, sky.prim = 4;
    sky.p0x = std::cos(0.4f), sky.p0y = std::sin(0.4f);
    sky.le_r = sky.le_g = sky.le_b = 1.5f;
    sky.area = mean;
    lights.push_back(sky);
  }
};

bool sameBits(float a, float b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}
bool sameBits(float3 a, float3 b) {
  return sameBits(a.x, b.x) && sameBits(a.y, b.y) && sameBits(a.z, b.z);
}

// Each type's functions, named here rather than from the table: a row that names the wrong set
// (or a dispatcher that forgets a type) fails.
struct FunctionSet {
  uint32_t type;
  int (*sample)(const dev::Light*, const float*, float, float3, float3, float, float,
                dev::LightSample*, float*, float*);
  float (*pdf)(const dev::Light*, const float*, float, float3, float3, float3, float3);
  float (*sampleEmit)(const dev::Light*, const float*, float3, float, float, float3*, float3*);
  float (*pdfEmit)(const dev::Light*, float3, float3);
  float (*falloff)(const dev::Light*, float3);
  float (*power)(const dev::Light*, float);
  float (*importance)(const dev::Light*, float3, float3);
};
#define PR_TEST_SET(T, fn)                                                              \
  {                                                                                     \
    T, dev::light_##fn##_sample, dev::light_##fn##_pdf, dev::light_##fn##_sample_emit,  \
        dev::light_##fn##_pdf_emit, dev::light_##fn##_falloff, dev::light_##fn##_power, \
        dev::light_##fn##_importance                                                    \
  }
const FunctionSet kSets[] = {
    PR_TEST_SET(PR_LIGHT_TRIANGLE, triangle), PR_TEST_SET(PR_LIGHT_POINT, point),
    PR_TEST_SET(PR_LIGHT_SPOT, spot),         PR_TEST_SET(PR_LIGHT_DIRECTIONAL, directional),
    PR_TEST_SET(PR_LIGHT_ENV, env),
};
#undef PR_TEST_SET

TEST(LightTable, DispatchReachesEachTypesOwnFunctions) {
  const LightsOfEveryType all;
  ASSERT_EQ(sizeof kSets / sizeof kSets[0], size_t(PR_LIGHT_TYPE_COUNT));
  dev::Rng rng = dev::rng_make(21u, PR_RNG_TEST, 0u, 3u, 0u);
  for (const FunctionSet& set : kSets) {
    const dev::Light& l = all.lights[set.type];
    ASSERT_EQ(l.type, set.type);
    const float* data = all.env.data();
    for (int k = 0; k < 200; ++k) {
      float r[8];
      for (float& v : r) v = dev::rng_next(&rng);
      const float3 ref = make_float3(2 * r[0] - 1, r[1], 2 * r[2] - 1);
      const float3 n = dev::normalize(make_float3(r[3] - 0.5f, 1.0f, r[4] - 0.5f));
      dev::LightSample a{}, b{};
      float a1 = 0, a2 = 0, b1 = 0, b2 = 0;
      const int got = dev::light_sample_towards(&l, data, 0.5f, ref, n, r[5], r[6], &a, &a1, &a2);
      ASSERT_EQ(got, set.sample(&l, data, 0.5f, ref, n, r[5], r[6], &b, &b1, &b2)) << set.type;
      EXPECT_EQ(a.delta, dev::light_is_delta(set.type));
      if (got) {
        EXPECT_TRUE(sameBits(a.pos, b.pos) && sameBits(a.wi, b.wi) && sameBits(a.le, b.le));
        EXPECT_TRUE(sameBits(a.pdf, b.pdf) && sameBits(a.dist, b.dist)) << set.type;
        EXPECT_TRUE(sameBits(dev::light_pdf_towards(&l, data, 0.5f, ref, n, a.pos, a.wi),
                             set.pdf(&l, data, 0.5f, ref, n, a.pos, a.wi)));
      }
      float3 da, db, la, lb;
      const float pa = dev::light_sample_emit(&l, data, n, r[5], r[6], &da, &la);
      EXPECT_TRUE(sameBits(pa, set.sampleEmit(&l, data, n, r[5], r[6], &db, &lb)));
      EXPECT_TRUE(sameBits(da, db) && sameBits(la, lb)) << set.type;
      EXPECT_TRUE(sameBits(dev::light_pdf_emit_dir(&l, n, da), set.pdfEmit(&l, n, da)));
      EXPECT_TRUE(sameBits(dev::light_falloff(&l, da), set.falloff(&l, da)));
      EXPECT_TRUE(sameBits(dev::light_receiver_importance(&l, ref, n), set.importance(&l, ref, n)));
    }
    EXPECT_TRUE(sameBits(dev::light_power(&l, 3.0f), set.power(&l, 3.0f))) << set.type;
    EXPECT_GT(dev::light_power(&l, 3.0f), 0.0f) << set.type;
  }
}

// MIS and the light tracer need each type's pdfs to be those of its samples: the pdf of the
// point a sample drew (0 for delta lights, whose sample pdf is the pmf alone), and the pdf of
// the direction a light path leaves in where eye vertices join vertex 0 (0 elsewhere).
TEST(LightTable, EachTypesPdfsAreThoseOfItsSamples) {
  const LightsOfEveryType all;
  const float* data = all.env.data();
  dev::Rng rng = dev::rng_make(22u, PR_RNG_TEST, 0u, 4u, 0u);
  for (const dev::Light& l : all.lights) {
    int drawn = 0, apart = 0;
    for (int k = 0; k < 2000; ++k) {
      float r[6];
      for (float& v : r) v = dev::rng_next(&rng);
      const float3 ref = make_float3(2 * r[0] - 1, 0.2f * r[1], 2 * r[2] - 1);
      const float3 n = make_float3(0, 1, 0);
      dev::LightSample s;
      float b1, b2;
      if (dev::light_sample_towards(&l, data, 0.25f, ref, n, r[3], r[4], &s, &b1, &b2)) {
        ++drawn;
        EXPECT_NEAR(dev::length(s.wi), 1.0f, 1e-5f);
        const float pdf = dev::light_pdf_towards(&l, data, 0.25f, ref, n, s.pos, s.wi);
        if (s.delta) {
          EXPECT_EQ(s.pdf, 0.25f) << l.type;
          EXPECT_EQ(pdf, 0.0f) << l.type;
        } else if (std::fabs(pdf - s.pdf) > 2e-3f * s.pdf) {
          // A direction on an environment texel's edge may look up its neighbour: rare.
          ++apart;
          EXPECT_FALSE(dev::light_is_triangle(l.type)) << pdf << " drawn with " << s.pdf;
        }
        EXPECT_EQ(s.dist == PR_INF_F, dev::light_at_infinity(l.type) != 0) << l.type;
      }
      const float3 n0 = dev::normalize(make_float3(l.e1x + l.e2x, 1.0f, l.e1z)) * -1.0f;
      float3 dir, le;
      const float pe = dev::light_sample_emit(&l, data, n0, r[3], r[4], &dir, &le);
      if (!(pe > 0.0f)) continue;
      EXPECT_NEAR(dev::length(dir), 1.0f, 1e-5f);
      const float back = dev::light_pdf_emit_dir(&l, n0, dir);
      if (dev::light_joins_vertex0(l.type))
        ASSERT_NEAR(back, pe, 1e-4f * pe) << l.type;
      else
        EXPECT_EQ(back, 0.0f) << l.type;
      // Nothing leaves a light where its falloff is 0 (outside a spot's cone).
      EXPECT_GT(dev::light_falloff(&l, dir), 0.0f) << l.type;
    }
    EXPECT_GT(drawn, 1000) << l.type;
    EXPECT_LT(apart, drawn / 100) << l.type;
  }
}

// Receiver importance is what light sampling sees: for point and spot lights exactly the
// irradiance a sample brings (its falloff included) times the receiver's cosine; 0 for lights
// at infinity, which no receiver-aware sampler weighs.
TEST(LightTable, ReceiverImportanceIsTheSampledIrradiance) {
  const LightsOfEveryType all;
  dev::Rng rng = dev::rng_make(23u, PR_RNG_TEST, 0u, 5u, 0u);
  for (const dev::Light& l : all.lights) {
    for (int k = 0; k < 500; ++k) {
      const float3 ref =
          make_float3(2 * dev::rng_next(&rng) - 1, 0.0f, 2 * dev::rng_next(&rng) - 1);
      const float3 n = dev::normalize(make_float3(dev::rng_next(&rng) - 0.5f, 1.0f, 0.0f));
      const float importance = dev::light_receiver_importance(&l, ref, n);
      if (dev::light_at_infinity(l.type)) {
        EXPECT_EQ(importance, 0.0f);
        continue;
      }
      if (!dev::light_is_delta(l.type)) continue;
      dev::LightSample s;
      float b1, b2;
      if (!dev::light_sample_towards(&l, all.env.data(), 1.0f, ref, n, 0.5f, 0.5f, &s, &b1, &b2)) {
        EXPECT_EQ(importance, 0.0f);
        continue;
      }
      // Near a spot's cone the falloff is steep: tolerances relative to the unattenuated value.
      const float full = dev::luminance(make_float3(l.le_r, l.le_g, l.le_b)) / (s.dist * s.dist);
      const float want = dev::luminance(s.le) * std::max(dev::dot(n, s.wi), 0.0f);
      EXPECT_NEAR(importance, want, 1e-5f * full) << l.type;
      // The falloff as the light tracer sees it: along -wi, leaving the light.
      EXPECT_NEAR(dev::luminance(s.le), full * dev::light_falloff(&l, -1.0f * s.wi), 1e-5f * full);
    }
  }
}

}  // namespace
}  // namespace pr
