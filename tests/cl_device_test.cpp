// The OpenCL device layer: enumeration, --device parsing, program builds, the binary cache,
// errors with symbolic names, and the host/device layout agreement of shared structs.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

#include "cl/binary_cache.h"
#include "cl/context.h"
#include "cl/device.h"
#include "cl/kernel_sources.h"
#include "shared/layout.h"
#include "shared/types.h"
#include "support/test_env.h"
#include "util/hash.h"

namespace pr {
namespace {

namespace fs = std::filesystem;

DeviceEntry fakeDevice(int index, int p, int d, const std::string& name, cl_device_type type) {
  DeviceEntry e;
  e.index = index;
  e.platformIndex = p;
  e.deviceIndex = d;
  e.name = name;
  e.type = type;
  return e;
}

std::vector<DeviceEntry> fakeList() {
  return {fakeDevice(0, 0, 0, "pthread-skylake", CL_DEVICE_TYPE_CPU),
          fakeDevice(1, 1, 0, "NVIDIA H100 PCIe", CL_DEVICE_TYPE_GPU),
          fakeDevice(2, 1, 1, "NVIDIA RTX 4090", CL_DEVICE_TYPE_GPU)};
}

TEST(DeviceSpec, DefaultPrefersFirstGpu) {
  const auto list = fakeList();
  EXPECT_EQ(selectDevice(list, "").index, 1);
  std::vector<DeviceEntry> cpuOnly = {list[0]};
  EXPECT_EQ(selectDevice(cpuOnly, "").index, 0);
}

TEST(DeviceSpec, IndexPlatformDeviceTypeAndName) {
  const auto list = fakeList();
  EXPECT_EQ(selectDevice(list, "2").index, 2);
  EXPECT_EQ(selectDevice(list, "1:1").index, 2);
  EXPECT_EQ(selectDevice(list, "0:0").index, 0);
  EXPECT_EQ(selectDevice(list, "cpu").index, 0);
  EXPECT_EQ(selectDevice(list, "GPU").index, 1);
  EXPECT_EQ(selectDevice(list, "rtx").index, 2);
  EXPECT_EQ(selectDevice(list, "h100").index, 1);
}

TEST(DeviceSpec, PlatformNameOrVendorWhenNoDeviceNameMatches) {
  auto list = fakeList();
  list[0].platformName = "Portable Computing Language";
  list[0].platformVendor = "The pocl project";
  list[1].platformName = list[2].platformName = "NVIDIA CUDA";
  list[1].platformVendor = list[2].platformVendor = "NVIDIA Corporation";
  list.push_back(fakeDevice(3, 2, 0, "Intel(R) Xeon(R) Gold", CL_DEVICE_TYPE_CPU));
  list[3].platformName = "Intel(R) OpenCL";
  list[3].platformVendor = "Intel(R) Corporation";
  list[0].name = "pthread-skylake-Intel(R) Xeon(R) Gold";
  EXPECT_EQ(selectDevice(list, "pocl").index, 0);
  EXPECT_EQ(selectDevice(list, "nvidia").index, 1);
  EXPECT_EQ(selectDevice(list, "Intel(R) OpenCL").index, 3);
  // A device name match comes first: PoCL's device carries the CPU's name.
  EXPECT_EQ(selectDevice(list, "xeon").index, 0);
}

TEST(DeviceSpec, RefusesWhatMatchesNothing) {
  const auto list = fakeList();
  EXPECT_THROW(selectDevice(list, "99"), InputError);
  EXPECT_THROW(selectDevice(list, "0:5"), InputError);
  EXPECT_THROW(selectDevice(list, "3:0"), InputError);
  EXPECT_THROW(selectDevice(list, "radeon"), InputError);
  std::vector<DeviceEntry> cpuOnly = {list[0]};
  EXPECT_THROW(selectDevice(cpuOnly, "gpu"), InputError);
  try {
    selectDevice(list, "99");
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--device 99"), std::string::npos) << e.what();
  }
}

TEST(DeviceSpec, NoDeviceAtAll) {
  std::vector<DeviceEntry> none;
  EXPECT_THROW(selectDevice(none, ""), NoDeviceError);
  try {
    selectDevice(none, "");
  } catch (const NoDeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("pocl-opencl-icd"), std::string::npos);
  }
}

TEST(ClError, CarriesSymbolicNameFileAndLine) {
  EXPECT_EQ(clErrorName(-5), "CL_OUT_OF_RESOURCES");
  EXPECT_EQ(clErrorName(-54), "CL_INVALID_WORK_GROUP_SIZE");
  EXPECT_EQ(clErrorName(-12345), "CL_ERROR(-12345)");
  try {
    CL_CHECK(CL_OUT_OF_RESOURCES);
    FAIL() << "CL_CHECK did not throw";
  } catch (const ClError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.code(), CL_OUT_OF_RESOURCES);
    EXPECT_NE(what.find("CL_OUT_OF_RESOURCES"), std::string::npos) << what;
    EXPECT_NE(what.find("cl_device_test.cpp:"), std::string::npos) << what;
  }
  EXPECT_NO_THROW(CL_CHECK(CL_SUCCESS));
}

