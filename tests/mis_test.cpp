// The MIS and resampling weights of kernels/shared/mis.h, as the kernels compute them: every
// family's weights of a path (or a sample) add to 1 whatever the densities (zero, infinite,
// NaN); the running products along a sub-path equal the per-vertex densities multiplied out;
// the eye paths' kept ratios give the weight of the whole path's densities; the connection
// history's GRIS merge is unbiased; and exact values that a changed exponent or a swapped
// forward / reverse density would miss.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "shared/eye_paths.h"
#include "shared/mis.h"

namespace pr {
namespace {

using namespace dev;

float weightL(float pl, float pe, float t) {
  return mis_connection_weight(PR_STRATEGY_L, pl, pe, t);
}
float weightE(float pl, float pe, float t) {
  return mis_connection_weight(PR_STRATEGY_E, pl, pe, t);
}

TEST(ConnectionMis, WeightsAddToOneForEveryPath) {
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> pdfs = {0.0f, 1e-30f, 1e-6f, 0.5f,  1.0f, 3.999f,
                             4.0f, 7.0f,   1e6f,  1e30f, inf,  nan};
  std::mt19937 gen(7);
  std::uniform_real_distribution<float> logu(-20.0f, 20.0f);
  for (int i = 0; i < 200; ++i) pdfs.push_back(std::exp(logu(gen)));
  for (float t : {0.0f, 0.5f, 1.0f, 4.0f, 100.0f}) {
    for (float pl : pdfs) {
      for (float pe : pdfs) {
        const float wl = weightL(pl, pe, t), we = weightE(pl, pe, t);
        ASSERT_GE(wl, 0.0f) << pl << " " << pe << " " << t;
        ASSERT_GE(we, 0.0f) << pl << " " << pe << " " << t;
        ASSERT_LE(wl, 1.0f);
        // Exactly 1 (E's weight is computed as 1 - L's; both rounded to float).
        ASSERT_NEAR(wl + we, 1.0f, 1e-7f) << pl << " " << pe << " " << t;
      }
    }
  }
}

TEST(ConnectionMis, StrategyEOnlyAtOrAboveTheThreshold) {
  // Below the threshold, or with MIS off, L keeps the whole path (E traces no ray).
  EXPECT_EQ(weightL(1.0f, 3.9f, 4.0f), 1.0f);
  EXPECT_EQ(weightE(1.0f, 3.9f, 4.0f), 0.0f);
  EXPECT_EQ(weightL(1.0f, 1e20f, 0.0f), 1.0f);
  EXPECT_EQ(weightE(1.0f, 1e20f, 0.0f), 0.0f);
  // At the threshold E takes its power-heuristic share.
  EXPECT_FLOAT_EQ(weightE(1.0f, 4.0f, 4.0f), 16.0f / 17.0f);
  // E cannot make the path (p_e = 0), with or without L's pdf: L alone.
  EXPECT_EQ(weightL(2.0f, 0.0f, 4.0f), 1.0f);
  EXPECT_EQ(weightL(0.0f, 0.0f, 4.0f), 1.0f);
  // L cannot make it (p_l = 0 < p_e): E alone.
  EXPECT_EQ(weightE(0.0f, 2.0f, 4.0f), 1.0f);
  EXPECT_EQ(weightL(0.0f, 2.0f, 4.0f), 0.0f);
}

TEST(ConnectionMis, AboveTheThresholdItIsThePowerHeuristic) {
  std::mt19937 gen(11);
  std::uniform_real_distribution<float> logu(-10.0f, 10.0f);
  for (int i = 0; i < 1000; ++i) {
    const float pl = std::exp(logu(gen)), pe = std::exp(logu(gen));
    if (!(pe / pl >= 4.0f)) continue;
    EXPECT_NEAR(weightE(pl, pe, 4.0f), power_heuristic(pe, pl), 2e-6f) << pl << " " << pe;
    EXPECT_NEAR(weightL(pl, pe, 4.0f), power_heuristic(pl, pe), 2e-6f) << pl << " " << pe;
  }
}

TEST(ConnectionMis, ThresholdedWeightsKeepAnEstimatorUnbiased) {
  // Two strategies sample x in (0, 1] with p_l = 1 and p_e = 2x (E's r = 2x never reaches the
  // threshold below x = t / 2); both weighted estimates of f = x^2 + 0.1 together integrate it.
  const float t = 1.5f;
  const double exact = 1.0 / 3.0 + 0.1;
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = 400000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double xl = 1.0 - u(gen);             // p_l = 1
    const double xe = std::sqrt(1.0 - u(gen));  // p_e = 2x
    const auto f = [](double x) { return x * x + 0.1; };
    const double est = weightL(1.0f, float(2.0 * xl), t) * f(xl) +
                       weightE(1.0f, float(2.0 * xe), t) * f(xe) / (2.0 * xe);
    sum += est;
    sum2 += est * est;
  }
  const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
  EXPECT_NEAR(mean, exact, 4.5 * se) << "standard error " << se;
}

TEST(ConnectionMis, AreaPdfIntegratesToTheSolidAngle) {
  // Directions uniform on the sphere from the origin (pdf 1 / 4 pi) meet the square
  // |x|, |y| <= a of the plane z = 1 with area pdf pdf_w cos / d^2; over the square it
  // integrates to the square's solid angle 4 asin(a^2 / (1 + a^2)) over 4 pi.
  const double a = 10.0, h = 0.01;
  double total = 0.0;
  for (double x = -a + h / 2; x < a; x += h) {
    for (double y = -a + h / 2; y < a; y += h) {
      const double d2 = x * x + y * y + 1.0;
      total += solid_angle_to_area_pdf(float(0.25 / M_PI), float(1.0 / std::sqrt(d2)), float(d2));
    }
  }
  total *= h * h;
  const double want = 4.0 * std::asin(a * a / (1.0 + a * a)) / (4.0 * M_PI);
  EXPECT_NEAR(total, want, 1e-4 * want);
}

// --eye-paths: the three strategies' weights, each from its own view of the same three
// densities (the others over its own), add to 1; a strategy that cannot make the path (density
// 0) gets 0.
TEST(EyePathShare, WeightsAddToOneForEveryPath) {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> dens = {0.0f, 1e-30f, 1e-6f, 0.5f, 1.0f, 7.0f, 1e6f, 1e30f};
  std::mt19937 gen(11);
  std::uniform_real_distribution<float> logu(-15.0f, 15.0f);
  for (int i = 0; i < 40; ++i) dens.push_back(std::exp(logu(gen)));
  for (float l : dens)
    for (float n : dens)
      for (float h : dens) {
        if (l + n + h == 0.0f) continue;  // no strategy makes the path
        const float wl = mis_power_share(n / l, h / l), wn = mis_power_share(l / n, h / n),
                    wh = mis_power_share(l / h, n / h);
        ASSERT_GE(wl, 0.0f);
        ASSERT_GE(wn, 0.0f);
        ASSERT_GE(wh, 0.0f);
        if (l == 0.0f) {
          ASSERT_EQ(wl, 0.0f) << n << " " << h;
        }
        if (n == 0.0f) {
          ASSERT_EQ(wn, 0.0f) << l << " " << h;
        }
        ASSERT_NEAR(wl + wn + wh, 1.0f, 1e-5f) << l << " " << n << " " << h;
      }
  // The power heuristic: a strategy twice as likely as the other, the third unable.
  EXPECT_NEAR(mis_power_share(0.5f, 0.0f), 0.8f, 1e-6f);
  EXPECT_EQ(mis_power_share(inf, 0.0f), 0.0f);
}

// The light side that light_trace keeps per vertex (eye_path_walk_*) and connect finishes
// (eye_path_weight) gives the same weight as the strategies' densities multiplied out along the
// whole path, vertex by vertex, on random paths with delta vertices, triangle, point, spot and
// directional lights and the environment.
TEST(EyePathShare, KeptRatiosGiveTheWeightOfTheWholePathsDensities) {
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  auto unit = [&] {
    const float z = 2.0f * u(gen) - 1.0f, phi = 6.2831853f * u(gen), r = std::sqrt(1 - z * z);
    return make_float3(r * std::cos(phi), r * std::sin(phi), z);
  };
  const float trace_cdf[2] = {0.25f, 1.0f};
  int checked = 0;
  for (int trial = 0; trial < 400; ++trial) {
    Light l{};
    const u32 types[7] = {PR_LIGHT_TRIANGLE, PR_LIGHT_TRIANGLE,    PR_LIGHT_TRIANGLE,
                          PR_LIGHT_POINT,    PR_LIGHT_DIRECTIONAL, PR_LIGHT_SPOT,
                          PR_LIGHT_ENV};
    l.type = types[trial % 7];
    l.area = 0.1f + u(gen);       // a triangle's
    l.disk_area = 0.1f + u(gen);  // the disk a directional light's or the environment's paths leave
    const u32 li = trial % 2;
    const int tri = l.type == PR_LIGHT_TRIANGLE;
    const int env = l.type == PR_LIGHT_ENV;
    const int sun = l.type == PR_LIGHT_DIRECTIONAL || env;
    // The environment's density of z_0's direction (its map's pdf), 1 for the others.
    const float dirpdf = env ? 0.05f + 2.0f * u(gen) : 1.0f;
    const float3 n_tri = tri ? unit() : make_float3(0.0f, 0.0f, 1.0f);
    const float C = float(1 + trial % 4);
    const float start = eye_paths_start_density(&l, li, trace_cdf, 1.0f);
    const int K = 1 + trial % 5;  // vertices z_1 .. z_K
    std::vector<float3> dir(K + 1), ng(K + 1);
    std::vector<float> t(K + 1), fwd(K + 1), rev(K + 1);
    std::vector<int> delta(K + 1);
    ng[0] = n_tri;
    for (int k = 1; k <= K; ++k) {
      dir[k] = unit();
      ng[k] = unit();
      t[k] = 0.2f + 3.0f * u(gen);
      fwd[k] = 0.05f + u(gen);
      rev[k] = 0.05f + u(gen);
      delta[k] = u(gen) < 0.25f;
    }
    if (l.type == PR_LIGHT_SPOT) {  // its cone holds the first direction
      l.e1x = dir[1].x, l.e1y = dir[1].y, l.e1z = dir[1].z;
      l.cos_outer = 0.5f;
    }
    EyePathWalk w = eye_path_walk_start(&l, li, n_tri, trace_cdf, 1.0f, dirpdf);
    for (int k = 1; k <= K; ++k) {
      const EyePathRatio r = eye_path_walk_arrive(&w, k, dir[k], t[k], ng[k]);
      if (!delta[k]) {
        // Join x_1 to z_k: x_1's pdf towards z_k, the cos and distance there, and z_k's pdf of
        // sampling z_{k-1} arriving from x_1.
        const float pdf_x = 0.05f + u(gen), cos_z = 0.05f + u(gen), d2 = 0.1f + 4.0f * u(gen);
        const float rev_join = 0.05f + u(gen);
        auto area = [](float pdf, float3 n, float3 d, float dist) {
          return pdf * std::fabs(dot(n, d)) / (dist * dist);
        };
        // L: C paths, z_0 by the power table, then each step from the vertex before; a
        // directional light's z_1 from its disk, projected.
        double dl = C * start * dirpdf *
                    (sun ? std::fabs(dot(ng[1], dir[1])) / l.disk_area
                         : light_pdf_emit_dir(&l, n_tri, dir[1]) * std::fabs(dot(ng[1], dir[1])) /
                               (t[1] * t[1]));
        for (int m = 2; m <= k; ++m)
          if (!delta[m - 1]) dl *= area(fwd[m - 1], ng[m], dir[m], t[m]);
        // The eye path: z_k from x_1, then z_{m-1} from z_m for m = k .. 2; N ends by next-event
        // estimation from z_1 (none from a delta z_1), H by z_1's BSDF sample.
        double de = pdf_x * cos_z / d2;
        for (int m = k; m >= 2; --m)
          if (!delta[m]) de *= area(m == k ? rev_join : rev[m], ng[m - 1], dir[m], t[m]);
        // H meets a triangle (per unit area) or the environment (per solid angle), through a
        // delta z_1 too; a point, a spot or a direction never.
        const double dn = delta[1] ? 0.0 : de * start * dirpdf;
        const double rev1 = k == 1 ? rev_join : rev[1];
        const double dh = !(tri || env) ? 0.0
                          : delta[1]    ? de
                          : env         ? de * rev1
                                        : de * area(float(rev1), n_tri, dir[1], t[1]);
        const double expect = 1.0 / (1.0 + (dn / dl) * (dn / dl) + (dh / dl) * (dh / dl));
        const float got = eye_path_weight(r, k, pdf_x, cos_z, d2, rev_join, 1.0f / C, 0.0f);
        EXPECT_NEAR(got, expect, 1e-4 * std::max(1.0, expect)) << "trial " << trial << " k " << k;
        // With strategy T (density dt): T takes its power share of all four, L its own of the
        // rest.
        const double dt = dl * std::exp(6.0 * u(gen) - 3.0);
        const double share_t = dt * dt / (dt * dt + dl * dl + dn * dn + dh * dh);
        const float got_t =
            eye_path_weight(r, k, pdf_x, cos_z, d2, rev_join, 1.0f / C, float(dt / dl));
        EXPECT_NEAR(got_t, expect * (1.0 - share_t), 1e-4) << "trial " << trial << " k " << k;
        ++checked;
      }
      eye_path_walk_leave(&w, k, delta[k], delta[k] ? 0.0f : fwd[k], delta[k] ? 0.0f : rev[k]);
    }
  }
  EXPECT_GT(checked, 500);
}

// Densities for the weights' tests: three in ten a special value (0, tiny, huge, infinite, NaN),
// the others log-uniform between e^-12 and e^12.
class DensityDraw {
 public:
  explicit DensityDraw(unsigned seed) : gen_(seed) {}
  float operator()() {
    static const float inf = std::numeric_limits<float>::infinity();
    static const std::vector<float> special = {0.0f, 1e-30f, 1e-3f, 1.0f,
                                               1e3f, 1e30f,  inf,   std::nanf("")};
    return u_(gen_) < 0.3f ? special[gen_() % special.size()] : std::exp(logu_(gen_));
  }

