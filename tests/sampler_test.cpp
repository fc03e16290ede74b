// Low-discrepancy samples of camera streams (kernels/shared/rng.h): the Sobol points
// themselves, the (0, k, 2)-net property of every pair of dimensions over a pixel's first 2^k
// samples after scrambling, and independence between pairs and between pixels.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "shared/rng.h"

namespace pr {
namespace {

using namespace dev;

TEST(Sobol, FirstPointsOfBothDimensions) {
  const double want0[] = {0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875};
  const double want1[] = {0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875};  // natural order
  for (uint32_t i = 0; i < 8; ++i) {
    EXPECT_EQ(pr_sobol0(i) / 4294967296.0, want0[i]) << i;
    EXPECT_EQ(pr_sobol1(i) / 4294967296.0, want1[i]) << i;
  }
}

TEST(Sobol, OwenScramblingIsABijectionThatKeepsPrefixes) {
  // Bit b of the result depends only on bits 0..b of the input (in Sobol's bit order), so the
  // 2^k values whose top k bits are all different keep all different top k bits.
  std::vector<bool> seen(1 << 12, false);
  for (uint32_t x = 0; x < (1u << 12); ++x) {
    const uint32_t y = pr_owen_scramble(x << 20, 0x1234567u) >> 20;
    EXPECT_FALSE(seen[y]) << x;
    seen[y] = true;
  }
}

// Every elementary interval of area 2^-k holds exactly one of the first 2^k points.
bool isNet(const std::vector<float2>& pts, int k) {
  for (int a = 0; a <= k; ++a) {
    const int nx = 1 << a, ny = 1 << (k - a);
    std::vector<int> count(size_t(nx) * ny, 0);
    for (const auto& p : pts) ++count[size_t(int(p.y * ny)) * nx + int(p.x * nx)];
    for (int c : count)
      if (c != 1) return false;
  }
  return true;
}

TEST(Sobol, EveryPairOfEveryPixelIsANet) {
  for (uint32_t pixel : {0u, 1u, 77u, 123456u}) {
    for (uint32_t pair : {0u, 1u, 5u, PR_SOBOL_DIMS / 2 - 1}) {
      for (int k = 1; k <= 8; ++k) {
        std::vector<float2> pts;
        for (uint32_t i = 0; i < (1u << k); ++i) {
          Rng r = rng_make(3, PR_RNG_TEST_SOBOL, 9, pixel, i);
          rng_skip(&r, pair);
          pts.push_back(rng_next2(&r));
        }
        EXPECT_TRUE(isNet(pts, k)) << "pixel " << pixel << " pair " << pair << " 2^" << k;
      }
    }
  }
  // Hashed streams are not nets (the test can tell).
  std::vector<float2> pts;
  for (uint32_t i = 0; i < 64; ++i) {
    Rng r = rng_make(3, PR_RNG_TEST, 9, 0, i);
    pts.push_back(rng_next2(&r));
  }
  EXPECT_FALSE(isNet(pts, 6));
}

// Pairs of one sample, and the same pair of neighbouring pixels, are uncorrelated.
TEST(Sobol, PairsAndPixelsAreIndependent) {
  const int n = 20000;
  double sxy = 0, sxz = 0;
  for (int p = 0; p < n; ++p) {
    Rng r = rng_make(3, PR_RNG_TEST_SOBOL, 0, uint32_t(p), 5);
    const float x = rng_next(&r), y = rng_next(&r);
    Rng q = rng_make(3, PR_RNG_TEST_SOBOL, 0, uint32_t(p + 1), 5);
    const float z = rng_next(&q);
    sxy += (x - 0.5) * (y - 0.5);
    sxz += (x - 0.5) * (z - 0.5);
  }
  // Correlation coefficient within 4 standard errors of 0 (variance of u is 1/12).
  const double bound = 4.0 / std::sqrt(double(n));
  EXPECT_LT(std::fabs(sxy / n * 12.0), bound);
  EXPECT_LT(std::fabs(sxz / n * 12.0), bound);
}

}  // namespace
}  // namespace pr
