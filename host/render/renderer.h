// `pathreuse render`: loads the scene, picks the device, and renders the frame range with the
// chosen mode, writing one EXR (and PNG) per frame and one stats line per frame.
#pragma once

#include "render/options.h"

namespace pr {

// Returns the exit code; throws InputError / RuntimeError for main to report.
int runRender(const RenderOptions& options);

}  // namespace pr
