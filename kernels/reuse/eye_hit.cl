// eye_hit: one work-item per pixel (one pass per sample index). Traces the camera ray through a
// jittered point of the pixel to its first non-delta surface, following mirror and glass
// bounces, and counts the emission it sees on the way (no other technique can reach it).
// Reads the camera and the scene; writes the pixel sample's EyeVertex and its radiance so far.
// A pixel that --noise-threshold's mask leaves out of the pass gets an empty vertex, no ray.
#include "shared/camera.h"
#include "shared/reuse.h"

PR_KERNEL void eye_hit(PR_PARAMS(PR_ARGS_EYE_HIT)) {
  const uint i = (uint)get_global_id(0);
  if (i >= rp.pixel_count) return;
  const SceneData s = PR_SCENE();
  Rng rng = rng_make(rp.seed, PR_RNG_CAMERA, rp.frame, i, sample);
  Ray ray = camera_ray(&cam, i, rng_next2(&rng));
  float3 d = make_float3(ray.dx, ray.dy, ray.dz);
  float3 tp = make_float3(1.0f, 1.0f, 1.0f), L = make_float3(0.0f, 0.0f, 0.0f);
  EyeVertex e;
  e.prim = PR_INVALID_INDEX;
  e.inst = PR_INVALID_INDEX;
  e.depth = 0u;
  uint bounces = 0u;
  const uint max_depth = pixel_takes_pass(budget, masked, i, sample) ? rp.max_depth : 0u;
  for (uint depth = 1u; depth <= max_depth; ++depth) {
    Hit hit;
    if (!trace_closest(&s, ray, &hit)) {
      L += tp * environment_radiance(&s, d);  // seen directly or through delta bounces
      break;
    }
    const SurfaceHit h = surface_at(&s.sd, hit.prim, hit.inst, hit.u, hit.v);
    const float3 wo = -d;
    tp = tp * volume_transmittance(&s, &h, d, hit.t);
    if (s.sd.materials[h.material].flags & PR_MAT_EMISSIVE) L += tp * surface_emission(&s, &h);
    if (depth >= rp.max_depth) break;
    const ShadingFrame f = shading_frame(&s, &h, wo);
    if (!bsdf_is_delta(&f.bsdf)) {
      eye_vertex_set(&e, &h, &hit, wo, tp, depth);
      break;
    }
    const float u0 = rng_next(&rng);
    const float2 u12 = rng_next2(&rng);
    PathStep step;
    if (!path_step(&s, &h, &f, wo, u0, u12.x, u12.y, PR_RADIANCE, &step)) break;
    d = step.wi;
    tp = tp * step.weight;
    ray = surface_ray(&s, &h, d, PR_INF_F);
    ++bounces;
  }
  if (e.prim == PR_INVALID_INDEX) {
    e.px = e.py = e.pz = 0.0f;
    e.wx = e.wy = e.wz = 0.0f;
    e.ng_oct = e.ns_oct = 0u;
    e.tp_r = e.tp_g = e.tp_b = 0.0f;
    e.b1 = e.b2 = 0.0f;
  }
  eye[i] = e;
  radiance[i] = (float4)(L.x, L.y, L.z, 0.0f);
  if (max_depth) atomic_inc(counter_lane(counters, PR_C_ROW) + PR_C_CAMERA_RAYS);
  if (bounces) atomic_add(counter_lane(counters, PR_C_ROW) + PR_C_BOUNCE_RAYS, bounces);
}
