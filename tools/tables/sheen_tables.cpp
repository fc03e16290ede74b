// Writes kernels/shared/sheen_tables.h, the energy model's sheen (host/render/sheen_volume.cpp
// computes it; a few minutes on two cores):
//   build/sheen_tables > kernels/shared/sheen_tables.h
// SheenTables.CommittedHeaderIsWhatTheToolWrites (tests/bsdf_test.cpp) checks the committed copy.
#include <iostream>

#include "render/sheen_volume.h"

int main() {
  std::cout << pr::sheenTablesHeader(
      pr::computeSheenTables(pr::kSheenTableCos, pr::kSheenTableRoughness, pr::kSheenWalks));
  return 0;
}