 private:
  std::mt19937 gen_;
  std::uniform_real_distribution<float> logu_{-12.0f, 12.0f}, u_{0.0f, 1.0f};
};

// Strategy T's share, L's and the eye path's add to 1 for any densities (0, tiny, huge, infinite,
// NaN), and T off (t = 0) leaves L's and the eye path's shares as they were, bit for bit.
TEST(EyePathShare, TheSharesOfTAndLAndTheEyePathAddToOne) {
  const float inf = std::numeric_limits<float>::infinity();
  DensityDraw draw(29);
  for (int trial = 0; trial < 20000; ++trial) {
    const float t = draw(), n = draw(), h = draw();
    const float w_t = eye_paths_camera_share(t, n, h);
    const float w_l = mis_power_share(n, h) * eye_paths_camera_rest(t, n, h);
    const float w_e = eye_paths_eye_share(n, h, t);
    ASSERT_GE(w_t, 0.0f);
    ASSERT_LE(w_t, 1.0f);
    ASSERT_NEAR(double(w_t) + w_l + w_e, 1.0, 1e-5) << t << " " << n << " " << h;
    if (!(t > 0.0f)) {
      ASSERT_EQ(w_t, 0.0f);
      ASSERT_EQ(w_e, 1.0f - mis_power_share(n, h));
    }
    if (t > 0.0f && t < inf && n == n && h == h && n < inf && h < inf) {
      const double a = double(t) * t, den = a + 1.0 + double(n) * n + double(h) * h;
      ASSERT_NEAR(w_t, a / den, 1e-5) << t << " " << n << " " << h;
    }
  }
}

// Where L cannot make a path (under a shutter, a segment of its light path meets what moves), T's
// share and the eye path's add to 1 and are the power heuristic over T, N and H alone; where it
// can, they are the shares with L, bit for bit.
TEST(EyePathShare, WithoutLTheSharesOfTAndTheEyePathAddToOne) {
  const float inf = std::numeric_limits<float>::infinity();
  DensityDraw draw(31);
  for (int trial = 0; trial < 20000; ++trial) {
    const float t = draw(), n = draw(), h = draw();
    ASSERT_EQ(eye_paths_camera_share_l(t, n, h, 1), eye_paths_camera_share(t, n, h));
    ASSERT_EQ(eye_paths_eye_share_l(n, h, t, 1), eye_paths_eye_share(n, h, t));
    const float w_t = eye_paths_camera_share_l(t, n, h, 0);
    const float w_e = eye_paths_eye_share_l(n, h, t, 0);
    ASSERT_GE(w_t, 0.0f);
    ASSERT_LE(w_t, 1.0f);
    ASSERT_NEAR(double(w_t) + w_e, 1.0, 1e-5) << t << " " << n << " " << h;
    if (!(t > 0.0f)) ASSERT_EQ(w_e, 1.0f);
    if (t > 0.0f && t < inf && n == n && h == h && n < inf && h < inf) {
      const double a = double(t) * t, den = a + double(n) * n + double(h) * h;
      if (den > 0.0) ASSERT_NEAR(w_t, a / den, 1e-5) << t << " " << n << " " << h;
    }
  }
}

// The power heuristic over density ratios for any number of strategies: each strategy's weight,
// from its own view of the same densities (the others over its own), adds to 1 over all of
// them, with densities 0, tiny, huge, infinite or NaN (NaN: the strategy is left out, as a
// kernel's 0 / 0 is); mis_power_share is mis_power_share_n for two others.
TEST(PowerShare, WeightsOfAllStrategiesAddToOne) {
  const float inf = std::numeric_limits<float>::infinity();
  DensityDraw draw(23);
  for (int trial = 0; trial < 20000; ++trial) {
    const int n = 2 + trial % 5;
    std::vector<float> d(n);
    for (float& x : d) x = draw();
    int usable = 0, infinite = 0;
    for (float x : d) usable += x > 0.0f, infinite += x == inf;
    if (usable == 0 || infinite > 1) continue;  // no strategy makes the path; inf / inf
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      std::vector<float> r;
      for (int j = 0; j < n; ++j)
        if (j != i) r.push_back(d[j] / d[i]);
      const float w = mis_power_share_n(r.data(), u32(r.size()));
      if (!(d[i] == d[i])) continue;  // a NaN density: the kernels never weigh such a strategy
      ASSERT_GE(w, 0.0f);
      ASSERT_LE(w, 1.0f);
      if (d[i] == 0.0f) {
        ASSERT_EQ(w, 0.0f);
      }
      if (n == 3) {
        ASSERT_EQ(w, mis_power_share(r[0], r[1]));
      }
      sum += w;
    }
    bool has_nan = false;
    for (float x : d) has_nan |= !(x == x);
    if (!has_nan) {
      ASSERT_NEAR(sum, 1.0, 1e-5) << "trial " << trial;
    }
  }
}

