// The connection strategies' MIS weights (kernels/shared/connection_mis.h), as the connect
// kernel computes them: they add to 1 for every path, whatever the pdfs (zero, infinite, NaN),
// E and E2 run only at or above the threshold, and above it they are the power heuristic.
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

// Paths without a vertex Z that E2 could sample (q_e = 0): L and E alone.
float weightL(float pl, float pe, float t) {
  return connection_mis_weight(PR_STRATEGY_L, pl, pe, 0.0f, 0.0f, t);
}
float weightE(float pl, float pe, float t) {
  return connection_mis_weight(PR_STRATEGY_E, pl, pe, 0.0f, 0.0f, t);
}

struct Weights {
  float l, e, e2;
};
Weights weights(float pl, float pe, float ql, float qe, float t) {
  return {connection_mis_weight(PR_STRATEGY_L, pl, pe, ql, qe, t),
          connection_mis_weight(PR_STRATEGY_E, pl, pe, ql, qe, t),
          connection_mis_weight(PR_STRATEGY_E2, pl, pe, ql, qe, t)};
}

TEST(ConnectionMis, WeightsAddToOneForEveryPath) {
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> pdfs = {0.0f, 1e-30f, 1e-6f, 0.5f, 1.0f, 3.999f, 4.0f, 7.0f, 1e6f, 1e30f, inf};
  std::mt19937 gen(7);
  std::uniform_real_distribution<float> logu(-20.0f, 20.0f);
  for (int i = 0; i < 30; ++i) pdfs.push_back(std::exp(logu(gen)));
  pdfs.push_back(nan);
  for (float t : {0.0f, 0.5f, 1.0f, 4.0f, 100.0f}) {
    for (float pl : pdfs) {
      for (float pe : pdfs) {
        for (float ql : pdfs) {
          for (float qe : pdfs) {
            const Weights w = weights(pl, pe, ql, qe, t);
            for (float x : {w.l, w.e, w.e2}) {
              ASSERT_GE(x, 0.0f) << pl << " " << pe << " " << ql << " " << qe << " " << t;
              ASSERT_LE(x, 1.0f) << pl << " " << pe << " " << ql << " " << qe << " " << t;
            }
            ASSERT_NEAR(w.l + w.e + w.e2, 1.0f, 3e-7f)
                << pl << " " << pe << " " << ql << " " << qe << " " << t;
          }
        }
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

TEST(ConnectionMis, StrategyE2OnlyWhereItsRatiosReachTheThreshold) {
  // Z far from Y (q_e small against q_l): E2 stays out, and L and E keep their two-way weights.
  Weights w = weights(1.0f, 8.0f, 1.0f, 3.9f, 4.0f);
  EXPECT_EQ(w.e2, 0.0f);
  EXPECT_FLOAT_EQ(w.e, 64.0f / 65.0f);
  // E2 against E at the threshold but not against L (r1 r2 = 0.5 * 4 < 4): out.
  EXPECT_EQ(weights(1.0f, 0.5f, 1.0f, 4.0f, 4.0f).e2, 0.0f);
  // A corner: Y close to x and Z close to Y. E2 takes the largest share, by the power heuristic
  // over the three path pdfs p_l q_l, p_e q_l and p_e q_e.
  w = weights(400.0f, 1800.0f, 1.0f, 1000.0f, 4.0f);
  const double pL = 400.0, pE = 1800.0, pE2 = 1800.0 * 1000.0;
  const double sum2 = pL * pL + pE * pE + pE2 * pE2;
  EXPECT_NEAR(w.l, pL * pL / sum2, 1e-6);
  EXPECT_NEAR(w.e, pE * pE / sum2, 1e-6);
  EXPECT_NEAR(w.e2, pE2 * pE2 / sum2, 1e-6);
  EXPECT_GT(w.e2, 0.999f);
  // E2 alone where neither L nor E can make the path (q_l = 0 < q_e), and out where it cannot
  // (q_e = 0).
  EXPECT_EQ(weights(1.0f, 8.0f, 0.0f, 2.0f, 4.0f).e2, 1.0f);
  EXPECT_EQ(weights(1.0f, 8.0f, 0.0f, 0.0f, 4.0f).e2, 0.0f);
  EXPECT_EQ(weights(1.0f, 8.0f, 2.0f, 0.0f, 4.0f).e2, 0.0f);
  // MIS off: L alone.
  EXPECT_EQ(weights(1.0f, 8.0f, 1.0f, 1e6f, 0.0f).l, 1.0f);
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

TEST(ConnectionMis, ThreeStrategiesKeepAnEstimatorUnbiased) {
  // Paths (y, z) in (0, 1]^2 with f = (y^2 + 0.1)(z + 0.2). L samples both uniformly (p = 1, 1),
  // E samples y with pdf 2y and z uniformly, E2 samples y with 2y and z with 3z^2; in the weights
  // p_l = q_l = 1, p_e = 2y, q_e = 3z^2. Each strategy's weighted estimate, summed, integrates f.
  const float t = 1.5f;
  const double exact = (1.0 / 3.0 + 0.1) * (0.5 + 0.2);
  std::mt19937 gen(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto f = [](double y, double z) { return (y * y + 0.1) * (z + 0.2); };
  const auto w = [t](u32 s, double y, double z) {
    return double(connection_mis_weight(s, 1.0f, float(2.0 * y), 1.0f, float(3.0 * z * z), t));
  };
  const int n = 400000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double yl = 1.0 - u(gen), zl = 1.0 - u(gen);
    const double ye = std::sqrt(1.0 - u(gen)), ze = 1.0 - u(gen);
    const double y2 = std::sqrt(1.0 - u(gen)), z2 = std::cbrt(1.0 - u(gen));
    const double est = w(PR_STRATEGY_L, yl, zl) * f(yl, zl) +
                       w(PR_STRATEGY_E, ye, ze) * f(ye, ze) / (2.0 * ye) +
                       w(PR_STRATEGY_E2, y2, z2) * f(y2, z2) / (2.0 * y2 * 3.0 * z2 * z2);
    sum += est;
    sum2 += est * est;
  }
  const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
  EXPECT_NEAR(mean, exact, 4.5 * se) << "standard error " << se;
  // Each strategy takes the whole path somewhere in the square, and shares it elsewhere.
  EXPECT_EQ(w(PR_STRATEGY_L, 0.1, 0.9), 1.0);
  EXPECT_GT(w(PR_STRATEGY_E, 0.9, 0.1), 0.5);
  EXPECT_GT(w(PR_STRATEGY_E2, 0.9, 0.9), 0.5);
  EXPECT_GT(w(PR_STRATEGY_E, 0.9, 0.9), 0.0);
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

}  // namespace
}  // namespace pr