TEST(Devices, EnumerationFindsACpuDevice) {
  const auto devices = enumerateDevices();
  ASSERT_FALSE(devices.empty()) << "no OpenCL device: is pocl-opencl-icd installed?";
  bool cpu = false;
  for (const auto& d : devices) {
    EXPECT_FALSE(d.name.empty());
    EXPECT_GT(d.computeUnits, 0u);
    EXPECT_GT(d.globalMemBytes, 0u);
    EXPECT_GT(d.maxAllocBytes, 0u);
    EXPECT_NE(d.openclCVersion.find("OpenCL C"), std::string::npos) << d.openclCVersion;
    cpu = cpu || (d.type & CL_DEVICE_TYPE_CPU);
  }
  EXPECT_TRUE(cpu) << "expected PoCL's CPU device";
}

TEST(KernelSources, EmbeddedAndExpanded) {
  const std::string src = expandKernelSource("test/layout.cl");
  // Both headers are inlined, once each, with #line markers naming them.
  EXPECT_NE(src.find("#line 1 \"shared/types.h\""), std::string::npos);
  EXPECT_NE(src.find("#line 1 \"shared/common.h\""), std::string::npos);
  EXPECT_EQ(src.find("#include \""), std::string::npos);
  EXPECT_THROW(readKernelFile("no/such/file.cl"), RuntimeError);
}

class ProgramTest : public ::testing::Test {
 protected:
  void SetUp() override {
    cacheDir_ = test::tempDir("cache");
    setenv("PATHREUSE_CACHE_DIR", cacheDir_.c_str(), 1);
  }
  void TearDown() override { unsetenv("PATHREUSE_CACHE_DIR"); }
  std::string cacheDir_;
};

TEST_F(ProgramTest, SmallKernelComputesExpectedNumbers) {
  Context& ctx = test::testContext();
  ProgramBuild b = ctx.buildProgram("test/smoke.cl");
  cl_int err = CL_SUCCESS;
  cl::Kernel k(b.program, "saxpy", &err);
  CL_CHECK(err);
  const cl_uint n = 1000;
  std::vector<float> x(n), y(n);
  for (cl_uint i = 0; i < n; ++i) {
    x[i] = float(i);
    y[i] = 1.0f - float(i) * 0.5f;
  }
  cl::Buffer bx = ctx.allocate("x", n * sizeof(float));
  cl::Buffer by = ctx.allocate("y", n * sizeof(float));
  CL_CHECK(ctx.queue().enqueueWriteBuffer(bx, CL_TRUE, 0, n * sizeof(float), x.data()));
  CL_CHECK(ctx.queue().enqueueWriteBuffer(by, CL_TRUE, 0, n * sizeof(float), y.data()));
  CL_CHECK(k.setArg(0, 3.0f));
  CL_CHECK(k.setArg(1, bx));
  CL_CHECK(k.setArg(2, by));
  CL_CHECK(k.setArg(3, n));
  ctx.launch1D(k, n, "saxpy");
  std::vector<float> out(n);
  CL_CHECK(ctx.queue().enqueueReadBuffer(by, CL_TRUE, 0, n * sizeof(float), out.data()));
  for (cl_uint i = 0; i < n; ++i) ASSERT_FLOAT_EQ(out[i], 3.0f * x[i] + y[i]) << "i=" << i;
}

