// From a ray hit to what shading needs: the surface point, its normals and uv, its material's
// BSDF parameters, emission and coverage (with textures).
#pragma once

#include "shared/bsdf.h"
#include "shared/geometry.h"
#include "shared/material.h"
#include "shared/math.h"
#include "shared/motion.h"
#include "shared/rng.h"
#include "shared/srgb.h"
#include "shared/types.h"

PR_NAMESPACE_BEGIN

// Device buffers for shading; built in the kernel from its arguments (PR_ARGS_SHADING).
typedef struct {
  PR_GLOBAL const ShadingVertex* vertices;
  PR_GLOBAL const ShadingTriangle* triangles;
  PR_GLOBAL const ShadingInstance* instances;  // by instance id
  PR_GLOBAL const Material* materials;
  PR_GLOBAL const TextureInfo* textures;
  PR_GLOBAL const u32* texels;    // RGBA8
  PR_GLOBAL const float* motion;  // --shutter, as SceneGeom's
  u32 motion_steps;
  float time;
  // Deforming meshes under a shutter: their vertices at each step, and per dynamic mesh 4 words
  // (its first vertex, vertex count, its steps' first vertex here, its steps; 1: none).
  PR_GLOBAL const ShadingVertex* motion_vertices;
  PR_GLOBAL const u32* vertex_motion;
} ShadingData;

typedef struct {
  float3 p;    // world position
  float3 ng;   // unit geometric normal (winding order), world space
  float3 ns;   // unit shading normal, on the same side as ng
  float2 uv;   // TEXCOORD_0
  float2 uv1;  // TEXCOORD_1
  u32 material;
  u32 prim;      // shading triangle index
  u32 inst;      // PR_INVALID_INDEX on the SSG
  float b1, b2;  // barycentrics of v1 and v2 (surface_lift, for rays that leave the surface)
} SurfaceHit;

PR_INLINE float3 xform_point12(PR_GLOBAL const float* m, float3 p) {
  return make_float3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3],
                     m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                     m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

// DSG instance inst's transforms at the path's time (this frame's where there is no motion blur).
PR_INLINE void instance_transforms(const ShadingData* sd, u32 inst, Affine* o2w, Affine* w2o) {
  if (sd->motion_steps > 1u) {
    motion_transform(sd->motion, sd->motion_steps, inst, sd->time, o2w, w2o);
    return;
  }
  affine_load(sd->instances[inst].object_to_world, o2w);
  affine_load(sd->instances[inst].world_to_object, w2o);
}

// Vertex v of a triangle of instance inst (PR_INVALID_INDEX: the SSG) at the path's time: a
// deforming mesh's is the blend of its two motion steps around it.
PR_INLINE ShadingVertex vertex_at(const ShadingData* sd, u32 inst, u32 v) {
  if (sd->motion_steps <= 1u || inst == PR_INVALID_INDEX) return sd->vertices[v];
  PR_GLOBAL const u32* vm = sd->vertex_motion + 4u * sd->instances[inst].mesh;
  if (vm[3] <= 1u) return sd->vertices[v];
  float a;
  const u32 k = motion_step(vm[3], sd->time, &a);
  PR_GLOBAL const ShadingVertex* s0 = sd->motion_vertices + vm[2] + (size_t)k * vm[1] + (v - vm[0]);
  const ShadingVertex v0 = s0[0], v1 = s0[vm[1]];
  ShadingVertex x = v0;
  x.px += (v1.px - v0.px) * a, x.py += (v1.py - v0.py) * a, x.pz += (v1.pz - v0.pz) * a;
  x.nx += (v1.nx - v0.nx) * a, x.ny += (v1.ny - v0.ny) * a, x.nz += (v1.nz - v0.nz) * a;
  x.tx += (v1.tx - v0.tx) * a, x.ty += (v1.ty - v0.ty) * a, x.tz += (v1.tz - v0.tz) * a;
  return x;
}

// The three vertices of triangle tri of instance inst, at the path's time.
PR_INLINE void triangle_vertices(const ShadingData* sd, ShadingTriangle tri, u32 inst,
                                 ShadingVertex* a, ShadingVertex* b, ShadingVertex* c) {
  *a = vertex_at(sd, inst, tri.v0);
  *b = vertex_at(sd, inst, tri.v1);
  *c = vertex_at(sd, inst, tri.v2);
}

