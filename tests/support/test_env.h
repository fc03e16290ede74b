// Helpers shared by the tests: the OpenCL device under test, paths, and running the CLI.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cl/context.h"

namespace pr::test {

// The device the tests run on: --device-style spec from $PATHREUSE_TEST_DEVICE, else the
// default choice. Created once per test process.
Context& testContext();

// The third-party scenes' folder: $PATHREUSE_SCENES, else ../shared/scenes beside the project.
std::string scenesDir();
// Whether a missing third-party scene fails its test ($PATHREUSE_REQUIRE_SCENES set, not 0; CI
// sets it) rather than skipping it.
bool scenesRequired();
// Path of scenesDir()/<rel>, or "" when it is absent.
std::string sharedScene(const std::string& rel);
// Why a test that needs scenesDir()/<rel> did not run, and how to get it.
std::string missingSceneMessage(const std::string& rel);

// Path of a file in the source tree.
std::string sourcePath(const std::string& rel);

// A fresh empty temporary folder, removed at process exit.
std::string tempDir(const std::string& tag);

struct CommandResult {
  int exitCode = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

// Runs the pathreuse binary with `args` (a shell-quoted string); `env` is prefixed as-is. Under
// $PATHREUSE_TEST_DEVICE its renders use that device (as $PATHREUSE_DEVICE) unless `env` names one.
CommandResult runPathreuse(const std::string& args, const std::string& env = "");

// The first device of every OpenCL platform that `pathreuse devices` lists, as `--device` indexes,
// with the platforms' names; fails the test where the listing fails or where fewer platforms are
// found than $PATHREUSE_REQUIRE_PLATFORMS asks (tools/ci/test.sh: 2).
struct PlatformDevices {
  std::vector<std::string> platforms, devices;
};
PlatformDevices firstDevicePerPlatform();

// The lines of `s` (its newline characters): an error must be exactly one.
size_t lineCount(const std::string& s);

// A whole file's bytes; empty when it cannot be read.
std::string slurp(const std::string& path);

// PoCL's two drivers as `pathreuse devices` lists them under kTwoPoclDrivers.
extern const char* const kTwoPoclDrivers;

// " --device I --device J" for PoCL's two drivers under kTwoPoclDrivers (named pthread or cpu,
// and basic, by PoCL's version), whatever other platforms are listed; fails the test unless
// there are exactly two.
std::string twoPoclDevices();

}  // namespace pr::test

// Declares `const std::string var`, the path of third-party scene `rel`. Where it is absent the
// test fails under PATHREUSE_REQUIRE_SCENES and is skipped, saying why, otherwise (a user's clone
// has no ../shared).
#define PR_SHARED_SCENE(var, rel)                                                     \
  const std::string var = ::pr::test::sharedScene(rel);                               \
  if (var.empty()) {                                                                  \
    if (::pr::test::scenesRequired()) FAIL() << ::pr::test::missingSceneMessage(rel); \
    GTEST_SKIP() << ::pr::test::missingSceneMessage(rel);                             \
  }
