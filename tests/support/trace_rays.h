// Rays traced on the test device by kernels/test/trace.cl, against BVHs uploaded by a
// DeviceAccel (in its width), for comparison with the CPU reference and brute force.
#pragma once

#include <vector>

#include "accel/device_accel.h"
#include "cl/cl.h"
#include "shared/types.h"

namespace pr::test {

struct TracedRays {
  std::vector<dev::Hit> hits;     // closest hits
  std::vector<cl_uint> occluded;  // any-hit answers
};

// mode 0: whole scene, 1: SSG only, 2: DSG only.
TracedRays traceRays(accel::DeviceAccel& acc, const std::vector<dev::Ray>& rays, cl_uint mode);

}  // namespace pr::test