// A DSG triangle's corners placed by instance inst; *w2o, for its normals.
PR_INLINE void place_corners(const ShadingData* sd, u32 inst, float3* pa, float3* pb, float3* pc,
                             Affine* w2o) {
  Affine o2w;
  instance_transforms(sd, inst, &o2w, w2o);
  *pa = affine_point(&o2w, *pa);
  *pb = affine_point(&o2w, *pb);
  *pc = affine_point(&o2w, *pc);
}

// The world-space corners of a surface's triangle: v0 and the edges to v1 and v2.
PR_INLINE void triangle_world(const ShadingData* sd, u32 prim, u32 inst, float3* v0, float3* e1,
                              float3* e2) {
  const ShadingTriangle tri = sd->triangles[prim];
  ShadingVertex a, b, c;
  triangle_vertices(sd, tri, inst, &a, &b, &c);
  float3 pa = make_float3(a.px, a.py, a.pz), pb = make_float3(b.px, b.py, b.pz),
         pc = make_float3(c.px, c.py, c.pz);
  if (inst != PR_INVALID_INDEX) {
    Affine w2o;
    place_corners(sd, inst, &pa, &pb, &pc, &w2o);
  }
  *v0 = pa;
  *e1 = pb - pa;
  *e2 = pc - pa;
}

PR_INLINE int wrap_texel(int i, int n, u32 mode) {
  if (mode == 1u) return i < 0 ? 0 : (i >= n ? n - 1 : i);
  if (mode == 2u) {
    const int period = 2 * n;
    int m = i % period;
    if (m < 0) m += period;
    return m < n ? m : period - 1 - m;
  }
  int m = i % n;
  return m < 0 ? m + n : m;
}

PR_INLINE float4 texel_at(const ShadingData* sd, TextureInfo t, int x, int y) {
  const u32 w = sd->texels[t.offset + (u32)y * t.width + (u32)x];
  const u32 r = w & 255u, g = (w >> 8) & 255u, b = (w >> 16) & 255u, a = w >> 24;
  if (t.flags & PR_TEX_SRGB)
    return make_float4(pr_srgb_to_linear[r], pr_srgb_to_linear[g], pr_srgb_to_linear[b],
                       (float)a * (1.0f / 255.0f));
  return make_float4((float)r, (float)g, (float)b, (float)a) * (1.0f / 255.0f);
}

// Bilinear (or nearest) lookup with the texture's wrap modes; linear RGBA.
PR_CALLABLE float4 texture_sample(const ShadingData* sd, i32 index, float2 uv) {
  const TextureInfo t = sd->textures[index];
  const u32 ws = (t.flags >> PR_TEX_WRAP_S_SHIFT) & 3u, wt = (t.flags >> PR_TEX_WRAP_T_SHIFT) & 3u;
  const float fx = uv.x * (float)t.width - 0.5f, fy = uv.y * (float)t.height - 0.5f;
  if (!isfinite_f(fx) || !isfinite_f(fy)) return texel_at(sd, t, 0, 0);
  // Keep the integer part in range before converting (huge uvs are legal glTF).
  const float x0f = floor(fx), y0f = floor(fy);
  const float big = 1048576.0f;
  const int x0 = (int)clamp(x0f, -big, big), y0 = (int)clamp(y0f, -big, big);
  if (t.flags & PR_TEX_NEAREST) {
    return texel_at(
        sd, t, wrap_texel((int)clamp(floor(uv.x * (float)t.width), -big, big), (int)t.width, ws),
        wrap_texel((int)clamp(floor(uv.y * (float)t.height), -big, big), (int)t.height, wt));
  }
  const float ax = fx - x0f, ay = fy - y0f;
  const int xa = wrap_texel(x0, (int)t.width, ws), xb = wrap_texel(x0 + 1, (int)t.width, ws);
  const int ya = wrap_texel(y0, (int)t.height, wt), yb = wrap_texel(y0 + 1, (int)t.height, wt);
  const float4 c00 = texel_at(sd, t, xa, ya), c10 = texel_at(sd, t, xb, ya);
  const float4 c01 = texel_at(sd, t, xa, yb), c11 = texel_at(sd, t, xb, yb);
  return (c00 * (1.0f - ax) + c10 * ax) * (1.0f - ay) + (c01 * (1.0f - ax) + c11 * ax) * ay;
}

