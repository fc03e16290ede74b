#include "accel/scene_accel.h"

#include "util/check.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/vec4.hpp>

#include "util/check.h"
#include "util/error.h"
#include "util/parallel.h"

namespace pr::accel {

dev::BvhTriangle packTriangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                              uint32_t prim) {
  const glm::vec3 e1 = b - a, e2 = c - a;
  dev::BvhTriangle t{};
  t.v0x = a.x, t.v0y = a.y, t.v0z = a.z;
  t.e1x = e1.x, t.e1y = e1.y, t.e1z = e1.z;
  t.e2x = e2.x, t.e2y = e2.y, t.e2z = e2.z;
  t.prim = prim;
  return t;
}

bool zeroArea(const dev::BvhTriangle& t) {
  const glm::vec3 c = glm::cross(glm::vec3(t.e1x, t.e1y, t.e1z), glm::vec3(t.e2x, t.e2y, t.e2z));
  return c.x == 0.0f && c.y == 0.0f && c.z == 0.0f;
}

namespace {

void setPacketLane(dev::BvhTriPacket* p, uint32_t i, const dev::BvhTriangle& t) {
  p->v0x[i] = t.v0x, p->v0y[i] = t.v0y, p->v0z[i] = t.v0z;
  p->e1x[i] = t.e1x, p->e1y[i] = t.e1y, p->e1z[i] = t.e1z;
  p->e2x[i] = t.e2x, p->e2y[i] = t.e2y, p->e2z[i] = t.e2z;
  p->prim[i] = t.prim;
}

}  // namespace

dev::BvhTriPacket packTriangles(const dev::BvhTriangle* first, uint32_t count) {
  dev::BvhTriPacket p{};
  for (uint32_t i = 0; i < PR_BVH_PACKET; ++i) p.prim[i] = PR_INVALID_INDEX;
  for (uint32_t i = 0; i < count && i < PR_BVH_PACKET; ++i) setPacketLane(&p, i, first[i]);
  return p;
}

namespace {

// Child i's box of wide node `node` (a leaf's: leafBoxes[leaf * stride], one motion step's),
// written to `bounds` (node by node, 6 * width floats each) for the whole subtree; returns the
// node's box. Boxes grow by a few ulps, as a blended triangle's rounding may step outside the
// blend of exact boxes.
Aabb refitNode(const WideBvh& wide, const Aabb* leafBoxes, size_t stride, uint32_t node,
               float* bounds) {
  const int w = wide.width;
  Aabb all;
  for (int i = 0; i < w; ++i) {
    const uint32_t ref = wide.words[wideChild(w, node, i)];
    Aabb box;
    if (ref == PR_INVALID_INDEX) {
    } else if (ref & PR_BVH_LEAF_BIT) {
      box = leafBoxes[size_t(ref & ~PR_BVH_LEAF_BIT) * stride];
    } else {
      box = refitNode(wide, leafBoxes, stride, ref, bounds);
    }
    float b[6] = {1e30f, -1e30f, 1e30f, -1e30f, 1e30f, -1e30f};  // finite: blends stay inverted
    if (!box.empty()) {
      const glm::vec3 pad =
          (glm::abs(box.lo) + glm::abs(box.hi)) * 1e-6f + (box.hi - box.lo) * 1e-5f;
      box.lo -= pad, box.hi += pad;
      const float got[6] = {box.lo.x, box.hi.x, box.lo.y, box.hi.y, box.lo.z, box.hi.z};
      std::copy(got, got + 6, b);
      all.grow(box);
    }
    for (int k = 0; k < 6; ++k)
      bounds[(size_t(node) * 6 + size_t(k)) * size_t(w) + size_t(i)] = b[k];
  }
  return all;
}

// Widens each child box of `wide` to hold the child at every motion step (`stepBounds`, node by
// node, its steps side by side), so that a traversal without the blend still finds every hit.
void holdEveryStep(WideBvh* wide, const std::vector<float>& stepBounds, size_t stepCount) {
  const int w = wide->width;
  const size_t nodeFloats = 6 * size_t(w);
  for (uint32_t n = 0; n < wide->nodeCount(); ++n)
    for (int i = 0; i < w; ++i) {
      if (wide->words[wideChild(w, n, i)] == PR_INVALID_INDEX) continue;
      for (int b = 0; b < 6; ++b) {
        float v = stepBounds[n * stepCount * nodeFloats + size_t(b * w + i)];
        for (size_t k = 1; k < stepCount; ++k) {
          const float at = stepBounds[(n * stepCount + k) * nodeFloats + size_t(b * w + i)];
          v = (b % 2 == 0) ? std::min(v, at) : std::max(v, at);  // lo, hi, lo, ...
        }
        std::memcpy(&wide->words[wideBound(w, n, b, i)], &v, sizeof v);
      }
    }
}

}  // namespace