TEST_F(ProgramTest, SyntaxErrorThrowsWithBuildLog) {
  Context& ctx = test::testContext();
  const std::string bad = "__kernel void broken(__global float* x) { x[0] = undeclared_thing; }\n";
  try {
    ctx.buildProgramFromSource(bad, "", "broken.cl");
    FAIL() << "a kernel with an error built";
  } catch (const RuntimeError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("CL_BUILD_PROGRAM_FAILURE"), std::string::npos) << what;
    EXPECT_NE(what.find("undeclared_thing"), std::string::npos) << "no build log in: " << what;
  }
}

TEST_F(ProgramTest, SecondBuildComesFromCacheAndCorruptEntryIsRebuilt) {
  Context& ctx = test::testContext();
  ProgramBuild first = ctx.buildProgram("test/smoke.cl", "-DPR_CACHE_PROBE=1");
  EXPECT_FALSE(first.fromCache);
  ASSERT_FALSE(first.cacheFile.empty());
  ASSERT_TRUE(fs::exists(first.cacheFile)) << first.cacheFile;
  ProgramBuild second = ctx.buildProgram("test/smoke.cl", "-DPR_CACHE_PROBE=1");
  EXPECT_TRUE(second.fromCache);
  EXPECT_EQ(second.cacheFile, first.cacheFile);
  // Other options: another key.
  ProgramBuild other = ctx.buildProgram("test/smoke.cl", "-DPR_CACHE_PROBE=2");
  EXPECT_FALSE(other.fromCache);
  EXPECT_NE(other.cacheFile, first.cacheFile);

  // Corrupt the cached binary: the build must still succeed, from source.
  {
    std::fstream f(first.cacheFile, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(40);
    f.write("garbage!garbage!", 16);
  }
  ProgramBuild third = ctx.buildProgram("test/smoke.cl", "-DPR_CACHE_PROBE=1");
  EXPECT_FALSE(third.fromCache);
  cl_int err = CL_SUCCESS;
  cl::Kernel k(third.program, "saxpy", &err);
  EXPECT_EQ(err, CL_SUCCESS);
  // Truncated to nothing: rebuilt again.
  std::ofstream(first.cacheFile, std::ios::trunc).close();
  EXPECT_FALSE(ctx.buildProgram("test/smoke.cl", "-DPR_CACHE_PROBE=1").fromCache);
  EXPECT_TRUE(ctx.buildProgram("test/smoke.cl", "-DPR_CACHE_PROBE=1").fromCache);
}

// A driver setting that changes the code a binary holds is in the key: a binary built under
// another PoCL work-group method is not loaded. Settings that only log or place work are not.
TEST_F(ProgramTest, DriverCodeSettingsAreInTheKey) {
  Context& ctx = test::testContext();
  const char* saved = std::getenv("POCL_WORK_GROUP_METHOD");
  const std::string before = saved ? saved : "";
  const ProgramBuild first = ctx.buildProgram("test/smoke.cl", "-DPR_CACHE_PROBE=3");
  ASSERT_FALSE(first.cacheFile.empty());
  setenv("POCL_WORK_GROUP_METHOD", before == "cbs" ? "loops" : "cbs", 1);
  const std::string otherMethod = driverEnvironmentTag();
  const ProgramBuild other = ctx.buildProgram("test/smoke.cl", "-DPR_CACHE_PROBE=3");
  if (saved)
    setenv("POCL_WORK_GROUP_METHOD", before.c_str(), 1);
  else
    unsetenv("POCL_WORK_GROUP_METHOD");
  EXPECT_FALSE(other.fromCache);
  EXPECT_NE(other.cacheFile, first.cacheFile);
  EXPECT_NE(otherMethod.find("POCL_WORK_GROUP_METHOD="), std::string::npos) << otherMethod;
  const std::string tag = driverEnvironmentTag();
  setenv("POCL_DEBUG", "all", 1);
  setenv("CL_CONFIG_USE_VECTORIZER", "0", 1);
  const std::string withDebug = driverEnvironmentTag();
  unsetenv("POCL_DEBUG");
  unsetenv("CL_CONFIG_USE_VECTORIZER");
  EXPECT_EQ(withDebug.find("POCL_DEBUG"), std::string::npos) << withDebug;
  EXPECT_NE(withDebug.find("CL_CONFIG_USE_VECTORIZER=0\n"), std::string::npos) << withDebug;
  EXPECT_EQ(driverEnvironmentTag(), tag);
  EXPECT_TRUE(ctx.buildProgram("test/smoke.cl", "-DPR_CACHE_PROBE=3").fromCache);
}

// A program whose kernel `scale` writes y[i] = factor * x[i].
std::string scaleSource(int factor) {
  return "__kernel void scale(__global const float* x, __global float* y) {\n"
         "  y[get_global_id(0)] = " +
         std::to_string(factor) + ".0f * x[get_global_id(0)];\n}\n";
}

// What kernel `scale` of `build` makes of x = 1.
float scaleOfOne(const ProgramBuild& build) {
  Context& ctx = test::testContext();
  cl_int err = CL_SUCCESS;
  cl::Kernel k(build.program, "scale", &err);
  EXPECT_EQ(err, CL_SUCCESS);
  const float one = 1.0f;
  float y = -1.0f;
  cl::Buffer x = ctx.allocate("x", sizeof one);
  cl::Buffer out = ctx.allocate("y", sizeof y);
  ctx.queue().enqueueWriteBuffer(x, CL_TRUE, 0, sizeof one, &one);
  k.setArg(0, x);
  k.setArg(1, out);
  ctx.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(1));
  ctx.queue().enqueueReadBuffer(out, CL_TRUE, 0, sizeof y, &y);
  ctx.release("x", sizeof one);
  ctx.release("y", sizeof y);
  return y;
}

