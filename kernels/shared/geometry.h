// Shading data of the scene's triangles, separate from the BVHs' intersection layout: vertex
// attributes and per-triangle vertex indices and material. SSG vertices are in world space;
// DSG mesh vertices in object space, placed each frame by their instance's transforms.
#pragma once

#include "shared/common.h"

PR_NAMESPACE_BEGIN

// 56 bytes.
typedef struct {
  float px, py, pz;
  float nx, ny, nz;
  float u, v;        // TEXCOORD_0
  float u1, v1;      // TEXCOORD_1 (TEXCOORD_0 where absent)
  float tx, ty, tz;  // tangent (normal maps): loaded, or generated from the normal map's uvs
  float tw;          // bitangent sign: b = tw cross(n, t)
} ShadingVertex;

// Absolute vertex indices into the one vertex array. 16 bytes.
typedef struct {
  u32 v0, v1, v2;
  u32 material;
} ShadingTriangle;

// One DSG instance this frame, indexed by instance id (Hit.inst). Matrices 3x4 row-major.
// 112 bytes.
typedef struct {
  float object_to_world[12];
  float world_to_object[12];
  u32 first_triangle;  // the instance's mesh's first triangle in the shading triangle array
  u32 mesh;
  u32 moved;        // transform changed since the previous frame (for invalidation)
  u32 first_light;  // the light of the instance's first emissive triangle
} ShadingInstance;

PR_NAMESPACE_END

PR_STATIC_ASSERT(sizeof(pr::dev::ShadingVertex) == 56, "ShadingVertex layout");
PR_STATIC_ASSERT(sizeof(pr::dev::ShadingTriangle) == 16, "ShadingTriangle layout");
PR_STATIC_ASSERT(sizeof(pr::dev::ShadingInstance) == 112, "ShadingInstance layout");
PR_STATIC_ASSERT(offsetof(pr::dev::ShadingInstance, first_triangle) == 96,
                 "ShadingInstance layout");
