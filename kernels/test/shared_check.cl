// Test kernel shared_check: runs the shared helpers that the rendering kernels build on, one
// random case per work-item, so that the host can compare every lane with the same helpers
// compiled as C++ (test/shared_check.h is compiled for both). Each helper is
// called from two sites, as in the rendering kernels, which is what once made a compiler keep
// them out of line. Reads the light power table and a light BVH; writes PR_CHECK_STRIDE floats per
// work-item.
#include "test/shared_check.h"

PR_KERNEL void shared_check(__global float* out, uint n, __global const float* cdf, uint cdf_count,
                            __global const LightNode* nodes, uint node_count) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  float r[PR_CHECK_STRIDE];
  shared_check_case(i, cdf, cdf_count, nodes, node_count, r);
  for (uint k = 0u; k < PR_CHECK_STRIDE; ++k) out[(size_t)i * PR_CHECK_STRIDE + k] = r[k];
}