TriangleBvh buildTriangleBvh(const std::vector<glm::vec3>& positions,
                             const std::vector<uint32_t>& indices, uint32_t primBase,
                             const BuildOptions& options, const char* what,
                             const std::vector<std::vector<glm::vec3>>* steps) {
  const size_t stepCount = steps ? steps->size() : 0;
  for (size_t k = 0; k < stepCount; ++k)
    if ((*steps)[k].size() != positions.size())
      throw InputError(std::string(what) + ": motion step " + std::to_string(k) + " has " +
                       std::to_string((*steps)[k].size()) + " positions of " +
                       std::to_string(positions.size()));
  if (indices.size() % 3 != 0)
    throw InputError(std::string(what) + ": " + std::to_string(indices.size()) +
                     " indices is not a whole number of triangles");
  auto finite = [](const glm::vec3& p) {
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
  };
  for (size_t i = 0; i < positions.size(); ++i)
    if (!finite(positions[i]))
      throw InputError(std::string(what) + ": position " + std::to_string(i) + " is not finite");
  for (size_t k = 0; k < stepCount; ++k)
    if (!std::all_of((*steps)[k].begin(), (*steps)[k].end(), finite))
      throw InputError(std::string(what) + ": motion step " + std::to_string(k) +
                       ": a position is not finite");
  const size_t count = indices.size() / 3;
  std::vector<dev::BvhTriangle> packed;
  std::vector<uint32_t> kept;  // the triangle of each of `packed`
  std::vector<Aabb> boxes;     // at the frame's time
  packed.reserve(count);
  kept.reserve(count);
  boxes.reserve(count);
  for (size_t t = 0; t < count; ++t) {
    Aabb box;
    for (int k = 0; k < 3; ++k) {
      const uint32_t i = indices[3 * t + size_t(k)];
      if (i >= positions.size())
        throw InputError(std::string(what) + ": triangle " + std::to_string(t) + " uses vertex " +
                         std::to_string(i) + " of " + std::to_string(positions.size()));
      box.grow(positions[i]);
    }
    const dev::BvhTriangle tri =
        packTriangle(positions[indices[3 * t]], positions[indices[3 * t + 1]],
                     positions[indices[3 * t + 2]], primBase + uint32_t(t));
    if (zeroArea(tri)) continue;
    packed.push_back(tri);
    kept.push_back(uint32_t(t));
    boxes.push_back(box);
  }
  BuildOptions o = options;
  o.leafPacket = PR_BVH_PACKET;
  o.maxLeafSize = std::min<uint32_t>(o.maxLeafSize, PR_BVH_PACKET);  // one packet per leaf
  TriangleBvh out;
  Bvh bvh;
  out.wide = buildWideBvh(boxes, o, &bvh);
  out.binary = std::move(bvh.nodes);
  out.stats = bvh.stats;
  out.triangles.reserve(packed.size());
  for (uint32_t k : bvh.order) {
    out.triangles.push_back(packed[k]);
    out.bounds.grow(boxes[k]);
  }
  out.packets.reserve(out.wide.leaves.size());
  for (const BinaryNode& leaf : out.wide.leaves) {
    const uint32_t count = leaf.meta & ~PR_BVH_LEAF_BIT;
    PR_CHECK(count <= PR_BVH_PACKET && size_t(leaf.index) + count <= out.triangles.size());
    out.packets.push_back(packTriangles(out.triangles.data() + leaf.index, count));
  }
  // The steps' packets in the kernels' layout and their boxes, a run of leaves on each core
  // (each writes its own stretch); then each step's node boxes on its own core.
  const size_t nodeFloats = 6 * size_t(out.wide.width), nodes = out.wide.nodeCount();
  const std::vector<BinaryNode>& leaves = out.wide.leaves;
  out.stepCount = uint32_t(stepCount);
  out.stepPackets.resize(leaves.size() * stepCount);
  out.stepBounds.resize(nodes * stepCount * nodeFloats);
  constexpr size_t kLeavesPerTask = 1024;
  const size_t tasks = stepCount > 0 ? (leaves.size() + kLeavesPerTask - 1) / kLeavesPerTask : 0;
  std::vector<Aabb> taskBox(tasks), leafBoxes(leaves.size() * stepCount);
  std::vector<uint32_t> corners(stepCount > 0 ? 3 * out.triangles.size() : 0);  // tree order
  for (size_t i = 0; i < corners.size() / 3; ++i)
    std::copy_n(&indices[3 * size_t(kept[bvh.order[i]])], 3, &corners[3 * i]);
  parallelFor(int(tasks), [&](int task) {
    const size_t end = std::min(leaves.size(), (size_t(task) + 1) * kLeavesPerTask);
    Aabb& box = taskBox[size_t(task)];
    for (size_t k = 0; k < stepCount; ++k) {
      const std::vector<glm::vec3>& at = (*steps)[k];  // one step at a time: it stays in cache
      for (size_t j = size_t(task) * kLeavesPerTask; j < end; ++j) {
        const uint32_t first = leaves[j].index, n = leaves[j].meta & ~PR_BVH_LEAF_BIT;
        // The packet and its box as the kernels see it (v0, v0 + e1, v0 + e2), in one pass.
        dev::BvhTriPacket& p = out.stepPackets[j * stepCount + k];
        p = packTriangles(nullptr, 0);
        Aabb leafBox;
        for (uint32_t l = 0; l < n; ++l) {
          const uint32_t* v = &corners[3 * size_t(first + l)];
          const glm::vec3 &a = at[v[0]], &b = at[v[1]], &c = at[v[2]];
          const dev::BvhTriangle t = packTriangle(a, b, c, out.triangles[first + l].prim);
          setPacketLane(&p, l, t);
          box.grow(a), box.grow(b), box.grow(c);
          leafBox.grow(a);
          leafBox.grow(a + glm::vec3(t.e1x, t.e1y, t.e1z));
          leafBox.grow(a + glm::vec3(t.e2x, t.e2y, t.e2z));
        }
        leafBoxes[j * stepCount + k] = leafBox;
      }
    }
  });
  for (const Aabb& b : taskBox) out.bounds.grow(b);
  if (stepCount > 0 && nodes > 0)
    parallelFor(int(stepCount), [&](int k) {
      std::vector<float> step(nodes * nodeFloats, 0.0f);
      refitNode(out.wide, leafBoxes.data() + k, stepCount, 0, step.data());
      for (size_t n = 0; n < nodes; ++n)
        std::copy_n(step.data() + n * nodeFloats, nodeFloats,
                    out.stepBounds.data() + (n * stepCount + size_t(k)) * nodeFloats);
    });
  if (stepCount > 0) holdEveryStep(&out.wide, out.stepBounds, stepCount);
  return out;
}

