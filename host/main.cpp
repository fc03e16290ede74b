// pathreuse: command-line entry. Parses arguments with CLI11, runs one subcommand, and turns
// every exception into one line on stderr and an exit code (docs/design.md section 1).
#include <algorithm>
#include <cmath>
#include <iterator>
#include <cstdio>
#include <exception>
#include <iostream>
#include <new>
#include <string>

#include <CLI/CLI.hpp>

#if defined(__GLIBC__)
#include <malloc.h>

#include <climits>
#endif

#include "app/cli_checks.h"
#include "app/render_cli.h"
#include "cl/device.h"
#include "portability/portability.h"
#include "render/options.h"
#include "render/renderer.h"
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

int runInfo(const std::string& path, bool json, double fps, bool allowOutsideUris) {
  if (!(fps > 0.0) || fps > 1000.0) throw pr::InputError("--fps: must be in (0, 1000]");
  pr::LoadOptions options;
  options.allowOutsideUris = allowOutsideUris;
  options.printWarnings = json;  // the text summary lists them itself
  const pr::Scene scene = pr::loadScene(path, options);
  if (json)
    std::cout << pr::sceneInfoJson(scene, fps).dump(2) << "\n";
  else
    std::cout << pr::sceneInfoText(scene, fps);
  return pr::kExitOk;
}

// Options declared after this are listed under `group` in the subcommand's --help. A heading
// only: unlike add_option_group, parsing and error messages stay as they are.
void listUnder(CLI::App* command, const char* group) {
  command->option_defaults()->group(group);
}

// --- devices and info ---

struct InfoArgs {
  std::string scene;
  bool json = false;
  double fps = 24.0;
  bool allowOutsideUris = false;
};

CLI::App* addDevicesCommand(CLI::App& app, bool& json) {
  auto* devices = app.add_subcommand("devices", "List every OpenCL platform and device");
  devices->add_flag("--json", json, "Print the list as JSON");
  return devices;
}

CLI::App* addInfoCommand(CLI::App& app, InfoArgs& a) {
  auto* info =
      app.add_subcommand("info", "What a scene holds: static/dynamic split, lights, animation");
  info->add_option("SCENE", a.scene, "glTF file (.gltf or .glb)")->required();
  info->add_flag("--json", a.json, "Print as JSON");
  info->add_option("--fps", a.fps, "Frames per second of the animation (default 24)")
      ->check(pr::finiteIn(0.001, 1000));
  info->add_flag("--allow-outside-uris", a.allowOutsideUris, pr::kOutsideUrisHelp);
  return info;
}

// --- portability ---

struct PortabilityArgs {
  pr::PortabilityOptions po;
  bool noDemo = false;
};

const char* const kPortabilityFooter =
    "Renders a fixed suite on every OpenCL device and compares each device's frames with the\n"
    "first's. Round-off may send paths another way on another device, so the check is\n"
    "statistical: the first device renders the suite again with seeds seed+1 and seed+2, and\n"
    "these independent estimates give each frame's noise floor. A device whose paths diverge\n"
    "is at worst another seed; a fault adds a systematic error. Leaving out the 1% most\n"
    "extreme pixels (fireflies), a device disagrees when its relMSE > TOLERANCE x the floor's,\n"
    "when its mean luminance is more than SIGMAS standard errors off, or on any NaN/Inf.\n"
    "Exit 0: all agree (or only one device: nothing to compare); 1: a device disagrees;\n"
    "2: bad input.";

// What is rendered: scenes, frames, size, samples and modes.
void addSuiteOptions(CLI::App* portability, PortabilityArgs& a) {
  pr::PortabilityOptions& po = a.po;
  listUnder(portability, "Suite");
  portability->add_flag("--no-demo", a.noDemo, "Test only the given scenes, not the demo scenes");
  portability->add_flag("--allow-outside-uris", po.allowOutsideUris, pr::kOutsideUrisHelp);
  portability->add_option("--frames", po.frames, "Frames: A, A-B or a list (A,B-C)")
      ->capture_default_str();
  portability->add_option("--width", po.width, "Image width")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  portability->add_option("--height", po.height, "Image height (default: from the camera's aspect)")
      ->check(CLI::Range(1, 16384));
  portability->add_option("--spp", po.spp, "Samples per pixel per frame")
      ->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  portability->add_option("--seed", po.seed, "Random seed (the noise floor uses seed+1 and seed+2)")
      ->check(CLI::Range(0u, 4294967293u))
      ->capture_default_str();
  portability
      ->add_option("--mode", po.modes,
                   "reuse, retrace or pathtrace; repeatable (default: all three)")
      ->check(CLI::IsMember({"reuse", "retrace", "pathtrace"}));
}