// Another program's valid cache file under this program's name (copied, or files rotated) is
// never loaded: the file holds the key it was made for.
TEST_F(ProgramTest, AnotherProgramsCacheFileIsRebuiltNotLoaded) {
  Context& ctx = test::testContext();
  const ProgramBuild two = ctx.buildProgramFromSource(scaleSource(2), "", "two");
  const ProgramBuild three = ctx.buildProgramFromSource(scaleSource(3), "", "three");
  ASSERT_FALSE(two.cacheFile.empty());
  ASSERT_NE(two.cacheFile, three.cacheFile);
  // Rotated: each file holds the other's binary.
  const std::string aside = two.cacheFile + ".aside";
  fs::rename(two.cacheFile, aside);
  fs::rename(three.cacheFile, two.cacheFile);
  fs::rename(aside, three.cacheFile);
  const ProgramBuild twoAgain = ctx.buildProgramFromSource(scaleSource(2), "", "two");
  EXPECT_FALSE(twoAgain.fromCache);
  EXPECT_EQ(scaleOfOne(twoAgain), 2.0f);
  const ProgramBuild threeAgain = ctx.buildProgramFromSource(scaleSource(3), "", "three");
  EXPECT_FALSE(threeAgain.fromCache);
  EXPECT_EQ(scaleOfOne(threeAgain), 3.0f);
  // Rewritten right, each loads from its own file again.
  EXPECT_TRUE(ctx.buildProgramFromSource(scaleSource(2), "", "two").fromCache);
  EXPECT_EQ(scaleOfOne(ctx.buildProgramFromSource(scaleSource(2), "", "two")), 2.0f);
}