void StaticAccel::build(const std::vector<glm::vec3>& positions,
                        const std::vector<uint32_t>& indices, const BuildOptions& options) {
  bvh_ = buildTriangleBvh(positions, indices, 0, options, "static geometry");
}

DynamicAccel::DynamicAccel(int width) : width_(width) {
  tlas_ = collapseBvh({makeNode(Aabb{}, 0, PR_BVH_LEAF_BIT)}, width_);
}

uint32_t DynamicAccel::addMesh(const std::vector<glm::vec3>& positions,
                               const std::vector<uint32_t>& indices, const BuildOptions& options) {
  return addMesh(positions, indices, nextPrimBase_, options);
}

uint32_t DynamicAccel::addMesh(const std::vector<glm::vec3>& positions,
                               const std::vector<uint32_t>& indices, uint32_t primBase,
                               const BuildOptions& options) {
  const std::string what = "dynamic mesh " + std::to_string(meshes_.size());
  BuildOptions o = options;
  o.width = width_;
  TriangleBvh bvh = buildTriangleBvh(positions, indices, primBase, o, what.c_str());
  Mesh m;
  m.rootNode = meshNodeCount();
  m.firstTriangle = uint32_t(meshTris_.size());
  m.triangleCount = uint32_t(bvh.triangles.size());
  m.primBase = primBase;
  m.bounds = bvh.bounds;
  m.stats = bvh.stats;
  parts_.push_back({bvh.wide.words, bvh.packets, bvh.triangles, 0, {}, {}});
  previous_.emplace_back();
  // Rebase to absolute indices in the concatenated buffers.
  meshMotion_.insert(meshMotion_.end(),
                     {uint32_t(meshPackets_.size()), uint32_t(bvh.packets.size()),
                      uint32_t(motionPacketCount_), 1u, m.rootNode, 0u, 0u, 0u});
  rebaseWide(bvh.wide.words, width_, m.rootNode, uint32_t(meshPackets_.size()));
  meshNodes_.insert(meshNodes_.end(), bvh.wide.words.begin(), bvh.wide.words.end());
  meshPackets_.insert(meshPackets_.end(), bvh.packets.begin(), bvh.packets.end());
  meshTris_.insert(meshTris_.end(), bvh.triangles.begin(), bvh.triangles.end());
  nextPrimBase_ = std::max(nextPrimBase_, primBase + m.triangleCount);
  meshes_.push_back(m);
  return uint32_t(meshes_.size() - 1);
}