// A texture's coordinates under its KHR_texture_transform matrix m (2x3, rows first).
PR_INLINE float2 texture_uv(PR_GLOBAL const float* m, float2 uv) {
  return make_float2(m[0] * uv.x + m[1] * uv.y + m[2], m[3] * uv.x + m[4] * uv.y + m[5]);
}

// A texture's coordinates at the surface: its uv set (bit `set` of the material's uv_sets
// chooses TEXCOORD_1) under its transform xf.
PR_INLINE float2 material_uv(PR_GLOBAL const Material* m, u32 set, PR_GLOBAL const float* xf,
                             float2 uv0, float2 uv1) {
  return texture_uv(xf, (m->uv_sets & set) ? uv1 : uv0);
}

// A glTF normal map's normal: the texel's tangent-space normal, x and y scaled, in the frame
// of the unit interpolated normal n, the tangent t made orthogonal to it and b = tw cross(n, t).
// n itself where the tangent is degenerate or the mapped normal would cross the geometric
// surface (ng) to the other side than n.
PR_INLINE float3 normal_mapped(const ShadingData* sd, i32 texture, float scale, float2 uv, float3 n,
                               float3 t, float tw, float3 ng) {
  const float4 c = texture_sample(sd, texture, uv);
  const float3 tn =
      make_float3((2.0f * c.x - 1.0f) * scale, (2.0f * c.y - 1.0f) * scale, 2.0f * c.z - 1.0f);
  const float3 to = t - n * dot(n, t);
  const float tl = length(to);
  if (!(tl > 1e-6f) || !isfinite_f(tl)) return n;
  const float3 tu = to / tl;
  const float3 b = cross(n, tu) * (tw < 0.0f ? -1.0f : 1.0f);
  const float3 p = tu * tn.x + b * tn.y + n * tn.z;
  const float pl = length(p);
  if (!(pl > 0.0f) || !isfinite_f(pl)) return n;
  const float3 r = p / pl;
  return dot(r, ng) * dot(n, ng) > 0.0f ? r : n;
}

// One corner's share of surface_lift: p (world space) moved onto the tangent plane of a vertex
// at pv with normal nv where p lies below it, times the barycentric b. Zero for a vertex normal
// that faces away from the interpolated normal n, and where p lies less than about a hundred
// ulps of its coordinates below the plane (round-off on a flat triangle; rays leave a surface
// by 256 ulps anyway).
PR_INLINE float3 lift_to_tangent_plane(float3 pv, float3 nv, float3 p, float b, float3 n) {
  const float h = dot(pv - p, nv);  // times |nv|
  const float scale = fmax(fmax(fabs(p.x), fabs(p.y)), fmax(fabs(p.z), 1.0f / 32.0f));
  if (!(h > 1e-5f * scale * length(nv)) || !(dot(nv, n) > 0.0f))
    return make_float3(0.0f, 0.0f, 0.0f);
  return nv * (b * h / dot(nv, nv));
}

// The shadow-terminator offset at barycentrics (b1, b2) of a triangle (Hanika 2021, "Hacking the
// shadow terminator", Ray Tracing Gems II ch. 4): the point projected onto the tangent plane of
// each vertex it lies below, the projections blended by the barycentrics, as an offset from the
// point (world space). It lifts the point of a coarse, smooth-shaded convex facet to about
// where the surface its normals describe would be, so that rays leaving there are not shadowed
// by the neighbouring facets where that surface would not be; zero on flat and concave parts
// (the point lies on or above every tangent plane), and at most the triangle's size. Rays use it
// through the integrator's ray_exit (shared/transport.h), which computes it only for the rays
// it can move.