// Exact values: the exponent is 2 (1 or 3 would give 2/3 or 8/9 here), the ratio is the other
// strategy's density over this one's, and the two-density form agrees with the ratio form.
TEST(PowerShare, ExactValuesPinTheExponentAndTheOrder) {
  EXPECT_FLOAT_EQ(mis_power_share(0.5f, 0.0f), 0.8f);
  EXPECT_FLOAT_EQ(mis_power_share(2.0f, 0.0f), 0.2f);
  EXPECT_FLOAT_EQ(mis_power_share(1.0f, 2.0f), 1.0f / 6.0f);
  EXPECT_FLOAT_EQ(power_heuristic(1.0f, 2.0f), 0.2f);
  EXPECT_FLOAT_EQ(power_heuristic(2.0f, 1.0f), 0.8f);
  EXPECT_FLOAT_EQ(power_heuristic(3.0f, 0.0f), 1.0f);
  EXPECT_EQ(power_heuristic(0.0f, 0.0f), 0.0f);
  const float r3[3] = {1.0f, 2.0f, 3.0f};
  EXPECT_FLOAT_EQ(mis_power_share_n(r3, 3), 1.0f / 15.0f);
  EXPECT_FLOAT_EQ(mis_connection_weight(PR_STRATEGY_L, 1.0f, 5.0f, 4.0f), 1.0f / 26.0f);
  EXPECT_FLOAT_EQ(mis_balance(1.0f, 1.0f, 3.0f, 1.0f), 0.25f);
  EXPECT_FLOAT_EQ(mis_balance(2.0f, 3.0f, 1.0f, 2.0f), 0.75f);
  EXPECT_FLOAT_EQ(ris_contribution_weight(6.0f, 2.0f, 3.0f), 1.0f);
  EXPECT_FLOAT_EQ(gris_weight(0.5f, 2.0f, 3.0f), 3.0f);
  EXPECT_EQ(gris_weight(0.0f, 2.0f, std::numeric_limits<float>::infinity()), 0.0f);
  for (float a : {1e-3f, 0.3f, 1.0f, 7.0f, 1e4f})
    for (float b : {0.0f, 1e-3f, 0.3f, 1.0f, 7.0f, 1e4f}) {
      EXPECT_NEAR(power_heuristic(a, b), mis_power_share(b / a, 0.0f), 1e-6f) << a << " " << b;
      EXPECT_NEAR(power_heuristic(a, b) + power_heuristic(b, a), 1.0f, 1e-6f);
    }
}

