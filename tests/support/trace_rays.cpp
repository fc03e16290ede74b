#include "support/trace_rays.h"

#include <map>
#include <string>

#include "cl/cl_check.h"
#include "support/test_env.h"

namespace pr::test {

TracedRays traceRays(accel::DeviceAccel& acc, const std::vector<dev::Ray>& rays, cl_uint mode) {
  Context& ctx = testContext();
  static std::map<int, cl::Program> programs;  // one build per width
  const int width = acc.width();
  if (!programs.count(width))
    programs[width] =
        ctx.buildProgram("test/trace.cl", "-DPR_BVH_WIDTH=" + std::to_string(width)).program;
  cl_int err = CL_SUCCESS;
  cl::Kernel k(programs[width], "trace_rays", &err);
  CL_CHECK(err);
  const cl_uint n = cl_uint(rays.size());
  cl::Buffer rb = ctx.allocate("rays", n * sizeof(dev::Ray));
  cl::Buffer hb = ctx.allocate("hits", n * sizeof(dev::Hit));
  cl::Buffer ob = ctx.allocate("occluded", n * sizeof(cl_uint));
  CL_CHECK(ctx.queue().enqueueWriteBuffer(rb, CL_TRUE, 0, n * sizeof(dev::Ray), rays.data()));
  CL_CHECK(k.setArg(0, rb));
  CL_CHECK(k.setArg(1, hb));
  CL_CHECK(k.setArg(2, ob));
  CL_CHECK(k.setArg(3, n));
  CL_CHECK(k.setArg(4, mode));
  acc.setKernelArgs(ctx, k, 5);
  ctx.launch1D(k, n, "trace_rays");
  TracedRays out;
  out.hits.resize(n);
  out.occluded.resize(n);
  CL_CHECK(ctx.queue().enqueueReadBuffer(hb, CL_TRUE, 0, n * sizeof(dev::Hit), out.hits.data()));
  CL_CHECK(ctx.queue().enqueueReadBuffer(ob, CL_TRUE, 0, n * sizeof(cl_uint), out.occluded.data()));
  ctx.release("rays", n * sizeof(dev::Ray));
  ctx.release("hits", n * sizeof(dev::Hit));
  ctx.release("occluded", n * sizeof(cl_uint));
  return out;
}

}  // namespace pr::test
