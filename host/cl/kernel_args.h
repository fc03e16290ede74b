// Kernel arguments set in order, so that no index is counted by hand.
#pragma once

#include "cl/cl.h"
#include "cl/error.h"

namespace pr {

// Sets consecutive arguments of `kernel` from index `first` on; returns the index after the
// last one set.
template <typename... Args>
cl_uint setKernelArgs(cl::Kernel& kernel, cl_uint first, const Args&... args) {
  (CL_CHECK(kernel.setArg(first++, args)), ...);
  return first;
}

}  // namespace pr
