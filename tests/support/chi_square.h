// Pearson's chi-square test of sampled counts against a density, for the sampling tests.
#pragma once

#include <vector>

namespace pr::test {

// Upper tail probability of chi-square with k degrees of freedom (Wilson-Hilferty).
double chiSquareTail(double x, int k);

// The tail probability of `observed` counts against `expected` ones, cell by cell. Cells that
// expect fewer than 5 are pooled into one; where the pool still expects fewer than 5 but holds
// more than 20 samples (draws where the density says there are almost none), 0.
double chiSquarePValue(const std::vector<double>& observed, const std::vector<double>& expected);

}  // namespace pr::test