PR_INLINE float3 surface_lift(const ShadingData* sd, u32 prim, u32 inst, float b1, float b2) {
  const ShadingTriangle tri = sd->triangles[prim];
  ShadingVertex a, b, c;
  triangle_vertices(sd, tri, inst, &a, &b, &c);
  const float b0 = 1.0f - b1 - b2;
  float3 pa = make_float3(a.px, a.py, a.pz), pb = make_float3(b.px, b.py, b.pz),
         pc = make_float3(c.px, c.py, c.pz);
  float3 na = make_float3(a.nx, a.ny, a.nz), nb = make_float3(b.nx, b.ny, b.nz),
         nc = make_float3(c.nx, c.ny, c.nz);
  // A flat-shaded triangle (one normal at every corner) has none.
  if (a.nx == b.nx && a.ny == b.ny && a.nz == b.nz && a.nx == c.nx && a.ny == c.ny && a.nz == c.nz)
    return make_float3(0.0f, 0.0f, 0.0f);
  if (inst != PR_INVALID_INDEX) {
    Affine w2o;
    place_corners(sd, inst, &pa, &pb, &pc, &w2o);
    na = affine_normal(&w2o, na);
    nb = affine_normal(&w2o, nb);
    nc = affine_normal(&w2o, nc);
  }
  const float3 p = pa * b0 + pb * b1 + pc * b2;
  const float3 n = na * b0 + nb * b1 + nc * b2;
  const float3 l = lift_to_tangent_plane(pa, na, p, b0, n) +
                   lift_to_tangent_plane(pb, nb, p, b1, n) +
                   lift_to_tangent_plane(pc, nc, p, b2, n);
  return isfinite_f(l.x + l.y + l.z) ? l : make_float3(0.0f, 0.0f, 0.0f);
}

// The interpolated vertex tangent at the surface (world space, not normalised, zero where the
// mesh has none) and in *tw the bitangent's sign: b = tw cross(n, t).
PR_INLINE float3 surface_tangent(const ShadingData* sd, const SurfaceHit* s, float* tw) {
  const ShadingTriangle tri = sd->triangles[s->prim];
  ShadingVertex a, b, c;
  triangle_vertices(sd, tri, s->inst, &a, &b, &c);
  float3 t = make_float3(a.tx, a.ty, a.tz) * (1.0f - s->b1 - s->b2) +
             make_float3(b.tx, b.ty, b.tz) * s->b1 + make_float3(c.tx, c.ty, c.tz) * s->b2;
  *tw = a.tw;
  if (s->inst != PR_INVALID_INDEX) {
    Affine o2w, w2o;
    instance_transforms(sd, s->inst, &o2w, &w2o);
    t = affine_vector(&o2w, t);
    // A mirroring transform turns the bitangent's handedness around.
    if (affine_det(&o2w) < 0.0f) *tw = -*tw;
  }
  return t;
}

// The surface at barycentrics (b1, b2) of a triangle (b1 weights v1, b2 weights v2); with its
// normal map applied where map_normals (not where the caller has the shading normal already).
PR_INLINE SurfaceHit surface_interp(const ShadingData* sd, u32 prim, u32 inst, float b1, float b2,
                                    int map_normals) {
  SurfaceHit s;
  // Hits report shading triangle indices: DSG meshes are numbered after the SSG's triangles.
  s.prim = prim;
  s.inst = inst;
  const ShadingTriangle tri = sd->triangles[s.prim];
  s.material = tri.material;
  ShadingVertex a, b, c;
  triangle_vertices(sd, tri, inst, &a, &b, &c);
  const float b0 = 1.0f - b1 - b2;
  float3 pa = make_float3(a.px, a.py, a.pz), pb = make_float3(b.px, b.py, b.pz),
         pc = make_float3(c.px, c.py, c.pz);
  float3 n = make_float3(a.nx, a.ny, a.nz) * b0 + make_float3(b.nx, b.ny, b.nz) * b1 +
             make_float3(c.nx, c.ny, c.nz) * b2;
  if (inst != PR_INVALID_INDEX) {
    Affine w2o;
    place_corners(sd, inst, &pa, &pb, &pc, &w2o);
    n = affine_normal(&w2o, n);
  }
  s.p = pa * b0 + pb * b1 + pc * b2;
  const float3 cr = cross(pb - pa, pc - pa);
  const float cl = length(cr);
  s.ng = cl > 0.0f ? cr / cl : make_float3(0.0f, 0.0f, 1.0f);
  const float nl = length(n);
  s.ns = nl > 0.0f && isfinite_f(nl) ? n / nl : s.ng;
  s.b1 = b1;
  s.b2 = b2;
  s.uv = make_float2(a.u * b0 + b.u * b1 + c.u * b2, a.v * b0 + b.v * b1 + c.v * b2);
  s.uv1 = make_float2(a.u1 * b0 + b.u1 * b1 + c.u1 * b2, a.v1 * b0 + b.v1 * b1 + c.v1 * b2);
  PR_GLOBAL const Material* m = sd->materials + s.material;
  if (map_normals && m->normal_texture != PR_NO_TEXTURE) {
    float tw;
    const float3 t = surface_tangent(sd, &s, &tw);
    s.ns =
        normal_mapped(sd, m->normal_texture, m->normal_scale,
                      material_uv(m, PR_UV_NORMAL, m->normal_uv, s.uv, s.uv1), s.ns, t, tw, s.ng);
  }
  if (dot(s.ns, s.ng) < 0.0f) s.ns = -s.ns;
  return s;
}