void DynamicAccel::replaceMesh(uint32_t index, const std::vector<glm::vec3>& positions,
                               const std::vector<uint32_t>& indices, const BuildOptions& options,
                               const std::vector<std::vector<glm::vec3>>* steps) {
  PR_CHECK(index < meshes_.size());
  const std::string what = "dynamic mesh " + std::to_string(index);
  BuildOptions o = options;
  o.width = width_;
  Mesh& m = meshes_[index];
  // The old steps are read no more (the device has them): their memory goes to the new ones.
  parts_[index].stepCount = 0;
  parts_[index].steps = {};
  TriangleBvh bvh = buildTriangleBvh(positions, indices, m.primBase, o, what.c_str(), steps);
  m.triangleCount = uint32_t(bvh.triangles.size());
  m.bounds = bvh.bounds;
  m.stats = bvh.stats;
  previous_[index] = std::move(parts_[index]);
  previous_[index].stepBounds = {};  // only its tree is read (concatenate)
  parts_[index] = {std::move(bvh.wide.words),  std::move(bvh.packets),
                   std::move(bvh.triangles),   bvh.stepCount,
                   std::move(bvh.stepPackets), std::move(bvh.stepBounds)};
  concatenate();
}

std::vector<DynamicAccel::PacketRun> DynamicAccel::motionPacketRuns() const {
  std::vector<PacketRun> runs;
  for (const Part& p : parts_)
    if (!p.steps.empty()) runs.push_back({p.steps.data(), p.steps.size()});
  return runs;
}

