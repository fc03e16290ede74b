// `pathreuse render`: loads the scene, picks the device, and renders the frame range with the
// chosen mode, writing one EXR (and PNG) per frame and one stats line per frame.
#pragma once

#include "render/options.h"

namespace pr {

// Returns the exit code; throws InputError / RuntimeError for main to report.
int runRender(const RenderOptions& options);

class MultiDeviceSession;

// --resume's history beside the last frame written: every device's, with the devices' split of
// the passes, under `key` (what else it depends on). unpackHistories gives the session that
// split and reads each device's; false where the file is not one this session can read (another
// key, frame, size or device count, or damaged).
std::string packHistories(MultiDeviceSession& session, const std::string& key);
bool unpackHistories(const std::string& data, MultiDeviceSession& session, const std::string& key,
                     int64_t frame);

}  // namespace pr