// The running products (MisChain, as light_trace's walk keeps them) and the running ratio
// (mis_ratio_*, as pt_shade's eye_ratio) along random paths of PathVertex records with delta
// vertices equal the per-vertex densities multiplied out directly; a density sampled from a
// delta vertex counts 1. Forward and reverse densities differ, so a swap is caught.
TEST(MisChain, RunningProductsEqualTheVertexDensities) {
  std::mt19937 gen(31);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int trial = 0; trial < 2000; ++trial) {
    const int n = 1 + trial % 8;
    std::vector<PathVertex> v(n);
    for (PathVertex& x : v) {
      x.pdf_fwd = 0.05f + 3.0f * u(gen);
      x.pdf_rev = 0.05f + 3.0f * u(gen);
      x.delta = u(gen) < 0.3f;
    }
    double fwd = 1.0, rev = 1.0;
    for (int i = 0; i < n; ++i) {
      if (i == 0 || !v[i - 1].delta) fwd *= v[i].pdf_fwd;
      if (i + 1 < n && !v[i + 1].delta) rev *= v[i].pdf_rev;
    }
    // As a kernel gathers them: arriving at each vertex, then leaving it for the next.
    MisChain c = mis_chain_start();
    float ratio = 1.0f;
    for (int i = 0; i < n; ++i) {
      const int from_delta = i > 0 && v[i - 1].delta;
      mis_chain_arrive(&c, v[i].pdf_fwd, from_delta);
      ratio = mis_ratio_arrive(ratio, v[i].pdf_fwd, from_delta);
      if (i > 0) {
        mis_chain_leave(&c, v[i - 1].pdf_rev, v[i].delta);
        ratio = mis_ratio_leave(ratio, v[i - 1].pdf_rev, v[i].delta);
      }
    }
    ASSERT_NEAR(c.fwd, fwd, 1e-5 * fwd) << "trial " << trial;
    ASSERT_NEAR(c.rev, rev, 1e-5 * rev) << "trial " << trial;
    ASSERT_NEAR(ratio, rev / fwd, 1e-5 * rev / fwd) << "trial " << trial;
    const MisChain whole = mis_chain_of(v.data(), 0u, u32(n - 1));
    ASSERT_EQ(whole.fwd, c.fwd);
    ASSERT_EQ(whole.rev, c.rev);
  }
}