// The clearcoat's normal (KHR_materials_clearcoat), world space, on ng's side: the interpolated
// vertex normal (the base layer's normal map does not apply to the coat), with the coat's own
// normal map where it has one.
PR_INLINE float3 surface_coat_normal(const ShadingData* sd, const SurfaceHit* s) {
  PR_GLOBAL const Material* m = sd->materials + s->material;
  const ShadingTriangle tri = sd->triangles[s->prim];
  ShadingVertex a, b, c;
  triangle_vertices(sd, tri, s->inst, &a, &b, &c);
  float3 n = make_float3(a.nx, a.ny, a.nz) * (1.0f - s->b1 - s->b2) +
             make_float3(b.nx, b.ny, b.nz) * s->b1 + make_float3(c.nx, c.ny, c.nz) * s->b2;
  if (s->inst != PR_INVALID_INDEX) {
    Affine o2w, w2o;
    instance_transforms(sd, s->inst, &o2w, &w2o);
    n = affine_normal(&w2o, n);
  }
  const float nl = length(n);
  n = nl > 0.0f && isfinite_f(nl) ? n / nl : s->ng;
  if (m->coat_normal_texture != PR_NO_TEXTURE) {
    float tw;
    const float3 t = surface_tangent(sd, s, &tw);
    n = normal_mapped(sd, m->coat_normal_texture, m->coat_normal_scale,
                      material_uv(m, PR_UV_COAT_NORMAL, m->coat_normal_uv, s->uv, s->uv1), n, t, tw,
                      s->ng);
  }
  return dot(n, s->ng) < 0.0f ? -n : n;
}

PR_INLINE SurfaceHit surface_at(const ShadingData* sd, u32 prim, u32 inst, float b1, float b2) {
  return surface_interp(sd, prim, inst, b1, b2, 1);
}

// Base colour (rgb) and alpha at the surface.
PR_INLINE float4 material_base(const ShadingData* sd, const SurfaceHit* s) {
  PR_GLOBAL const Material* m = sd->materials + s->material;
  float4 c = make_float4(m->base_r, m->base_g, m->base_b, m->base_a);
  if (m->base_texture != PR_NO_TEXTURE) {
    const float4 t =
        texture_sample(sd, m->base_texture, material_uv(m, PR_UV_BASE, m->base_uv, s->uv, s->uv1));
    c = make_float4(c.x * t.x, c.y * t.y, c.z * t.z, c.w * t.w);
  }
  return c;
}

// KHR_materials_anisotropy at the surface: the strength (0: isotropic) and the direction as
// (cos, sin) from the tangent towards the bitangent: the rotation, turned by the texture's
// direction (RG in [-1, 1]) whose B scales the strength.
PR_INLINE float material_anisotropy(const ShadingData* sd, const SurfaceHit* s, float2* dir) {
  PR_GLOBAL const Material* m = sd->materials + s->material;
  *dir = make_float2(1.0f, 0.0f);
  float strength = m->aniso_strength;
  if (!PR_HAS_ANISOTROPY || !(strength > 0.0f)) return 0.0f;
  float c = m->aniso_cos, sn = m->aniso_sin;
  if (m->aniso_texture != PR_NO_TEXTURE) {
    const float4 t = texture_sample(sd, m->aniso_texture,
                                    material_uv(m, PR_UV_ANISO, m->aniso_uv, s->uv, s->uv1));
    const float tx = 2.0f * t.x - 1.0f, ty = 2.0f * t.y - 1.0f;
    const float l = sqrt(tx * tx + ty * ty);
    if (l > 1e-6f) {
      const float ux = tx / l, uy = ty / l;
      const float c2 = c * ux - sn * uy;
      sn = sn * ux + c * uy;
      c = c2;
    }
    strength *= t.z;
  }
  *dir = make_float2(c, sn);
  return clamp(strength, 0.0f, 1.0f);
}