void DynamicAccel::concatenate() {
  meshNodes_.clear();
  meshPackets_.clear();
  meshTris_.clear();
  motionPacketCount_ = 0;
  motionBounds_.clear();
  meshMotion_.assign(meshes_.size() * PR_MESH_MOTION_WORDS, 0u);
  for (size_t i = 0; i < meshes_.size(); ++i) {
    Mesh& m = meshes_[i];
    const Part& p = parts_[i];
    m.rootNode = meshNodeCount();
    m.firstTriangle = uint32_t(meshTris_.size());
    uint32_t* mm = &meshMotion_[i * PR_MESH_MOTION_WORDS];
    mm[0] = uint32_t(meshPackets_.size()), mm[1] = uint32_t(p.packets.size());
    mm[2] = uint32_t(motionPacketCount_);
    mm[3] = std::max<uint32_t>(p.stepCount, 1);
    mm[4] = m.rootNode;
    mm[5] = uint32_t(motionBounds_.size() / (6 * size_t(width_)));
    motionBounds_.insert(motionBounds_.end(), p.stepBounds.begin(), p.stepBounds.end());
    motionPacketCount_ += p.steps.size();
    std::vector<uint32_t> words = p.words;
    rebaseWide(words, width_, m.rootNode, uint32_t(meshPackets_.size()));
    meshNodes_.insert(meshNodes_.end(), words.begin(), words.end());
    meshPackets_.insert(meshPackets_.end(), p.packets.begin(), p.packets.end());
    meshTris_.insert(meshTris_.end(), p.triangles.begin(), p.triangles.end());
  }
  // The previous shapes after every mesh, so meshes' roots and triangle ranges do not move.
  for (size_t i = 0; i < meshes_.size(); ++i) {
    const Part& p = previous_[i];
    meshes_[i].previousRoot = PR_INVALID_INDEX;
    if (p.words.empty()) continue;
    meshes_[i].previousRoot = meshNodeCount();
    std::vector<uint32_t> words = p.words;
    rebaseWide(words, width_, meshes_[i].previousRoot, uint32_t(meshPackets_.size()));
    meshNodes_.insert(meshNodes_.end(), words.begin(), words.end());
    meshPackets_.insert(meshPackets_.end(), p.packets.begin(), p.packets.end());
  }
}

namespace {

// glm is column-major (m[col][row]); records are 3x4 row-major.
void store3x4(const glm::mat4& m, float* out) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out[4 * r + c] = m[c][r];
}

bool finite(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

}  // namespace

