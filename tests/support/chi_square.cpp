#include "support/chi_square.h"

#include <cmath>

namespace pr::test {

double chiSquareTail(double x, int k) {
  const double z = (std::cbrt(x / k) - (1.0 - 2.0 / (9.0 * k))) / std::sqrt(2.0 / (9.0 * k));
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

double chiSquarePValue(const std::vector<double>& observed, const std::vector<double>& expected) {
  double chi = 0.0, poolObserved = 0.0, poolExpected = 0.0;
  int dof = -1;
  for (size_t c = 0; c < expected.size(); ++c) {
    if (expected[c] < 5.0) {
      poolObserved += observed[c], poolExpected += expected[c];
      continue;
    }
    chi += (observed[c] - expected[c]) * (observed[c] - expected[c]) / expected[c];
    ++dof;
  }
  if (poolExpected >= 5.0) {
    chi += (poolObserved - poolExpected) * (poolObserved - poolExpected) / poolExpected;
    ++dof;
  } else if (poolObserved > 20.0) {
    return 0.0;
  }
  return dof > 0 ? chiSquareTail(chi, dof) : 1.0;
}

}  // namespace pr::test
