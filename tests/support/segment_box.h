// The kernels' slab test of a segment (o + t d, 0 <= t <= 1) against a box b (lo xyz, hi xyz),
// as kernels/shared/transport.h's ray_meets_box makes it, for host tests of box records.
#pragma once

#include <algorithm>
#include <cmath>

namespace pr::test {

inline bool segmentMeetsBox(const float* b, const float o[3], const float d[3]) {
  float t0 = 0.0f, t1 = 1.0f;
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(d[a]) < 1e-30f) {
      if (o[a] < b[a] || o[a] > b[3 + a]) return false;
      continue;
    }
    const float ta = (b[a] - o[a]) / d[a], tb = (b[3 + a] - o[a]) / d[a];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace pr::test
