// Host side of the kernels' statistics counters, kept in lanes (kernels/shared/types.h).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "cl/cl_check.h"
#include "cl/context.h"
#include "shared/types.h"
#include "util/check.h"

namespace pr {

// Bytes of a counter buffer whose lanes are `row` u32 long.
constexpr size_t counterBytes(uint32_t row) {
  return size_t(row) * dev::PR_COUNTER_LANES * 4;
}

// Counters [0, N) of each lane, added over the lanes (a blocking read).
template <size_t N>
std::array<cl_uint, N> readCounters(Context& ctx, const cl::Buffer& buffer, uint32_t row) {
  static_assert(N > 0);
  PR_CHECK(N <= row);
  std::vector<cl_uint> lanes(size_t(row) * dev::PR_COUNTER_LANES);
  CL_CHECK(ctx.queue().enqueueReadBuffer(buffer, CL_TRUE, 0, lanes.size() * 4, lanes.data()));
  std::array<cl_uint, N> sum{};
  for (uint32_t lane = 0; lane < dev::PR_COUNTER_LANES; ++lane)
    for (size_t i = 0; i < N; ++i) sum[i] += lanes[size_t(lane) * row + i];
  return sum;
}

}  // namespace pr