// The generalized balance heuristic's weights of a sample over all reservoirs add to 1, with
// confidences and targets that are 0, tiny or huge; a reservoir whose target is 0 there gets 0.
TEST(Gris, BalanceWeightsAddToOne) {
  std::mt19937 gen(41);
  std::uniform_real_distribution<float> logu(-15.0f, 15.0f), u(0.0f, 1.0f);
  for (int trial = 0; trial < 20000; ++trial) {
    const int n = 2 + trial % 4;
    std::vector<float> c(n), p(n);
    for (int i = 0; i < n; ++i) {
      c[i] = u(gen) < 0.1f ? 0.0f : std::exp(logu(gen));
      p[i] = u(gen) < 0.2f ? 0.0f : std::exp(logu(gen));
    }
    double sum = 0.0, cp = 0.0;
    for (int i = 0; i < n; ++i) {
      const float m = mis_balance_n(c.data(), p.data(), u32(i), u32(n));
      ASSERT_GE(m, 0.0f);
      if (p[i] == 0.0f) {
        ASSERT_EQ(m, 0.0f);
      }
      sum += m;
      cp += double(c[i]) * p[i];
    }
    if (float(cp) > 0.0f) {
      ASSERT_NEAR(sum, 1.0, 1e-5) << "trial " << trial;
    }
    if (n == 2) {
      const float a = mis_balance(c[0], p[0], c[1], p[1]), b = mis_balance(c[1], p[1], c[0], p[0]);
      ASSERT_EQ(a, mis_balance_n(c.data(), p.data(), 0u, 2u));
      if (float(cp) > 0.0f) {
        ASSERT_NEAR(a + b, 1.0f, 1e-6f);
      }
    }
  }
}

