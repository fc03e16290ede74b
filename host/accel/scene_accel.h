// The host side of the scene's acceleration structures (docs/design.md section 3): the SSG's BVH,
// built once over world-space static triangles, and the DSG's two levels: one object-space BVH
// per dynamic mesh, built once, and a top-level BVH over this frame's instances.
// Triangles come as plain arrays: positions and 3 indices per triangle.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "accel/bvh_builder.h"
#include "shared/bvh.h"
#include "shared/types.h"
#include "util/default_init.h"

namespace pr::accel {

// Triangle (a, b, c) packed for intersection, reporting `prim` on a hit.
dev::BvhTriangle packTriangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                              uint32_t prim);
// True when the packed triangle has exactly zero area (cross(e1, e2) == 0).
bool zeroArea(const dev::BvhTriangle& t);

// A BVH over one triangle soup: wide nodes (root at 0, indices relative to this BVH) whose
// leaf k is packets[k], each triangle keeping primBase + its index in the input. `binary` and
// `triangles` (in the binary tree's leaf order) are the tree it was collapsed from, kept on the
// host for statistics and tests.
// Written whole where it is made, so never zeroed first.
using StepPackets = std::vector<dev::BvhTriPacket, DefaultInitAllocator<dev::BvhTriPacket>>;

struct TriangleBvh {
  WideBvh wide;
  std::vector<dev::BvhTriPacket> packets;
  // With motion steps: the packets at each step, leaf by leaf with a leaf's steps side by side
  // (leaf j at step k is stepPackets[j * stepCount + k], the kernels' layout: a blend reads two
  // neighbours), and the wide nodes' child boxes refitted to each step (node by node, its steps
  // side by side, 6 * width floats each as BvhNode.bounds): a box blended between two steps
  // holds the blended triangles.
  uint32_t stepCount = 0;
  StepPackets stepPackets;
  std::vector<float> stepBounds;
  std::vector<BinaryNode> binary;
  std::vector<dev::BvhTriangle> triangles;
  Aabb bounds;
  BvhStats stats;
};

// The packet of triangles [first, first + count) (count <= PR_BVH_PACKET; unused lanes never hit).
dev::BvhTriPacket packTriangles(const dev::BvhTriangle* first, uint32_t count);

// Triangles whose edge cross product is exactly zero (points, repeated vertices) are left out:
// they have no surface, and Moller-Trumbore's rounding could report stray hits on them.
// Throws InputError (naming `what`) on an index out of range, a non-finite position or an
// index count that is not a multiple of 3.
// With `steps` (the positions at each motion step, kernels/shared/motion.h), the tree is built on
// the triangles at `positions` (the frame's time, the middle step) and its node boxes then hold
// every step; stepPackets and stepBounds hold each step's, and `bounds` the mesh over all steps.
// (Built on boxes over every step, a limb's sweep made SAH trees too deep for the traversal
// stack: BrainStem over a second took 48 builds a frame, 1.6-2.6 s, against 5 now.)
TriangleBvh buildTriangleBvh(const std::vector<glm::vec3>& positions,
                             const std::vector<uint32_t>& indices, uint32_t primBase,
                             const BuildOptions& options, const char* what,
                             const std::vector<std::vector<glm::vec3>>* steps = nullptr);

// SSG: hits report prim = the triangle's index in the input (indices[3*prim ...]).
class StaticAccel {
 public:
  void build(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
             const BuildOptions& options = {});

  // The device's layout: wide nodes and leaf packets.
  const WideBvh& wide() const { return bvh_.wide; }
  const std::vector<dev::BvhTriPacket>& packets() const { return bvh_.packets; }
  // The binary tree it was collapsed from and its triangles in leaf order.
  const std::vector<BinaryNode>& nodes() const { return bvh_.binary; }
  const std::vector<dev::BvhTriangle>& triangles() const { return bvh_.triangles; }
  const BvhStats& stats() const { return bvh_.stats; }
  const Aabb& bounds() const { return bvh_.bounds; }

 private:
  TriangleBvh bvh_ = buildTriangleBvh({}, {}, 0, BuildOptions{}, "static geometry");
};

// One instance of a dynamic mesh this frame.
struct InstanceInput {
  uint32_t mesh = 0;
  glm::mat4 objectToWorld{1.0f};
};

// DSG. Hits report inst = the instance's index in setInstances' list and prim = the mesh's
// primBase + the triangle's index in that mesh.
class DynamicAccel {
 public:
  // Nodes `width` wide (PR_BVH_WIDTH: the layout this host's CPU reference traverses).
  explicit DynamicAccel(int width = PR_BVH_WIDTH);

  // Builds the mesh's object-space BVH (once). primBase defaults to the number of triangles of
  // the meshes added before, so prim is the index in the concatenation of all meshes' lists.
  uint32_t addMesh(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                   const BuildOptions& options = {});
  uint32_t addMesh(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                   uint32_t primBase, const BuildOptions& options = {});

  // Builds mesh m's BVH again over new vertex positions (a deforming mesh: same triangles, same
  // prim numbers). The concatenated arrays are rebuilt; setInstances must follow. The BVH it
  // replaces stays in meshNodes() (previousRoot), for what tests a segment against the shape the
  // mesh had in the previous frame; no instance refers to it.
  // With `steps` (its positions at each motion step) it deforms under a shutter.
  void replaceMesh(uint32_t m, const std::vector<glm::vec3>& positions,
                   const std::vector<uint32_t>& indices, const BuildOptions& options = {},
                   const std::vector<std::vector<glm::vec3>>* steps = nullptr);

