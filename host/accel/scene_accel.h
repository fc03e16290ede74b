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
#include "shared/types.h"

namespace pr::accel {

// Triangle (a, b, c) packed for intersection, reporting `prim` on a hit.
dev::BvhTriangle packTriangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                              uint32_t prim);
// True when the packed triangle has exactly zero area (cross(e1, e2) == 0).
bool zeroArea(const dev::BvhTriangle& t);

// A BVH over one triangle soup, flattened: nodes (root at 0, indices relative to this BVH)
// and the triangles in leaf order, each keeping primBase + its index in the input.
struct TriangleBvh {
  std::vector<dev::BvhNode> nodes;
  std::vector<dev::BvhTriangle> triangles;
  Aabb bounds;
  BvhStats stats;
};

// Triangles whose edge cross product is exactly zero (points, repeated vertices) are left out:
// they have no surface, and Moller-Trumbore's rounding could report stray hits on them.
// Throws InputError (naming `what`) on an index out of range, a non-finite position or an
// index count that is not a multiple of 3.
TriangleBvh buildTriangleBvh(const std::vector<glm::vec3>& positions,
                             const std::vector<uint32_t>& indices, uint32_t primBase,
                             const BuildOptions& options, const char* what);

// SSG: hits report prim = the triangle's index in the input (indices[3*prim ...]).
class StaticAccel {
 public:
  void build(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
             const BuildOptions& options = {});

  const std::vector<dev::BvhNode>& nodes() const { return bvh_.nodes; }
  const std::vector<dev::BvhTriangle>& triangles() const { return bvh_.triangles; }
  const BvhStats& stats() const { return bvh_.stats; }
  const Aabb& bounds() const { return bvh_.bounds; }

 private:
  TriangleBvh bvh_{{makeNode(Aabb{}, 0, PR_BVH_LEAF_BIT)}, {}, {}, {}};
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
  // Builds the mesh's object-space BVH (once). primBase defaults to the number of triangles of
  // the meshes added before, so prim is the index in the concatenation of all meshes' lists.
  uint32_t addMesh(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                   const BuildOptions& options = {});
  uint32_t addMesh(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                   uint32_t primBase, const BuildOptions& options = {});

  // This frame: world bounds of every instance and the top-level BVH over them. Instances of
  // empty meshes or with a singular or non-finite transform cannot be hit and are left out.
  // Throws InputError on a mesh index out of range.
  void setInstances(const std::vector<InstanceInput>& instances);

  uint32_t meshCount() const { return uint32_t(meshes_.size()); }
  uint32_t meshTriangleCount() const { return uint32_t(meshTris_.size()); }
  // All meshes' BVHs concatenated, with absolute child and triangle indices.
  const std::vector<dev::BvhNode>& meshNodes() const { return meshNodes_; }
  const std::vector<dev::BvhTriangle>& meshTriangles() const { return meshTris_; }
  // This frame's TLAS (root at 0) and instance records in its leaf order.
  const std::vector<dev::BvhNode>& tlasNodes() const { return tlas_; }
  const std::vector<dev::BvhInstance>& instances() const { return records_; }
  const BvhStats& tlasStats() const { return tlasStats_; }
  // World bounds of instance i of the last setInstances (empty when left out).
  const std::vector<Aabb>& instanceBounds() const { return worldBounds_; }

 private:
  struct Mesh {
    uint32_t rootNode = 0, firstTriangle = 0, triangleCount = 0, primBase = 0;
    Aabb bounds;
    BvhStats stats;
  };
  std::vector<Mesh> meshes_;
  uint32_t nextPrimBase_ = 0;
  std::vector<dev::BvhNode> meshNodes_;
  std::vector<dev::BvhTriangle> meshTris_;
  std::vector<dev::BvhNode> tlas_{makeNode(Aabb{}, 0, PR_BVH_LEAF_BIT)};
  std::vector<dev::BvhInstance> records_;
  std::vector<Aabb> worldBounds_;
  BvhStats tlasStats_;
};

}  // namespace pr::accel