// The connection history's merge (connect.cl, history_resolve) as an estimator: two reservoirs,
// each resampled by RIS from uniform candidates with its own target (the previous frame's and
// this frame's, 0 in places), merged by GRIS with the generalized balance heuristic and this
// frame's target; f(y) W then estimates the sum of f over the domain.
TEST(Gris, MergedReservoirsAreUnbiased) {
  const int N = 8;
  const float p_prev[N] = {1.0f, 0.0f, 2.0f, 0.5f, 3.0f, 0.0f, 1.0f, 0.2f};
  const float p_cur[N] = {0.5f, 1.0f, 2.0f, 0.0f, 1.0f, 4.0f, 0.3f, 0.2f};
  const float f[N] = {0.4f, 1.2f, 2.5f, 0.0f, 0.8f, 3.0f, 0.5f, 0.1f};  // 0 where p_cur is
  double exact = 0.0;
  for (float x : f) exact += x;
  std::mt19937 gen(53);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  // RIS from M uniform candidates (pdf 1 / N): the kept sample and its W.
  auto ris = [&](const float* p, int M, int* y, float* W) {
    float w_sum = 0.0f;
    *y = -1;
    for (int j = 0; j < M; ++j) {
      const int x = int(u(gen) * N) % N;
      const float w = p[x] * N / M;
      if (!(w > 0.0f)) continue;
      w_sum += w;
      if (ris_accept(u(gen), w_sum, w)) *y = x;
    }
    *W = *y >= 0 ? ris_contribution_weight(w_sum, p[*y], 1.0f) : 0.0f;
  };
  const float m_prev = 6.0f, m_cur = 2.0f;
  const int n = 400000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    int y_prev, y_cur;
    float W_prev, W_cur;
    ris(p_prev, int(m_prev), &y_prev, &W_prev);
    ris(p_cur, int(m_cur), &y_cur, &W_cur);
    const float w_prev =
        y_prev < 0 ? 0.0f
                   : gris_weight(mis_balance(m_prev, p_prev[y_prev], m_cur, p_cur[y_prev]),
                                 p_cur[y_prev], W_prev);
    const float w_cur = y_cur < 0
                            ? 0.0f
                            : gris_weight(mis_balance(m_cur, p_cur[y_cur], m_prev, p_prev[y_cur]),
                                          p_cur[y_cur], W_cur);
    const float total = w_prev + w_cur;
    double est = 0.0;
    if (total > 0.0f) {
      const int y = ris_accept(u(gen), total, w_prev) ? y_prev : y_cur;
      est = f[y] * double(ris_contribution_weight(total, p_cur[y], 1.0f));
    }
    sum += est;
    sum2 += est * est;
  }
  const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
  EXPECT_NEAR(mean, exact, 4.5 * se) << "standard error " << se;
}

