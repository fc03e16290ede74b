// The split both box trees over moving things use (render/moved_tree, render/sweeps): items at
// the median of their centres along the axis where those centres spread widest.
#pragma once

#include <algorithm>
#include <iterator>

namespace pr {

// Reorders [first, last) so that the middle item is the median by centre(item, axis) on the
// widest axis, those before it not above it and those after not below; returns the middle.
template <typename It, typename Centre>
It medianSplit(It first, It last, Centre centre) {
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  for (It i = first; i != last; ++i)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], centre(*i, a));
      hi[a] = std::max(hi[a], centre(*i, a));
    }
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
  const It mid = first + std::distance(first, last) / 2;
  using Item = typename std::iterator_traits<It>::value_type;
  std::nth_element(first, mid, last,
                   [&](const Item& x, const Item& y) { return centre(x, axis) < centre(y, axis); });
  return mid;
}

}  // namespace pr
