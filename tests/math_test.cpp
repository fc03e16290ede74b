// shared/math.h compiled as C++ (the CPU reference) and as OpenCL C agree.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "shared/math.h"
#include "support/test_env.h"

namespace pr {
namespace {

using namespace pr::dev;

TEST(SharedMath, OrthonormalBasis) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    const float3 n = normalize(make_float3(u(rng), u(rng), u(rng)));
    float3 t, b;
    orthonormal_basis(n, &t, &b);
    EXPECT_NEAR(dot(t, n), 0.0f, 1e-5f);
    EXPECT_NEAR(dot(b, n), 0.0f, 1e-5f);
    EXPECT_NEAR(dot(t, b), 0.0f, 1e-5f);
    EXPECT_NEAR(length(t), 1.0f, 1e-5f);
    // Right-handed: t x b = n.
    EXPECT_NEAR(dot(cross(t, b), n), 1.0f, 1e-5f);
  }
}

TEST(SharedMath, DeviceMatchesHost) {
  const uint32_t n = 257;
  std::vector<float> in(3 * n);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-10.0f, 10.0f);
  for (auto& v : in) v = u(rng);
  Context& ctx = test::testContext();
  auto build = ctx.buildProgram("test/math_check.cl");
  cl_int err = CL_SUCCESS;
  cl::Kernel k(build.program, "math_check", &err);
  CL_CHECK(err);
  cl::Buffer bin = ctx.allocate("in", in.size() * 4), bout = ctx.allocate("out", n * 16);
  CL_CHECK(ctx.queue().enqueueWriteBuffer(bin, CL_TRUE, 0, in.size() * 4, in.data()));
  CL_CHECK(k.setArg(0, bin));
  CL_CHECK(k.setArg(1, bout));
  CL_CHECK(k.setArg(2, n));
  ctx.launch1D(k, n, "math_check");
  std::vector<float> out(4 * n);
  CL_CHECK(ctx.queue().enqueueReadBuffer(bout, CL_TRUE, 0, out.size() * 4, out.data()));
  for (uint32_t i = 0; i < n; ++i) {
    const float3 v = normalize(pr_load3(&in[3 * i]));
    EXPECT_NEAR(out[4 * i + 0], v.x, 1e-6f);
    EXPECT_NEAR(out[4 * i + 1], v.y, 1e-6f);
    EXPECT_NEAR(out[4 * i + 2], v.z, 1e-6f);
    EXPECT_NEAR(out[4 * i + 3], max3(fabs(v)), 1e-6f);
  }
}

}  // namespace
}  // namespace pr
