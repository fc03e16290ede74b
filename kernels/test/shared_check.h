// One random case of the shared helpers, for kernels/test/shared_check.cl on the device and for
// tests/shared_device_test.cpp on the host: the same source, so every output can be compared
// lane by lane. Outputs are floats at fixed positions (PR_CHECK_*).
#pragma once

#include "shared/bsdf.h"
#include "shared/bvh.h"
#include "shared/lights.h"
#include "shared/arena.h"
#include "shared/rng.h"
#include "shared/sampling.h"

PR_NAMESPACE_BEGIN

#define PR_CHECK_STRIDE 52

PR_INLINE void check_put3(float* r, u32 at, float3 v) {
  r[at] = v.x;
  r[at + 1] = v.y;
  r[at + 2] = v.z;
}

PR_INLINE float3 check_unit(Rng* rng) {
  // One draw per statement: the order of evaluation of arguments is unspecified.
  const float x = rng_next(rng) - 0.5f, y = rng_next(rng) - 0.5f, z = rng_next(rng) - 0.5f;
  const float3 v = make_float3(x, y, z);
  return dot(v, v) > 1e-6f ? normalize(v) : make_float3(0.0f, 0.0f, 1.0f);
}

PR_INLINE void shared_check_case(u32 i, PR_GLOBAL const float* cdf, u32 cdf_count,
                                 PR_GLOBAL const LightNode* nodes, u32 node_count, float* r) {
  for (u32 k = 0u; k < PR_CHECK_STRIDE; ++k) r[k] = 0.0f;
  Rng rng = rng_make(7u, PR_RNG_TEST, 0u, i, 0u);

  // Octahedral normals and frames.
  const float3 n = check_unit(&rng);
  const u32 e = oct_encode(n);
  r[0] = (float)(e & 0xffffu);
  r[1] = (float)(e >> 16);
  check_put3(r, 2, oct_decode(e) + oct_decode(e ^ 0x00010001u));
  float3 t, b;
  orthonormal_basis(n, &t, &b);
  check_put3(r, 5, t);
  check_put3(r, 8, to_local(check_unit(&rng), t, b, n));

  // A microfacet BSDF: sample, then evaluate the sample and a cosine-distributed direction.
  BsdfParams m = bsdf_params_default();
  const float cr = rng_next(&rng), cg = rng_next(&rng), cb = rng_next(&rng);
  m.base = make_float3(cr, cg, cb);
  m.metallic = rng_next(&rng);
  m.alpha_x = fmax(rng_next(&rng), PR_MIN_ALPHA);
  m.alpha_y = m.alpha_x;
  m.f0 = make_float3(0.04f + 0.3f * rng_next(&rng), 0.04f, 0.1f);
  m.f90 = rng_next(&rng);
  m.coat = rng_next(&rng);
  m.coat_alpha = fmax(rng_next(&rng), PR_MIN_ALPHA);
  // Every other case: the glTF model; anisotropic, with a sheen and a tilted coat normal.
  if (i & 1u) m.model = PR_MODEL_GLTF;
  if (i & 2u) {
    m.alpha_x = fmin(1.0f, m.alpha_x * 4.0f);
    m.sheen = make_float3(0.8f, 0.5f, 0.3f);
    m.sheen_alpha = fmax(rng_next(&rng), PR_MIN_SHEEN_ALPHA);
    m.coat_n = normalize(make_float3(0.2f, -0.1f, 1.0f));
  }
  const float o1 = rng_next(&rng), o2 = rng_next(&rng);
  const float3 wo = sample_cosine_hemisphere(o1, o2);
  const float u0 = rng_next(&rng), u1 = rng_next(&rng), u2 = rng_next(&rng);
  float3 wi = make_float3(0.0f, 0.0f, 1.0f), weight;
  float pdf = 0.0f;
  int delta = 0;
  r[11] = (float)bsdf_sample(&m, wo, u0, u1, u2, PR_RADIANCE, &wi, &weight, &pdf, &delta);
  check_put3(r, 12, wi);
  check_put3(r, 15, weight);
  r[18] = pdf;
  const float c1 = rng_next(&rng), c2 = rng_next(&rng);
  const float3 wc = sample_cosine_hemisphere(c1, c2);
  float pdf_c = 0.0f;
  float pdf_w = 0.0f;
  check_put3(r, 19, bsdf_eval(&m, wo, wc, &pdf_c) + bsdf_eval(&m, wo, wi, &pdf_w));
  r[22] = pdf_c + pdf_w;

  // Leaving a surface: the offset origin and the ray to a point on another surface.
  const float px = rng_next(&rng), py = rng_next(&rng), pz = rng_next(&rng);
  const float3 p = make_float3(4.0f * px - 2.0f, 100.0f * py, 0.01f * pz);
  const float3 away = check_unit(&rng);
  const float3 q = p + away * (1.0f + rng_next(&rng));
  check_put3(r, 23, offset_ray_origin(p, n) - offset_ray_origin(q, t));
  const Ray ray = spawn_ray_to(p, n, q, -n);
  r[26] = ray.ox;
  r[27] = ray.oy;
  r[28] = ray.oz;
  r[29] = ray.dx;
  r[30] = ray.dy;
  r[31] = ray.dz;

  // Choosing a light by power, and a point on a triangle light seen from p.
  const float us = rng_next(&rng);
  r[32] = (float)light_select(cdf, cdf_count, us);
  Light l;
  l.type = PR_LIGHT_TRIANGLE;
  l.p0x = q.x;
  l.p0y = q.y;
  l.p0z = q.z;
  l.e1x = t.x;
  l.e1y = t.y;
  l.e1z = t.z;
  l.e2x = b.x + 0.5f * t.x;
  l.e2y = b.y + 0.5f * t.y;
  l.e2z = b.z + 0.5f * t.z;
  l.area = 0.5f * length(cross(make_float3(l.e1x, l.e1y, l.e1z), make_float3(l.e2x, l.e2y, l.e2z)));
  l.le_r = l.le_g = l.le_b = 1.0f;
  LightSample ls;
  float b1 = 0.0f, b2 = 0.0f;
  const float l1 = rng_next(&rng), l2 = rng_next(&rng);
  const int got = light_sample(&l, 0.5f, p, n, l1, l2, &ls, &b1, &b2);
  r[33] = (float)got;
  if (got) {
    check_put3(r, 34, ls.pos);
    check_put3(r, 37, ls.wi);
    r[40] = ls.pdf;
    check_put3(r, 41, ls.normal);
    r[44] = power_heuristic(ls.pdf, pdf_c);
  }
  r[45] = b1;
  r[46] = b2;
  r[47] = (float)light_select(cdf, cdf_count, 1.0f - us);

  // The light BVH: a node's importance, a choice and its pmf, and the pmf of reaching a node.
  const u32 node = i % node_count;
  const float3 nr = (i & 3u) == 3u ? make_float3(0.0f, 0.0f, 0.0f) : n;
  const float3 pl = make_float3(2.0f * p.x, 0.08f * p.y - 4.0f, 4.0f * n.z);  // among the lights
  r[48] = light_node_importance(nodes + node, pl, nr);
  float pmf = 0.0f;
  r[49] = (float)light_bvh_sample(nodes, pl, nr, l1, &pmf);
  r[50] = pmf;
  r[51] = light_bvh_pmf(nodes, node, pl, nr);
}

PR_NAMESPACE_END
