// Test kernel: exercises shared/math.h on the device so that it is compiled as OpenCL C.
// Reads in[3*i..3*i+2]; writes out[4*i..4*i+3] = normalized vector and its max component.
#include "shared/math.h"

PR_KERNEL void math_check(__global const float* in, __global float* out, uint n) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  const float3 v = normalize(pr_load3(in + 3 * i));
  out[4 * i + 0] = v.x;
  out[4 * i + 1] = v.y;
  out[4 * i + 2] = v.z;
  out[4 * i + 3] = max3(fabs(v));
}