void DynamicAccel::setInstances(const std::vector<InstanceInput>& instances,
                                const std::vector<std::vector<glm::mat4>>& motion) {
  motionSteps_ = motion.empty() ? 1u : uint32_t(motion.front().size());
  if (!motion.empty() && (motion.size() != instances.size() || motionSteps_ < 2 ||
                          std::any_of(motion.begin(), motion.end(),
                                      [&](const auto& m) { return m.size() != motionSteps_; })))
    throw InputError("motion steps: not one count of at least 2 for each of " +
                     std::to_string(instances.size()) + " instances");
  motion_.assign(motion.empty() ? 0 : size_t(motionSteps_) * instances.size() * 12, 0.0f);
  for (size_t i = 0; i < motion.size(); ++i)
    for (uint32_t k = 0; k < motionSteps_; ++k)
      store3x4(motion[i][k], &motion_[(i * motionSteps_ + k) * 12]);
  worldBounds_.assign(instances.size(), Aabb{});
  std::vector<Aabb> boxes;
  std::vector<uint32_t> kept;
  std::vector<glm::mat4> inverses;
  for (size_t i = 0; i < instances.size(); ++i) {
    const InstanceInput& in = instances[i];
    if (in.mesh >= meshes_.size())
      throw InputError("instance " + std::to_string(i) + " refers to dynamic mesh " +
                       std::to_string(in.mesh) + " of " + std::to_string(meshes_.size()));
    const Mesh& mesh = meshes_[in.mesh];
    if (mesh.triangleCount == 0 || !finite(in.objectToWorld)) continue;
    const std::vector<glm::mat4> placements =
        motion.empty() ? std::vector<glm::mat4>{in.objectToWorld} : motion[i];
    if (!std::all_of(placements.begin(), placements.end(),
                     [](const glm::mat4& m) { return finite(m); }))
      continue;
    const float det = glm::determinant(glm::mat3(in.objectToWorld));
    const glm::mat4 inv = glm::inverse(in.objectToWorld);
    if (!(std::fabs(det) > 0.0f) || !finite(inv)) continue;
    Aabb box;
    for (const glm::mat4& m : placements) box.grow(mesh.bounds.transformed(m));
    // Rays are tested in object space; pad the world box by a few ulps of its coordinates so
    // the transform's rounding never culls a hit at the box's edge.
    const glm::vec3 pad = (glm::abs(box.lo) + glm::abs(box.hi)) * 1e-6f + 1e-30f;
    box.lo -= pad;
    box.hi += pad;
    worldBounds_[i] = box;
    boxes.push_back(box);
    kept.push_back(uint32_t(i));
    inverses.push_back(inv);
  }
  BuildOptions o;
  o.maxLeafSize = 1;  // leaf k of the wide tree is record k
  o.width = width_;
  Bvh bvh;
  tlas_ = buildWideBvh(boxes, o, &bvh);
  tlasStats_ = bvh.stats;
  records_.clear();
  records_.reserve(tlas_.leaves.size());
  for (const BinaryNode& leaf : tlas_.leaves) {
    PR_CHECK((leaf.meta & ~PR_BVH_LEAF_BIT) == 1u);  // leaf k is record k
    const uint32_t k = bvh.order[leaf.index];
    const uint32_t i = kept[k];
    const Mesh& mesh = meshes_[instances[i].mesh];
    dev::BvhInstance r{};
    store3x4(inverses[k], r.world_to_object);
    store3x4(instances[i].objectToWorld, r.object_to_world);
    r.root_node = mesh.rootNode;
    r.first_triangle = mesh.firstTriangle;
    r.mesh = instances[i].mesh;
    r.instance_id = i;
    records_.push_back(r);
  }
}

namespace {

std::vector<dev::BvhNode> toNodes(const std::vector<uint32_t>& words, int width) {
  if (width != PR_BVH_WIDTH)
    throw RuntimeError("HostGeom: BVH is " + std::to_string(width) + " wide, the CPU reference " +
                       std::to_string(PR_BVH_WIDTH));
  std::vector<dev::BvhNode> nodes(words.size() * 4 / sizeof(dev::BvhNode));
  if (!nodes.empty()) std::memcpy(nodes.data(), words.data(), nodes.size() * sizeof(dev::BvhNode));
  return nodes;
}

}  // namespace

HostGeom::HostGeom(const StaticAccel& ssg, const DynamicAccel* dsg) {
  staticNodes_ = toNodes(ssg.wide().words, ssg.wide().width);
  geom_.static_nodes = staticNodes_.data();
  geom_.static_tris = ssg.packets().data();
  geom_.motion_steps = 1;
  if (dsg) {
    tlasNodes_ = toNodes(dsg->tlas().words, dsg->width());
    meshNodes_ = toNodes(dsg->meshNodes(), dsg->width());
    geom_.tlas_nodes = tlasNodes_.data();
    geom_.instances = dsg->instances().data();
    geom_.mesh_nodes = meshNodes_.data();
    geom_.mesh_tris = dsg->meshPackets().data();
    geom_.instance_count = uint32_t(dsg->instances().size());
    geom_.motion = dsg->motion().empty() ? nullptr : dsg->motion().data();
    geom_.motion_steps = dsg->motionSteps();
    for (const DynamicAccel::PacketRun& run : dsg->motionPacketRuns())
      motionPackets_.insert(motionPackets_.end(), run.data, run.data + run.count);
    geom_.motion_tris = motionPackets_.empty() ? nullptr : motionPackets_.data();
    geom_.mesh_motion = dsg->meshMotion().empty() ? nullptr : dsg->meshMotion().data();
    geom_.motion_bounds = dsg->motionBounds().empty() ? nullptr : dsg->motionBounds().data();
  }
  geom_.time = 0.5f;
}

}  // namespace pr::accel