// Header: magic (8), key (32 hex), size (8), MAC (32); the binary follows.
constexpr size_t kCacheHeaderBytes = 80;

// A cache file of `key` around `binary` whose MAC is made under `secret`.
std::string forgeCacheFile(const std::string& key, const std::string& binary,
                           const std::string& secret) {
  std::string forged = cacheFormatTag() + key;
  const uint64_t size = binary.size();
  forged.append(reinterpret_cast<const char*>(&size), sizeof size);
  forged += cacheFileMac(secret, key, binary);
  return forged + binary;
}

// A cache file with this program's key and a right MAC around a binary that lacks the kernel
// asked for (the driver loads it): the kernel is built again from source, not refused.
TEST_F(ProgramTest, CachedBinaryWithoutTheKernelIsRebuilt) {
  Context& ctx = test::testContext();
  const ProgramBuild smoke = ctx.buildProgram("test/smoke.cl");
  const ProgramBuild other = ctx.buildProgramFromSource(scaleSource(2), "", "other");
  std::string smokeFile = test::slurp(smoke.cacheFile), otherFile = test::slurp(other.cacheFile);
  ASSERT_GT(smokeFile.size(), kCacheHeaderBytes);
  ASSERT_GT(otherFile.size(), kCacheHeaderBytes);
  const std::string secret = test::slurp(cacheDir_ + "/kernels/secret");
  ASSERT_EQ(secret.size(), kCacheSecretBytes);
  const std::string forged =
      forgeCacheFile(smokeFile.substr(8, 32), otherFile.substr(kCacheHeaderBytes), secret);
  std::ofstream(smoke.cacheFile, std::ios::binary | std::ios::trunc) << forged;
  ASSERT_TRUE(ctx.buildProgram("test/smoke.cl").fromCache) << "the forged file was not loaded";
  cl::Kernel k = ctx.kernel("test/smoke.cl", "saxpy");
  EXPECT_TRUE(k());
  EXPECT_NE(test::slurp(smoke.cacheFile), forged);
  EXPECT_TRUE(ctx.buildProgram("test/smoke.cl").fromCache);
}

// Files this user's pathreuse did not write never reach the driver, which may crash on a damaged
// binary rather than refuse it: half a binary in a file whose header and checksum are consistent
// but made without this cache's secret, and a whole one from another user's cache, are rebuilt.
TEST_F(ProgramTest, CacheFileNotWrittenUnderThisCachesSecretIsRebuilt) {
  Context& ctx = test::testContext();
  const ProgramBuild first = ctx.buildProgramFromSource(scaleSource(5), "", "five");
  ASSERT_FALSE(first.cacheFile.empty());
  const std::string file = test::slurp(first.cacheFile);
  ASSERT_GT(file.size(), kCacheHeaderBytes + 2);
  const std::string key = file.substr(8, 32), binary = file.substr(kCacheHeaderBytes);
  const std::string strangersSecret(kCacheSecretBytes, 'x');
  for (const std::string& forged :
       {forgeCacheFile(key, binary.substr(0, binary.size() / 2), strangersSecret),
        forgeCacheFile(key, binary, strangersSecret)}) {
    std::ofstream(first.cacheFile, std::ios::binary | std::ios::trunc) << forged;
    const ProgramBuild again = ctx.buildProgramFromSource(scaleSource(5), "", "five");
    EXPECT_FALSE(again.fromCache);
    EXPECT_EQ(scaleOfOne(again), 5.0f);
    // Stored again under this cache's secret: the next build loads it.
    const ProgramBuild stored = ctx.buildProgramFromSource(scaleSource(5), "", "five");
    EXPECT_TRUE(stored.fromCache);
    EXPECT_EQ(scaleOfOne(stored), 5.0f);
  }
}