  // This frame: world bounds of every instance and the top-level BVH over them. Instances of
  // empty meshes or with a singular or non-finite transform cannot be hit and are left out.
  // With `motion` (--shutter: per instance, its transforms at the motion steps, all as many;
  // kernels/shared/motion.h) each box holds its instance at every step. Throws InputError on a
  // mesh index out of range, or on motion not of one step count per instance.
  void setInstances(const std::vector<InstanceInput>& instances,
                    const std::vector<std::vector<glm::mat4>>& motion = {});

  uint32_t meshCount() const { return uint32_t(meshes_.size()); }
  // Mesh m's BVH root in meshNodes().
  uint32_t meshRoot(uint32_t m) const { return meshes_[m].rootNode; }
  // The root of mesh m's BVH before the last replaceMesh (PR_INVALID_INDEX: never replaced).
  uint32_t previousRoot(uint32_t m) const { return meshes_[m].previousRoot; }
  uint32_t meshTriangleCount() const { return uint32_t(meshTris_.size()); }
  int width() const { return width_; }
  // All meshes' wide BVHs concatenated, with absolute node and packet references.
  const std::vector<uint32_t>& meshNodes() const { return meshNodes_; }
  const std::vector<dev::BvhTriPacket>& meshPackets() const { return meshPackets_; }
  // All meshes' triangles in their binary trees' leaf order (host only: tests, statistics).
  const std::vector<dev::BvhTriangle>& meshTriangles() const { return meshTris_; }
  uint32_t meshNodeCount() const { return uint32_t(meshNodes_.size() / wideNodeWords(width_)); }
  // This frame's wide TLAS (root at 0); leaf k is instance record k.
  const WideBvh& tlas() const { return tlas_; }
  const std::vector<dev::BvhInstance>& instances() const { return records_; }
  const BvhStats& tlasStats() const { return tlasStats_; }
  // World bounds of instance i of the last setInstances (empty when left out).
  const std::vector<Aabb>& instanceBounds() const { return worldBounds_; }
  // Motion steps of every instance (1: none) and their transforms, 12 floats each (3x4 rows),
  // instance by instance (kernels/shared/motion.h).
  uint32_t motionSteps() const { return motionSteps_; }
  const std::vector<float>& motion() const { return motion_; }
  // Deforming meshes' packets and node boxes at their motion steps, and per mesh
  // PR_MESH_MOTION_WORDS words (SceneGeom.mesh_motion). The packets stay where each mesh's were
  // built (hundreds of MB on a skinned character): motionPacketRuns gives them mesh by mesh, to
  // be laid end to end.
  struct PacketRun {
    const dev::BvhTriPacket* data;
    size_t count;
  };
  std::vector<PacketRun> motionPacketRuns() const;
  uint64_t motionPacketCount() const { return motionPacketCount_; }
  const std::vector<float>& motionBounds() const { return motionBounds_; }
  const std::vector<uint32_t>& meshMotion() const { return meshMotion_; }

 private:
  struct Mesh {
    uint32_t rootNode = 0, firstTriangle = 0, triangleCount = 0, primBase = 0;
    uint32_t previousRoot = PR_INVALID_INDEX;
    Aabb bounds;
    BvhStats stats;
  };
  // One mesh's BVH with mesh-relative references, kept to concatenate again.
  struct Part {
    std::vector<uint32_t> words;
    std::vector<dev::BvhTriPacket> packets;
    std::vector<dev::BvhTriangle> triangles;
    uint32_t stepCount = 0;  // under a shutter (replaceMesh): TriangleBvh's step parts
    StepPackets steps;
    std::vector<float> stepBounds;
  };
  void concatenate();
  int width_;
  std::vector<Mesh> meshes_;
  std::vector<Part> parts_;
  std::vector<Part> previous_;  // per mesh: its BVH before the last replaceMesh (empty: none)
  uint32_t nextPrimBase_ = 0;
  std::vector<uint32_t> meshNodes_;
  std::vector<dev::BvhTriPacket> meshPackets_;
  std::vector<dev::BvhTriangle> meshTris_;
  WideBvh tlas_;
  std::vector<dev::BvhInstance> records_;
  std::vector<Aabb> worldBounds_;
  BvhStats tlasStats_;
  uint32_t motionSteps_ = 1;
  std::vector<float> motion_;
  uint64_t motionPacketCount_ = 0;
  std::vector<float> motionBounds_;
  std::vector<uint32_t> meshMotion_;
};

// The CPU reference's view of both structures (kernels/shared/bvh.h compiled for the host), for
// tests and tools: the wide nodes copied into BvhNode arrays. Needs BVHs PR_BVH_WIDTH wide;
// made again after each setInstances.
class HostGeom {
 public:
  explicit HostGeom(const StaticAccel& ssg, const DynamicAccel* dsg = nullptr);
  HostGeom(const HostGeom&) = delete;
  HostGeom& operator=(const HostGeom&) = delete;
  const dev::SceneGeom& geom() const { return geom_; }

 private:
  std::vector<dev::BvhNode> staticNodes_, tlasNodes_, meshNodes_;
  std::vector<dev::BvhTriPacket> motionPackets_;  // the DSG's runs laid end to end
  dev::SceneGeom geom_{};
};

}  // namespace pr::accel
