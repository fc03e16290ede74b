// pathreuse: command-line entry. Parses arguments with CLI11, runs one subcommand, and turns
// every exception into one line on stderr and an exit code (DESIGN.md section 1).
#include <cstdio>
#include <exception>
#include <iostream>
#include <new>
#include <string>

#include <CLI/CLI.hpp>

#include "cl/device.h"
#include "scene/gltf_loader.h"
#include "scene/scene_info.h"
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

int runInfo(const std::string& path, bool json, double fps) {
  if (!(fps > 0.0) || fps > 1000.0) throw pr::InputError("--fps: must be in (0, 1000]");
  pr::LoadOptions options;
  options.printWarnings = json;  // the text summary lists them itself
  const pr::Scene scene = pr::loadScene(path, options);
  if (json)
    std::cout << pr::sceneInfoJson(scene, fps).dump(2) << "\n";
  else
    std::cout << pr::sceneInfoText(scene, fps);
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

  std::string infoScene;
  bool infoJson = false;
  double infoFps = 24.0;
  auto* info = app.add_subcommand("info", "What a scene holds: static/dynamic split, lights, animation");
  info->add_option("SCENE", infoScene, "glTF file (.gltf or .glb)")->required();
  info->add_flag("--json", infoJson, "Print as JSON");
  info->add_option("--fps", infoFps, "Frames per second of the animation (default 24)");

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
    if (*info) return runInfo(infoScene, infoJson, infoFps);
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
