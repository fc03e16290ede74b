// What moves while the shutter is open, as boxes that kernels test light sub-paths against
// (LightData.sweeps, kernels/shared/transport.h sweep_clear; docs/design.md section 3, "Path
// reuse over the shutter"). A record is a box (lo xyz, hi xyz) and the number of records that
// follow it in its subtree, 7 floats: a segment that meets a record with none (a leaf) meets what
// moves; the subtree of a record whose box it misses is skipped. Top level: a tree over the
// moving instances and lights (sweepTree); below an instance's record, its parts.
// A moving instance is a record over its parts: its triangles in spatially coherent groups,
// each group's box holding the group at every motion step (a blend between two steps moves
// every point along the segment between its placements, inside the union of the two boxes).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace pr {

inline constexpr int kSweepRecordFloats = 7;

// The triangles of a mesh (positions, indices) in at most 2^levels groups by median splits of
// their centroids along the widest axis (groups of at most 8 triangles are not split), each
// group as the sorted list of its vertices.
std::vector<std::vector<uint32_t>> sweepParts(const std::vector<glm::vec3>& positions,
                                              const std::vector<uint32_t>& indices, int levels = 5);

// Appends the record of an instance placed by `transforms` at the motion steps, its mesh's
// vertices at each step `positions[k]` (one entry: the same at every step), its `parts`
// (sweepParts), each box enlarged by `pad` plus 1e-4 of its coordinates' size. Nothing where
// the mesh has no vertices.
void appendInstanceSweep(const std::vector<std::vector<uint32_t>>& parts,
                         const std::vector<glm::mat4>& transforms,
                         const std::vector<const std::vector<glm::vec3>*>& positions, float pad,
                         std::vector<float>* records);

// Appends a record without parts: the box [lo, hi] enlarged as appendInstanceSweep's.
void appendBoxSweep(const glm::vec3& lo, const glm::vec3& hi, float pad,
                    std::vector<float>* records);

// The records (each top-level record followed by its subtree, as the append functions leave
// them) under a tree of boxes over the top-level ones, split at the median of their centres
// along the widest axis down to leafSize records, so that a segment is tested against a few
// boxes where the city has 45 moving instances.
std::vector<float> sweepTree(const std::vector<float>& records, size_t leafSize = 4);

}  // namespace pr