// Which devices, what they are compared with, and how closely.
void addComparisonOptions(CLI::App* portability, PortabilityArgs& a) {
  pr::PortabilityOptions& po = a.po;
  listUnder(portability, "Devices and comparison");
  portability->add_option(
      "--device", po.devices,
      "Device (index, P:D, cpu, gpu or part of its name); repeatable, the first is the "
      "reference (default: every device found)");
  portability
      ->add_option("--tolerance", po.tolerance.relMseFactor,
                   "A device disagrees when its relMSE exceeds this multiple of the noise floor")
      ->check(pr::finiteIn(0.001, 1e6))
      ->capture_default_str();
  portability
      ->add_option("--sigmas", po.tolerance.lumSigmas,
                   "... or when its mean luminance is this many standard errors off")
      ->check(pr::finiteIn(0.001, 1e6))
      ->capture_default_str();
  portability->add_option("--save-reference", po.saveReferenceDir,
                          "Also write the reference device's frames (and noise-floor seeds) to "
                          "this folder, to compare a device on another machine with");
  portability->add_option("--reference", po.referenceDir,
                          "Compare every device with the frames saved in this folder by "
                          "--save-reference, instead of with the first device");
}

void addReportOptions(CLI::App* portability, PortabilityArgs& a) {
  pr::PortabilityOptions& po = a.po;
  listUnder(portability, "Output");
  portability->add_flag("--json", po.json, "Print one JSON document instead of the table");
  portability->add_option("--out", po.outDir, "Folder for the PNG of the worst difference")
      ->capture_default_str();
  portability->add_flag("-q,--quiet", po.quiet, "No progress lines on stderr");
}

CLI::App* addPortabilityCommand(CLI::App& app, PortabilityArgs& a) {
  auto* portability = app.add_subcommand(
      "portability", "Render a fixed suite on every OpenCL device and compare the images");
  portability->footer(kPortabilityFooter);
  portability->add_option("SCENES", a.po.scenes, "glTF files tested besides the demo scenes");
  addSuiteOptions(portability, a);
  addComparisonOptions(portability, a);
  addReportOptions(portability, a);
  return portability;
}

// --- options ---

// Prints the render options as Markdown: README.md's table and docs/options.md are this output
// (tools/docs/option_tables.py). Not listed in --help: it is for the docs.
CLI::App* addOptionsCommand(CLI::App& app, bool& all) {
  auto* options = app.add_subcommand("options", "The render options as Markdown tables");
  options->group("");
  options->add_flag("--all", all, "Every option by group, research knobs too");
  return options;
}

// --- running ---

// Runs `command`, turning its exceptions into one line on stderr and an exit code.
template <typename Command>
int runReportingErrors(Command command) {
  try {
    return command();
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
}

// Every frame frees and allocates again buffers of many MiB (a deforming mesh at each motion
// step, its tree, its packets). glibc maps blocks that large on their own and unmaps them when
// freed, so each frame faulted their pages in anew; kept in the heap, they are reused (BrainStem
// at 2 fps with the shutter open: frames 0.34 -> 0.26 s; docs/experiments/motion-blur.md).
void keepLargeBlocksInTheHeap() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 1 << 30);
  mallopt(M_TRIM_THRESHOLD, INT_MAX);
#endif
}

}  // namespace

int main(int argc, char** argv) {
  keepLargeBlocksInTheHeap();
  CLI::App app{"pathreuse: global illumination of animated glTF scenes by reusing light paths"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "pathreuse 0.1.0");
  app.set_help_all_flag("--help-all", "Print this help with every option, research knobs too");
  bool devicesJson = false;
  InfoArgs infoArgs;
  pr::RenderArgs renderArgs;
  PortabilityArgs portabilityArgs;
  bool allOptions = false;
  const CLI::App* devices = addDevicesCommand(app, devicesJson);
  const CLI::App* info = addInfoCommand(app, infoArgs);
  const CLI::App* render = pr::addRenderCommand(app, renderArgs, pr::asksForHelpAll(argc, argv));
  const CLI::App* portability = addPortabilityCommand(app, portabilityArgs);
  const CLI::App* options = addOptionsCommand(app, allOptions);

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

  return runReportingErrors([&]() -> int {
    if (*devices) return runDevices(devicesJson);
    if (*info)
      return runInfo(infoArgs.scene, infoArgs.json, infoArgs.fps, infoArgs.allowOutsideUris);
    if (*render) return pr::runRender(pr::toRenderOptions(renderArgs, *render));
    if (*options) {
      std::cout << pr::renderOptionsMarkdown(allOptions);
      return pr::kExitOk;
    }
    if (*portability) {
      portabilityArgs.po.demoScenes = !portabilityArgs.noDemo;
      return pr::runPortability(portabilityArgs.po);
    }
    return pr::kExitOk;
  });
}