// A secret others could read (or one another user owns) could sign anything: the cache is not
// used at all, and the run goes on building from source.
TEST_F(ProgramTest, CacheWhoseSecretOthersCanReadIsNotUsed) {
  Context& ctx = test::testContext();
  const std::string dir = test::tempDir("cache-open");
  fs::create_directories(dir + "/kernels");
  std::ofstream(dir + "/kernels/secret", std::ios::binary) << std::string(kCacheSecretBytes, 'k');
  fs::permissions(dir + "/kernels/secret", fs::perms::owner_read | fs::perms::owner_write |
                                               fs::perms::group_read | fs::perms::others_read);
  setenv("PATHREUSE_CACHE_DIR", dir.c_str(), 1);
  testing::internal::CaptureStderr();
  const ProgramBuild first = ctx.buildProgramFromSource(scaleSource(7), "", "seven");
  const ProgramBuild second = ctx.buildProgramFromSource(scaleSource(7), "", "seven");
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_TRUE(first.cacheFile.empty());
  EXPECT_FALSE(second.fromCache);
  EXPECT_EQ(scaleOfOne(second), 7.0f);
  EXPECT_NE(err.find("kernel cache is not used this run: " + dir +
                     "/kernels/secret is open to "
                     "other users"),
            std::string::npos)
      << err;
  EXPECT_EQ(err.find("kernel cache", err.find("kernel cache") + 1), std::string::npos)
      << "said more than once: " << err;
  // Nothing was written into it.
  std::vector<std::string> bins;
  for (const auto& e : fs::directory_iterator(dir + "/kernels"))
    if (e.path().extension() == ".bin") bins.push_back(e.path());
  EXPECT_TRUE(bins.empty());
}

// A fresh cache folder gets a private secret of the right size, made once.
TEST_F(ProgramTest, CacheSecretIsPrivateAndKept) {
  Context& ctx = test::testContext();
  ctx.buildProgramFromSource(scaleSource(9), "", "nine");
  const std::string secretFile = cacheDir_ + "/kernels/secret";
  ASSERT_TRUE(fs::is_regular_file(secretFile));
  EXPECT_EQ(fs::file_size(secretFile), kCacheSecretBytes);
  const fs::perms p = fs::status(secretFile).permissions();
  EXPECT_EQ(p & (fs::perms::group_all | fs::perms::others_all), fs::perms::none);
  std::string why;
  const std::string secret = cacheSecret(cacheDir_ + "/kernels", &why);
  EXPECT_TRUE(why.empty()) << why;
  EXPECT_EQ(secret, test::slurp(secretFile));
  EXPECT_EQ(cacheSecret(cacheDir_ + "/kernels", &why), secret);
}

TEST(Layout, DeviceAgreesWithHostOnEverySharedStruct) {
  using namespace pr::dev;
  std::vector<std::string> names;
  std::vector<cl_uint> host;
#define PR_HOST_SIZE(T)          \
  names.push_back("sizeof " #T); \
  host.push_back(sizeof(T));
  PR_SHARED_STRUCTS(PR_HOST_SIZE)
#define PR_HOST_OFFSET(T, m)              \
  names.push_back("offsetof " #T "." #m); \
  host.push_back(offsetof(T, m));
  PR_SHARED_FIELDS(PR_HOST_OFFSET)

  Context& ctx = test::testContext();
  ProgramBuild b = ctx.buildProgram("test/layout.cl");
  cl_int err = CL_SUCCESS;
  cl::Kernel k(b.program, "struct_layout", &err);
  CL_CHECK(err);
  const size_t bytes = host.size() * sizeof(cl_uint);
  cl::Buffer out = ctx.allocate("layout", bytes);
  ctx.zero(out, bytes);
  CL_CHECK(k.setArg(0, out));
  ctx.launch1D(k, 1, "struct_layout");
  std::vector<cl_uint> device(host.size(), 0xdeadbeef);
  CL_CHECK(ctx.queue().enqueueReadBuffer(out, CL_TRUE, 0, bytes, device.data()));
  for (size_t i = 0; i < host.size(); ++i) EXPECT_EQ(device[i], host[i]) << names[i];
}

}  // namespace
}  // namespace pr
