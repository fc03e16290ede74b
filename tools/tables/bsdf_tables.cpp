// Writes kernels/shared/bsdf_tables.h, the directional-albedo tables of the BSDFs' energy
// compensation (host/render/albedo_tables.cpp computes them):
//   build/bsdf_tables > kernels/shared/bsdf_tables.h
// BsdfTables.CommittedHeaderIsWhatTheToolWrites (tests/bsdf_test.cpp) checks the committed copy.
#include <iostream>

#include "render/albedo_tables.h"

int main() {
  std::cout << pr::bsdfTablesHeader(
      pr::computeBsdfTables(pr::kBsdfTableCos, pr::kBsdfTableRoughness, pr::kBsdfTableSamples));
  return 0;
}
