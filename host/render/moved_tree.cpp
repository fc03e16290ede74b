#include "render/moved_tree.h"

#include <algorithm>
#include <cstdint>

#include "render/median_split.h"

namespace pr {
namespace {

// Both boxes of a record as one (lo xyz, hi xyz); an empty box (lo > hi) adds nothing.
void unionInto(const dev::MovedInstance& m, float* out) {
  for (int b = 0; b < 2; ++b) {
    const float* box = m.box + 6 * b;
    if (box[0] > box[3] || box[1] > box[4] || box[2] > box[5]) continue;
    for (int a = 0; a < 3; ++a) {
      out[a] = std::min(out[a], box[a]);
      out[3 + a] = std::max(out[3 + a], box[3 + a]);
    }
  }
}

struct Builder {
  std::vector<dev::MovedInstance> in, out;
  size_t leafSize;

  void build(size_t first, size_t last) {  // in[first, last)
    if (last - first <= leafSize) {
      for (size_t i = first; i < last; ++i) {
        out.push_back(in[i]);
        out.back().node = 0u;
        out.back().skip = uint32_t(out.size());
      }
      return;
    }
    dev::MovedInstance n{};
    for (int a = 0; a < 3; ++a) n.box[a] = 1e30f, n.box[3 + a] = -1e30f;
    for (size_t i = first; i < last; ++i) unionInto(in[i], n.box);
    std::copy(n.box, n.box + 6, n.box + 6);
    n.root = n.root_before = PR_INVALID_INDEX;
    n.node = 1u;
    auto centre = [](const dev::MovedInstance& m, int a) {
      float b[6] = {1e30f, 1e30f, 1e30f, -1e30f, -1e30f, -1e30f};
      unionInto(m, b);
      return b[a] <= b[3 + a] ? 0.5f * (b[a] + b[3 + a]) : 0.0f;
    };
    const auto begin = in.begin();
    const size_t mid = size_t(
        medianSplit(begin + std::ptrdiff_t(first), begin + std::ptrdiff_t(last), centre) - begin);
    const size_t self = out.size();
    out.push_back(n);
    build(first, mid);
    build(mid, last);
    out[self].skip = uint32_t(out.size());
  }
};

}  // namespace

std::vector<dev::MovedInstance> movedTree(std::vector<dev::MovedInstance> instances,
                                          size_t leafSize) {
  Builder b{std::move(instances), {}, std::max<size_t>(leafSize, 1)};
  b.out.reserve(2 * b.in.size());
  b.build(0, b.in.size());
  return std::move(b.out);
}

}  // namespace pr
