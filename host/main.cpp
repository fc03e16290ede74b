// pathreuse: command-line entry. Parses arguments with CLI11, runs one subcommand, and turns
// every exception into one line on stderr and an exit code (DESIGN.md section 1).
#include <cstdio>
#include <exception>
#include <iostream>
#include <new>
#include <string>

#include <CLI/CLI.hpp>

#include "cl/device.h"
#include "util/error.h"

namespace {

int runDevices(bool json) {
  const auto devices = pr::enumerateDevices();
  if (devices.empty()) throw pr::NoDeviceError();
  if (json) {
    std::cout << pr::devicesJson(devices) << "\n";
  } else {
    for (const auto& d : devices) std::cout << pr::describeDevice(d) << "\n";
  }
  return pr::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pathreuse: global illumination of animated glTF scenes by reusing light paths"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "pathreuse 0.1.0");

  bool devicesJson = false;
  auto* devices = app.add_subcommand("devices", "List every OpenCL platform and device");
  devices->add_flag("--json", devicesJson, "Print the list as JSON");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "error: " << e.what() << " (see pathreuse --help)\n";
    return pr::kExitBadInput;
  }

  try {
    if (*devices) return runDevices(devicesJson);
  } catch (const pr::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return pr::kExitBadInput;
  } catch (const pr::RuntimeError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return pr::kExitRuntime;
  } catch (const std::bad_alloc&) {
    std::cerr << "error: out of host memory\n";
    return pr::kExitRuntime;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return pr::kExitRuntime;
  }
  return pr::kExitOk;
}
