// The kernel tables (kernels/shared/kernel_args.h) against built kernels: a kernel that
// differs from its table in count, name, type, address space or constness is refused with one
// line naming the kernel and the argument.
#include <gtest/gtest.h>

#include <cstdlib>
#include <map>
#include <set>
#include <string>

#include "cl/kernel_binding.h"
#include "shared/layout.h"
#include "support/test_env.h"
#include "util/error.h"

namespace pr {
namespace {

using kargs::ArgSpec;
using kargs::Kind;

// Builds from source while alive: a cached binary may carry no argument info (Intel's).
class NoProgramCache {
 public:
  NoProgramCache() {
    const char* saved = std::getenv("PATHREUSE_CACHE_DIR");
    had_ = saved != nullptr;
    if (had_) saved_ = saved;
    ::setenv("PATHREUSE_CACHE_DIR", "off", 1);
  }
  ~NoProgramCache() {
    if (had_)
      ::setenv("PATHREUSE_CACHE_DIR", saved_.c_str(), 1);
    else
      ::unsetenv("PATHREUSE_CACHE_DIR");
  }

 private:
  bool had_ = false;
  std::string saved_;
};

cl::Kernel buildProbe(const std::string& params) {
  Context& ctx = test::testContext();
  NoProgramCache fresh;
  const std::string source = "__kernel void probe(" + params + ") {}\n";
  ProgramBuild b = ctx.buildProgramFromSource(source, "", "probe.cl");
  cl_int err = CL_SUCCESS;
  cl::Kernel k(b.program, "probe", &err);
  CL_CHECK(err);
  return k;
}

const ArgSpec kProbe[] = {
    {kargs::kFrame, Kind::In, "float*", "in"},
    {kargs::kFrame, Kind::Out, "float4*", "out"},
    {kargs::kPass, Kind::Val, "uint", "a"},
    {kargs::kPass, Kind::Val, "uint", "b"},
};

std::string refusal(const std::string& params) {
  try {
    kargs::checkKernelArgs(buildProbe(params), "probe", kProbe, 4);
  } catch (const RuntimeError& e) {
    return e.what();
  }
  return "";
}

TEST(KernelArgs, AKernelThatMatchesItsTableIsAccepted) {
  EXPECT_EQ(refusal("__global const float* in, __global float4* out, uint a, uint b"), "");
}

TEST(KernelArgs, EachDifferenceIsRefusedNamingKernelAndArgument) {
  EXPECT_EQ(refusal("__global const float* in, __global float4* out, uint a"),
            "kernel probe takes 3 arguments, its table in kernels/shared/kernel_args.h lists 4");
  // Two swapped uints: the mistake that positional binding let through.
  EXPECT_EQ(refusal("__global const float* in, __global float4* out, uint b, uint a"),
            "kernel probe: argument 2 (a) is named b in the kernel (kernels/shared/kernel_args.h)");
  EXPECT_EQ(refusal("__global const float* in, __global float4* out, float a, uint b"),
            "kernel probe: argument 2 (a) has type float in the kernel, uint in the table "
            "(kernels/shared/kernel_args.h)");
  EXPECT_EQ(refusal("__global float* in, __global float4* out, uint a, uint b"),
            "kernel probe: argument 0 (in) is not const in the kernel (the table says IN) "
            "(kernels/shared/kernel_args.h)");
  EXPECT_EQ(refusal("__global const float* in, __global const float4* out, uint a, uint b"),
            "kernel probe: argument 1 (out) is const in the kernel (the table says OUT) "
            "(kernels/shared/kernel_args.h)");
  EXPECT_EQ(refusal("__global const float* in, __local float4* out, uint a, uint b"),
            "kernel probe: argument 1 (out) is not a __global buffer in the kernel "
            "(kernels/shared/kernel_args.h)");
}

TEST(KernelArgs, TheFilmKernelMatchesItsTableBuiltAndFromTheCache) {
  Context& ctx = test::testContext();
  {
    // Built from source: the argument info is there, and each name was compared.
    NoProgramCache fresh;
    cl::Kernel k;
    EXPECT_NO_THROW(k = kargs::kernel<kargs::AccumulateArgs>(ctx, "accumulate.cl"));
    std::string name;
    EXPECT_EQ(k.getArgInfo(0, CL_KERNEL_ARG_NAME, &name), CL_SUCCESS);
  }
  // From the cache, some platforms (Intel's) keep no argument info: the count is still checked,
  // and the names were when that binary was built.
  for (int i = 0; i < 2; ++i)
    EXPECT_NO_THROW(kargs::kernel<kargs::AccumulateArgs>(ctx, "accumulate.cl"));
}

TEST(KernelArgs, TheSceneComesFirstInEveryTableThatTakesIt) {
  // GpuScene's arguments are copied by name, but kernels build SceneData from the same
  // parameter names: each table that names one scene argument names all, in the scene's order.
  for (const kargs::TableEntry& t : kargs::kTables) {
    if (t.specs[0].role != kargs::kScene) continue;
    ASSERT_GE(t.count, kargs::SceneArgs::kCount) << t.kernel;
    for (size_t i = 0; i < kargs::SceneArgs::kCount; ++i)
      EXPECT_STREQ(t.specs[i].name, kargs::SceneArgs::kSpecs[i].name) << t.kernel;
    for (size_t i = kargs::SceneArgs::kCount; i < t.count; ++i)
      EXPECT_NE(t.specs[i].role, kargs::kScene) << t.kernel << " " << t.specs[i].name;
  }
}

TEST(KernelArgs, EveryStructATableNamesIsInTheLayoutTest) {
  std::set<std::string> shared;
#define PR_NAME_OF(T) shared.insert(#T);
  PR_SHARED_STRUCTS(PR_NAME_OF)
#undef PR_NAME_OF
  const std::set<std::string> builtin = {"uint", "float", "float4"};
  size_t structs = 0;
  for (const kargs::TableEntry& t : kargs::kTables) {
    for (size_t i = 0; i < t.count; ++i) {
      std::string type = t.specs[i].type;
      if (!type.empty() && type.back() == '*') type.pop_back();
      if (builtin.count(type)) continue;
      ++structs;
      EXPECT_TRUE(shared.count(type)) << t.kernel << "." << t.specs[i].name << ": " << type
                                      << " is missing from kernels/shared/layout.h";
    }
  }
  EXPECT_GT(structs, 10u);
}

// Every kernel's parameters fit in 1024 bytes, the least CL_DEVICE_MAX_PARAMETER_SIZE a device
// may report (OpenCL 1.2, 4.2), pointers counted as 8 bytes: a table that grew past it would
// build here and fail to launch on some device.
TEST(KernelArgs, EveryKernelsParametersFitTheLeastADeviceTakes) {
  std::map<std::string, size_t> bytesOf = {{"uint", 4}, {"float", 4}, {"float4", 16}};
#define PR_SIZE_OF(T) bytesOf[#T] = sizeof(dev::T);
  PR_SHARED_STRUCTS(PR_SIZE_OF)
#undef PR_SIZE_OF
  for (const kargs::TableEntry& t : kargs::kTables) {
    size_t bytes = 0;
    for (size_t i = 0; i < t.count; ++i) {
      const std::string type = t.specs[i].type;
      ASSERT_TRUE(type.back() == '*' || bytesOf.count(type)) << t.kernel << ": " << type;
      bytes += type.back() == '*' ? 8 : bytesOf.at(type);
    }
    EXPECT_LE(bytes, 1024u) << t.kernel;
    EXPECT_GT(bytes, 0u) << t.kernel;
  }
}

}  // namespace
}  // namespace pr
