#include "support/test_env.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cl/device.h"

namespace pr::test {

namespace fs = std::filesystem;

Context& testContext() {
  static std::unique_ptr<Context> ctx;
  static std::once_flag once;
  std::call_once(once, [] {
    const char* spec = std::getenv("PATHREUSE_TEST_DEVICE");
    static const auto devices = enumerateDevices();
    ctx = std::make_unique<Context>(selectDevice(devices, spec ? spec : ""));
  });
  return *ctx;
}

std::string scenesDir() {
  if (const char* dir = std::getenv("PATHREUSE_SCENES"); dir && *dir) return dir;
  return (fs::path(PATHREUSE_SHARED_DIR) / "scenes").lexically_normal().string();
}

bool scenesRequired() {
  const char* r = std::getenv("PATHREUSE_REQUIRE_SCENES");
  return r && *r && std::string(r) != "0";
}

std::string sharedScene(const std::string& rel) {
  const fs::path p = fs::path(scenesDir()) / rel;
  return fs::exists(p) ? p.lexically_normal().string() : "";
}

std::string missingSceneMessage(const std::string& rel) {
  return "third-party scene " + rel + " is not in " + scenesDir() +
         (scenesRequired() ? " and PATHREUSE_REQUIRE_SCENES is set"
                           : "; put ../shared/scenes beside the clone or set PATHREUSE_SCENES");
}

std::string sourcePath(const std::string& rel) {
  return (fs::path(PATHREUSE_SOURCE_DIR) / rel).string();
}

namespace {
struct TempDirs {
  std::vector<std::string> dirs;
  ~TempDirs() {
    if (std::getenv("PATHREUSE_KEEP_TEST_FILES")) return;  // to look into a failure
    for (const auto& d : dirs) {
      std::error_code ec;
      fs::remove_all(d, ec);
    }
  }
};
TempDirs& tempDirs() {
  static TempDirs t;
  return t;
}
}  // namespace

std::string tempDir(const std::string& tag) {
  std::string templ = (fs::temp_directory_path() / ("pathreuse-" + tag + "-XXXXXX")).string();
  std::vector<char> buf(templ.begin(), templ.end());
  buf.push_back('\0');
  if (!mkdtemp(buf.data())) throw std::runtime_error("mkdtemp failed for " + templ);
  tempDirs().dirs.emplace_back(buf.data());
  return buf.data();
}

size_t lineCount(const std::string& s) {
  size_t n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

CommandResult runPathreuse(const std::string& args, const std::string& env) {
  const std::string dir = tempDir("cli");
  const std::string outFile = dir + "/stdout", errFile = dir + "/stderr";
  // Renders run on the device under test too, unless the caller names one.
  std::string prefix = env;
  const char* spec = std::getenv("PATHREUSE_TEST_DEVICE");
  if (spec && *spec && env.find("PATHREUSE_DEVICE=") == std::string::npos)
    prefix = "PATHREUSE_DEVICE='" + std::string(spec) + "' " + prefix;
  const std::string cmd = prefix + (prefix.empty() ? "" : " ") + "'" + PATHREUSE_BINARY + "' " +
                          args + " >'" + outFile + "' 2>'" + errFile + "' </dev/null";
  const int status = std::system(cmd.c_str());
  CommandResult r;
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp(outFile);
  r.err = slurp(errFile);
  return r;
}

const char* const kTwoPoclDrivers = "POCL_DEVICES='pthread basic'";

PlatformDevices firstDevicePerPlatform() {
  PlatformDevices out;
  const auto list = runPathreuse("devices --json");
  EXPECT_EQ(list.exitCode, 0) << list.err;
  const auto found =
      list.exitCode == 0 ? nlohmann::json::parse(list.out) : nlohmann::json::object();
  if (found.contains("devices"))
    for (const auto& d : found["devices"]) {
      const std::string platform = d["platform"];
      if (std::find(out.platforms.begin(), out.platforms.end(), platform) != out.platforms.end())
        continue;
      out.platforms.push_back(platform);
      out.devices.push_back(std::to_string(d["index"].get<int>()));
    }
  const char* required = std::getenv("PATHREUSE_REQUIRE_PLATFORMS");
  const size_t need = required ? std::strtoul(required, nullptr, 10) : 0;
  EXPECT_GE(out.platforms.size(), need)
      << "PATHREUSE_REQUIRE_PLATFORMS=" << need << " but found: " << list.out;
  return out;
}

std::string twoPoclDevices() {
  const auto r = runPathreuse("devices --json", kTwoPoclDrivers);
  std::string args;
  int found = 0;
  const auto list = r.exitCode == 0 ? nlohmann::json::parse(r.out) : nlohmann::json::object();
  if (list.contains("devices"))
    for (const auto& d : list["devices"])
      if (d["platform_vendor"] == "The pocl project") {
        args += " --device " + std::to_string(d["index"].get<int>());
        ++found;
      }
  EXPECT_EQ(found, 2) << r.out << r.err;
  return args;
}

}  // namespace pr::test