// A key of a surface point for choices that every kernel and every device must make alike there
// (alpha coverage, glass or not): its triangle, instance and barycentrics on a grid of 2^-16.
// Not their float bits: those differ in the last place between compilers, and each difference
// would be another choice (docs/experiments/portability.md).
PR_INLINE u32 surface_point_key(u32 salt, u32 prim, u32 inst, float b1, float b2) {
  const u32 q1 = (u32)(fmin(fmax(b1, 0.0f), 1.0f) * 65536.0f);
  const u32 q2 = (u32)(fmin(fmax(b2, 0.0f), 1.0f) * 65536.0f);
  return pr_hash_u32(salt ^ prim ^ pr_hash_u32(inst ^ pr_hash_u32(q1 ^ pr_hash_u32(q2))));
}

// Whether a transmissive material is glass at the point (else it is its opaque base): the
// transmission factor x its texture is the chance, decided by the point's key so that every
// kernel that shades the point sees the same surface (as alpha coverage, surface_passes).
PR_INLINE int material_transmits_at(const ShadingData* sd, PR_GLOBAL const Material* m,
                                    const SurfaceHit* s) {
  float t = m->transmission;
  if (m->transmission_texture != PR_NO_TEXTURE)
    t *= texture_sample(sd, m->transmission_texture,
                        material_uv(m, PR_UV_TRANSMISSION, m->transmission_uv, s->uv, s->uv1))
             .x;
  if (t >= 1.0f) return 1;
  if (!(t > 0.0f)) return 0;
  return pr_u32_to_unit(surface_point_key(0x7a3c91e5u, s->prim, s->inst, s->b1, s->b2)) < t;
}