// Pairwise MIS (path resampling across pixels): for any targets and confidences, the canonical
// weight and the k neighbours' weights at a sample add to 1, zero targets included; a neighbour
// whose target is 0 gets 0; equal targets and confidences give the canonical side more than a
// neighbour (it takes part in every pair).
TEST(Pairwise, WeightsAddToOne) {
  std::mt19937 gen(11);
  std::uniform_real_distribution<float> logu(-10.0f, 10.0f);
  std::uniform_int_distribution<int> zero(0, 3);
  for (int k = 1; k <= 6; ++k) {
    for (int trial = 0; trial < 2000; ++trial) {
      const float kf = float(k);
      const float pc = zero(gen) == 0 ? 0.0f : std::exp(logu(gen));
      const float cc = std::exp(0.2f * logu(gen));
      std::vector<float> pi(k), ci(k);
      float total = cc;
      for (int i = 0; i < k; ++i) {
        pi[i] = zero(gen) == 0 ? 0.0f : std::exp(logu(gen));
        ci[i] = std::exp(0.2f * logu(gen));
        total += ci[i];
      }
      double sum = 0.0, terms = 0.0;
      for (int i = 0; i < k; ++i) {
        const float m = mis_pairwise_neighbor(ci[i], pi[i], cc, pc, kf, total);
        EXPECT_GE(m, 0.0f);
        if (pi[i] == 0.0f) {
          EXPECT_EQ(m, 0.0f);
        }
        sum += m;
        terms += mis_pairwise_canonical_term(ci[i], pi[i], cc, pc, kf, total);
      }
      sum += mis_pairwise_canonical(float(terms), cc, total);
      ASSERT_NEAR(sum, 1.0, 1e-5) << "k " << k << " trial " << trial;
    }
  }
  const float c = mis_pairwise_canonical(3 * mis_pairwise_canonical_term(1, 1, 1, 1, 3, 4), 1, 4);
  EXPECT_NEAR(c, 7.0f / 16.0f, 1e-6f);
  EXPECT_NEAR(mis_pairwise_neighbor(1, 1, 1, 1, 3, 4), 3.0f / 16.0f, 1e-6f);
  // A neighbour standing for 20 samples (the previous frame's reservoir) takes most of a sample
  // both targets agree on.
  EXPECT_GT(mis_pairwise_neighbor(20, 1, 1, 1, 1, 21), 0.85f);
}

