// The instances that moved since the previous frame as a bounding-box tree in preorder, so that
// pt_resample's temporal tests (kernels/shared/resample.h, rs_clear) visit the few whose boxes a
// segment comes near instead of every one.
#pragma once

#include <vector>

#include "shared/path_state.h"

namespace pr {

// The instances' records (each `node` 0, both boxes set) ordered into a tree: inner records bound
// their subtrees and say where the record after it is (`skip`). At most leafSize instances sit
// side by side under one inner record; a list of at most that many is returned as it is.
std::vector<dev::MovedInstance> movedTree(std::vector<dev::MovedInstance> instances,
                                          size_t leafSize = 2);

}  // namespace pr
