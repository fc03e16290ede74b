// `pathreuse portability`: renders a fixed suite (a few frames of each demo scene and of each
// given scene, every mode, small size, fixed seed) on several OpenCL devices and compares every
// device's frames with the first device's, or with a reference saved on another machine, within
// a statistical tolerance (compare.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "portability/compare.h"

namespace pr {

struct PortabilityOptions {
  std::vector<std::string> scenes;  // added to the demo scenes
  bool demoScenes = true;           // false: only `scenes`
  bool allowOutsideUris = false;    // LoadOptions::allowOutsideUris
  std::string frames = "0-2,24";    // consecutive frames so reuse reuses, and a later one
  int width = 64;
  int height = 0;  // 0: from the camera's aspect (48 for the demo scenes)
  int spp = 8;
  uint32_t seed = 1;
  std::vector<std::string> modes;    // empty: reuse, retrace, pathtrace
  std::vector<std::string> devices;  // --device specs; empty: every device found
  Tolerance tolerance;
  bool json = false;
  std::string outDir = "out/portability";
  bool quiet = false;
  // The reference frames (seed and noise-floor seeds) as float EXRs and a manifest, so that a
  // device on another machine can be compared with them (--save-reference / --reference).
  std::string saveReferenceDir;
  std::string referenceDir;  // non-empty: every device is compared with these frames
};

// "A", "A-B" and comma-separated lists of them ("0-2,24"), sorted, without repeats. Throws
// InputError naming --frames.
std::vector<int64_t> parseFrameList(const std::string& text);

// Where the demo scenes are: <executable dir>/../scenes, else the source tree's scenes/.
// Throws InputError when neither holds them.
std::vector<std::string> demoScenePaths();

// Returns the exit code: 0 all devices agree (or there is only one), 1 a device disagrees.
// Throws InputError for bad options, a missing scene or an unknown device, RuntimeError for
// device failures.
int runPortability(const PortabilityOptions& options);

}  // namespace pr
