// Rendering through the command line in tests, and statistics of the images.
#pragma once

#include <string>
#include <vector>

#include "io/image.h"

namespace pr::test {

struct Moments {
  double mean = 0, stderr_ = 0;
};

// Mean of channel c over the pixel rectangle [x0, x1) x [y0, y1), with the standard error of
// that mean (pixels are independent estimates).
Moments regionMean(const Image& img, int x0, int y0, int x1, int y1, int c);

// Renders `frames` ("A" or "A-B") of `scene` with extra `args` into a fresh folder; returns
// the folder. Fails the current test on a non-zero exit.
std::string renderFrames(const std::string& scene, const std::string& frames,
                         const std::string& args, const std::string& tag);

// The float EXR of frame f in a folder made by renderFrames.
Image frameImage(const std::string& dir, int64_t frame);

// The JSON lines of dir/stats.jsonl.
std::vector<std::string> statsLines(const std::string& dir);

// A floor lit by a point light and by its glossy reflection in a metal wall (roughness 0.15):
// strategy T (light tracing) takes most of the reflected light, as an eye path's next-event
// estimation seldom finds the narrow lobe. Written into a fresh folder named after `tag`; 4:3.
std::string glossyReflectionScene(const std::string& tag);

}  // namespace pr::test