// The reconnection shift's Jacobian: x_2 kept, x_1 moved to x_1'. A small patch around x_2 seen
// from x_1 and from x_1' subtends solid angles whose ratio is |J| = g(x_1') / g(x_1), with g =
// |cos at x_2| / d^2 (measured here in double precision from the patch's corners); and the
// shifts there and back multiply to 1.
TEST(Reconnection, JacobianIsTheRatioOfSolidAngles) {
  using V = std::array<double, 3>;
  auto sub = [](V a, V b) { return V{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
  auto dot3 = [](V a, V b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  auto norm = [&](V a) {
    const double l = std::sqrt(dot3(a, a));
    return V{a[0] / l, a[1] / l, a[2] / l};
  };
  auto cross3 = [](V a, V b) {
    return V{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  // The solid angle of the small triangle (a, b, c) seen from o.
  auto solidAngle = [&](V o, V a, V b, V c) {
    const V da = norm(sub(a, o)), db = norm(sub(b, o)), dc = norm(sub(c, o));
    const double num = std::fabs(dot3(da, cross3(db, dc)));
    const double den = 1.0 + dot3(da, db) + dot3(db, dc) + dot3(dc, da);
    return 2.0 * std::atan2(num, den);
  };
  std::mt19937 gen(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const V x2{u(gen), u(gen), u(gen)};
    const V n2 = norm(V{u(gen), u(gen), 2.0 + u(gen)});  // x_2's normal, facing +z roughly
    const V t1 = norm(cross3(n2, V{1, 0, 0})), t2 = cross3(n2, t1);
    const V x1{x2[0] + 2 * u(gen), x2[1] + 2 * u(gen), x2[2] + 1.5 + u(gen)};
    const V x1b{x2[0] + 2 * u(gen), x2[1] + 2 * u(gen), x2[2] + 1.5 + u(gen)};
    if (dot3(sub(x1, x2), n2) <= 0.1 || dot3(sub(x1b, x2), n2) <= 0.1) continue;
    const double e = 1e-4;
    const V a = x2;
    const V b{x2[0] + e * t1[0], x2[1] + e * t1[1], x2[2] + e * t1[2]};
    const V c{x2[0] + e * t2[0], x2[1] + e * t2[1], x2[2] + e * t2[2]};
    const double measured = solidAngle(x1b, a, b, c) / solidAngle(x1, a, b, c);
    auto g = [&](V x) {
      const V d = sub(x, x2);
      const double d2 = dot3(d, d);
      return float(std::fabs(dot3(n2, d)) / std::sqrt(d2) / d2);
    };
    const float jac = reconnection_jacobian(g(x1b), g(x1));
    EXPECT_NEAR(jac, measured, 1e-3 * measured) << "trial " << trial;
    EXPECT_NEAR(jac * reconnection_jacobian(g(x1), g(x1b)), 1.0f, 1e-5f);
  }
  EXPECT_EQ(reconnection_jacobian(1.0f, 0.0f), 0.0f);
}

}  // namespace
}  // namespace pr