// The BSDF's parameters at the surface; in *aniso the anisotropy direction (cos, sin) from the
// tangent towards the bitangent, (0, 0) where the surface is isotropic.
PR_INLINE BsdfParams material_bsdf(const ShadingData* sd, const SurfaceHit* s, float2* aniso) {
  PR_GLOBAL const Material* m = sd->materials + s->material;
  const float4 base = material_base(sd, s);
  BsdfParams p = bsdf_params_default();
  p.base = make_float3(base.x, base.y, base.z);
  float metallic = m->metallic, roughness = m->roughness;
  if (m->mr_texture != PR_NO_TEXTURE) {
    const float4 t =
        texture_sample(sd, m->mr_texture, material_uv(m, PR_UV_MR, m->mr_uv, s->uv, s->uv1));
    roughness *= t.y;
    metallic *= t.z;
  }
  p.metallic = clamp(metallic, 0.0f, 1.0f);
  roughness = clamp(roughness, 0.0f, 1.0f);
  p.alpha_x = fmax(roughness * roughness, PR_MIN_ALPHA);
  p.alpha_y = p.alpha_x;
  p.ior = m->ior;
  // KHR_materials_specular: F0 = min(((ior-1)/(ior+1))^2 colour, 1) x factor, F90 = factor.
  float3 f0 = make_float3(m->spec_f0[0], m->spec_f0[1], m->spec_f0[2]);
  float f90 = m->spec_f90;
  if (m->spec_color_texture != PR_NO_TEXTURE) {
    const float4 t =
        texture_sample(sd, m->spec_color_texture,
                       material_uv(m, PR_UV_SPEC_COLOR, m->spec_color_uv, s->uv, s->uv1));
    f0 = f0 * make_float3(t.x, t.y, t.z);
  }
  if (m->spec_texture != PR_NO_TEXTURE)
    f90 *=
        texture_sample(sd, m->spec_texture, material_uv(m, PR_UV_SPEC, m->spec_uv, s->uv, s->uv1))
            .w;
  p.f0 = make_float3(fmin(f0.x, 1.0f), fmin(f0.y, 1.0f), fmin(f0.z, 1.0f)) * f90;
  p.f90 = f90;
  float coat = PR_HAS_COAT ? m->coat : 0.0f, coat_roughness = m->coat_roughness;
  if (PR_HAS_COAT && m->coat_texture != PR_NO_TEXTURE)
    coat *=
        texture_sample(sd, m->coat_texture, material_uv(m, PR_UV_COAT, m->coat_uv, s->uv, s->uv1))
            .x;
  if (PR_HAS_COAT && m->coat_roughness_texture != PR_NO_TEXTURE)
    coat_roughness *=
        texture_sample(sd, m->coat_roughness_texture,
                       material_uv(m, PR_UV_COAT_ROUGHNESS, m->coat_roughness_uv, s->uv, s->uv1))
            .y;
  p.coat = coat;
  const float cr = clamp(coat_roughness, 0.0f, 1.0f);
  p.coat_alpha = fmax(cr * cr, PR_MIN_ALPHA);
  // KHR_materials_sheen: colour x texture RGB, roughness x texture A.
  float3 sheen = make_float3(m->sheen[0], m->sheen[1], m->sheen[2]);
  if (PR_HAS_SHEEN && max3(sheen) > 0.0f) {
    float sheen_roughness = m->sheen_roughness;
    if (m->sheen_texture != PR_NO_TEXTURE) {
      const float4 t = texture_sample(sd, m->sheen_texture,
                                      material_uv(m, PR_UV_SHEEN, m->sheen_uv, s->uv, s->uv1));
      sheen = sheen * make_float3(t.x, t.y, t.z);
    }
    if (m->sheen_roughness_texture != PR_NO_TEXTURE)
      sheen_roughness *= texture_sample(sd, m->sheen_roughness_texture,
                                        material_uv(m, PR_UV_SHEEN_ROUGHNESS, m->sheen_roughness_uv,
                                                    s->uv, s->uv1))
                             .w;
    p.sheen = make_float3(clamp(sheen.x, 0.0f, 1.0f), clamp(sheen.y, 0.0f, 1.0f),
                          clamp(sheen.z, 0.0f, 1.0f));
    const float sr = clamp(sheen_roughness, 0.0f, 1.0f);
    p.sheen_alpha = fmax(sr * sr, PR_MIN_SHEEN_ALPHA);
  }
  // KHR_materials_anisotropy: the roughness along the anisotropy direction (the shading frame's
  // tangent, shading_frame) mixed towards 1 by strength^2.
  const float strength = material_anisotropy(sd, s, aniso);
  if (strength > 0.0f)
    p.alpha_x = mix(p.alpha_x, 1.0f, strength * strength);
  else
    *aniso = make_float2(0.0f, 0.0f);
  p.model = (m->flags & PR_MAT_GLTF_MODEL) ? PR_MODEL_GLTF : PR_MODEL_ENERGY;
  if ((m->flags & PR_MAT_GLASS) && material_transmits_at(sd, m, s)) {
    // A refraction tints by the square root of the base colour, so that light through a closed
    // object is tinted by it once (as Cycles' Principled BSDF does).
    p.base = make_float3(sqrt(fmax(p.base.x, 0.0f)), sqrt(fmax(p.base.y, 0.0f)),
                         sqrt(fmax(p.base.z, 0.0f)));
    p.kind = p.alpha_x > PR_MIN_ALPHA ? PR_BSDF_ROUGH_GLASS : PR_BSDF_GLASS;
  } else if (m->flags & PR_MAT_MIRROR)
    p.kind = PR_BSDF_MIRROR;
  else if (m->flags & PR_MAT_LAMBERT)
    p.kind = PR_BSDF_LAMBERT;
  else
    p.kind = PR_BSDF_MICROFACET;
  return p;
}

PR_INLINE float3 material_emission(const ShadingData* sd, const SurfaceHit* s) {
  PR_GLOBAL const Material* m = sd->materials + s->material;
  float3 e = make_float3(m->emit_r, m->emit_g, m->emit_b);
  if (m->emission_texture != PR_NO_TEXTURE) {
    const float4 t = texture_sample(sd, m->emission_texture,
                                    material_uv(m, PR_UV_EMISSION, m->emission_uv, s->uv, s->uv1));
    e = e * make_float3(t.x, t.y, t.z);
  }
  return e;
}

PR_INLINE float3 material_emission_factor(const ShadingData* sd, u32 material) {
  PR_GLOBAL const Material* m = sd->materials + material;
  return make_float3(m->emit_r, m->emit_g, m->emit_b);
}

PR_NAMESPACE_END

#ifdef PR_DEVICE_CODE
PR_ARG_GATHER(ShadingData, pr_shading_data, PR_ARGS_SHADING)
#endif
