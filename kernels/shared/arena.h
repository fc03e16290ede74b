// The path-record arena (docs/design.md section 4; the paper's PATH structure): a fixed number of
// light-path slots, each with a PathHeader and up to `stride` LightVertex records at
// slot * stride + k. Vertex 0 lies on the light. Normals are stored octahedron-encoded, and the
// light tracer spawns its rays from the decoded normals, so that invalidation can rebuild every
// segment's ray bit for bit from the stored record.
#pragma once

#include "shared/math.h"

PR_NAMESPACE_BEGIN

#define PR_END_ABSORBED 0u  // Russian roulette or a BSDF that gave no direction
#define PR_END_ESCAPED 1u   // the last ray left the scene (escape_* holds its direction)
#define PR_END_MAX_DEPTH 2u
// PathHeader.valid of a path that meets what moves while the shutter is open, traced at its own
// time in the interval (light_path_time): this frame's alone.
#define PR_PATH_TIMED 2u

// 32 bytes.
typedef struct {
  u32 light;         // index in the light table
  u32 generation;    // RNG key part: re-tracing with the same generation reproduces the path
  u32 vertex_count;  // stored vertices, vertex 0 (on the light) included; 0 = none
  u32 end;           // PR_END_*
  u32 valid;         // 1: the stored path is what tracing would give now; PR_PATH_TIMED
  float escape_x, escape_y, escape_z;  // direction of the escaping last ray (PR_END_ESCAPED)
} PathHeader;

// 64 bytes.
typedef struct {
  float px, py, pz;
  float t;           // distance along the arriving ray (unit direction) from the previous vertex
  float wx, wy, wz;  // unit direction of the arriving ray (from the previous vertex)
  u32 ng_oct;        // geometric normal, octahedron-encoded (for the light: emission side)
  float tp_r, tp_g, tp_b;  // throughput of the light sub-path arriving at this vertex
  u32 ns_oct;              // shading normal, same side as ng
  u32 prim;                // shading triangle (PR_INVALID_INDEX for punctual lights)
  u32 inst;                // DSG instance, PR_INVALID_INDEX on the SSG
  float b1, b2;            // barycentrics on prim (uv and material come from them)
} LightVertex;

// The first non-delta eye vertex of a pixel sample, written by eye_hit for connect. 64 bytes.
typedef struct {
  float px, py, pz;
  u32 ng_oct;
  float wx, wy, wz;  // unit direction towards the previous eye vertex (wo)
  u32 ns_oct;
  float tp_r, tp_g, tp_b;  // camera weight times the delta chain's weights
  u32 depth;               // surface vertices on the eye path so far, this one included
  u32 prim;                // PR_INVALID_INDEX: no vertex (escaped, absorbed or too deep)
  u32 inst;
  float b1, b2;
} EyeVertex;

// --eye-paths: what L's weight against the eye path needs of stored light vertex z_k, k >= 1,
// kept beside it (the same index) by light_trace, so that connect needs no walk along the path
// (shared/eye_paths.h, eye_path_walk_arrive). 8 bytes.
typedef struct {
  float n;  // N's density of the path over L's, but for the factors connect adds
  float h;  // the same for H
} EyePathRatio;

// A pixel sample's connection history (--connection-history; kernels/reuse/connect.cl), carried
// from one frame to the next: the first eye vertex its reservoir was last resampled at (rebuilt
// with surface_at), the light vertex it keeps and its weights. 64 bytes.
typedef struct {
  u32 prim, inst;
  float b1, b2;
  float wx, wy, wz;  // towards the previous eye vertex
  float tp_r, tp_g, tp_b;
  u32 depth_k;  // the eye vertex's depth | the kept light vertex's depth k << 16
  u32 slot;     // the kept light vertex's slot; PR_INVALID_INDEX: none
  float p;      // its target value at that eye vertex
  float w;      // its unbiased contribution weight
  float m;      // the candidates the reservoir stands for (its confidence)
  u32 frame;    // the frame (counted from 1 by the renderer) that wrote it; 0: never written
} ConnectionHistory;

// Octahedral normal encoding, two 16-bit fixed-point coordinates (Cigolle et al., JCGT 2014).
PR_INLINE float pr_sign_nz(float v) {
  return v >= 0.0f ? 1.0f : -1.0f;
}

PR_INLINE u32 oct_encode(float3 n) {
  const float l1 = fabs(n.x) + fabs(n.y) + fabs(n.z);
  float px = l1 > 0.0f ? n.x / l1 : 0.0f, py = l1 > 0.0f ? n.y / l1 : 0.0f;
  if (n.z < 0.0f) {
    const float ox = (1.0f - fabs(py)) * pr_sign_nz(px), oy = (1.0f - fabs(px)) * pr_sign_nz(py);
    px = ox;
    py = oy;
  }
  const i32 qx = (i32)floor(clamp(px, -1.0f, 1.0f) * 32767.0f + 0.5f);
  const i32 qy = (i32)floor(clamp(py, -1.0f, 1.0f) * 32767.0f + 0.5f);
  return ((u32)(qx & 0xffff)) | ((u32)(qy & 0xffff) << 16);
}

PR_INLINE float3 oct_decode(u32 e) {
  // Sign-extend the two 16-bit halves.
  const i32 qx = (i32)(e << 16) >> 16, qy = (i32)e >> 16;
  const float px = (float)qx / 32767.0f, py = (float)qy / 32767.0f;
  float3 n = make_float3(px, py, 1.0f - fabs(px) - fabs(py));
  if (n.z < 0.0f) {
    const float ox = (1.0f - fabs(py)) * pr_sign_nz(px), oy = (1.0f - fabs(px)) * pr_sign_nz(py);
    n.x = ox;
    n.y = oy;
  }
  return normalize(n);
}

PR_NAMESPACE_END

PR_STATIC_ASSERT(sizeof(pr::dev::PathHeader) == 32, "PathHeader layout");
PR_STATIC_ASSERT(offsetof(pr::dev::PathHeader, escape_x) == 20, "PathHeader layout");
PR_STATIC_ASSERT(sizeof(pr::dev::LightVertex) == 64, "LightVertex layout");
PR_STATIC_ASSERT(offsetof(pr::dev::LightVertex, tp_r) == 32, "LightVertex layout");
PR_STATIC_ASSERT(offsetof(pr::dev::LightVertex, prim) == 48, "LightVertex layout");
PR_STATIC_ASSERT(offsetof(pr::dev::LightVertex, b2) == 60, "LightVertex layout");
PR_STATIC_ASSERT(sizeof(pr::dev::EyeVertex) == 64, "EyeVertex layout");
PR_STATIC_ASSERT(offsetof(pr::dev::EyeVertex, depth) == 44, "EyeVertex layout");
PR_STATIC_ASSERT(sizeof(pr::dev::EyePathRatio) == 8, "EyePathRatio layout");
PR_STATIC_ASSERT(sizeof(pr::dev::ConnectionHistory) == 64, "ConnectionHistory layout");
PR_STATIC_ASSERT(offsetof(pr::dev::ConnectionHistory, frame) == 60, "ConnectionHistory layout");
