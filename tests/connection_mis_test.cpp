// The connection strategies' MIS weights (kernels/shared/connection_mis.h), as the connect
// kernel computes them: they add to 1 for every path, whatever the pdfs (zero, infinite, NaN),
// E runs only at or above the threshold, and above it they are the power heuristic.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "shared/connection_mis.h"
#include "shared/sampling.h"

namespace pr {
namespace {

using namespace dev;

float weightL(float pl, float pe, float t) {
  return connection_mis_weight(PR_STRATEGY_L, pl, pe, t);
}
float weightE(float pl, float pe, float t) {
  return connection_mis_weight(PR_STRATEGY_E, pl, pe, t);
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
        const float wl = eye_path_share(n / l, h / l), wn = eye_path_share(l / n, h / n),
                    wh = eye_path_share(l / h, n / h);
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
  EXPECT_NEAR(eye_path_share(0.5f, 0.0f), 0.8f, 1e-6f);
  EXPECT_EQ(eye_path_share(inf, 0.0f), 0.0f);
}

}  // namespace
}  // namespace pr
