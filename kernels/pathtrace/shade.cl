// pt_shade: one work-item per live path. Reads the path and its hit; adds emission (MIS-weighted
// against next-event estimation) to the sample's radiance, writes a shadow ray for next-event
// estimation, samples the BSDF for the next ray and applies Russian roulette.
// Writes the PathState, the radiance and the ShadowRay of the same index.
#include "shared/integrator.h"
#include "shared/path_state.h"

__kernel void pt_shade(PR_SCENE_PARAMS, __global PathState* states, __global const Hit* hits,
                       __global float4* radiance, __global ShadowRay* shadows, uint count,
                       uint seed, uint frame, uint sample, uint max_depth) {
  const uint i = (uint)get_global_id(0);
  if (i >= count) return;
  const SceneData s = PR_SCENE();
  PathState p = states[i];
  shadows[i].valid = 0u;
  if (!p.alive) return;

  const Hit hit = hits[i];
  if (hit.prim == PR_INVALID_INDEX) {
    // Escaped: the environment's light, MIS-weighted against next-event estimation.
    const float3 d = make_float3(p.ray.dx, p.ray.dy, p.ray.dz);
    const float3 le = environment_radiance(&s, d);
    if (max3(le) > 0.0f) {
      float w = 1.0f;
      if (!(p.flags & PR_PATH_SPECULAR))
        w = power_heuristic(p.last_pdf,
                            environment_pdf(&s, make_float3(p.prev_x, p.prev_y, p.prev_z),
                                            make_float3(p.prev_nx, p.prev_ny, p.prev_nz), d));
      const float3 add = make_float3(p.tp_r, p.tp_g, p.tp_b) * le * w;
      radiance[i] += (float4)(add.x, add.y, add.z, 0.0f);
    }
    p.alive = 0u;
    states[i] = p;
    return;
  }
  Rng rng = rng_make(seed, PR_RNG_CAMERA, frame, p.pixel, sample);
  rng.dim = p.rng_dim;
  const float3 d = make_float3(p.ray.dx, p.ray.dy, p.ray.dz);
  const float3 wo = -d;
  const SurfaceHit h = surface_at(&s.sd, hit.prim, hit.inst, hit.u, hit.v);
  float3 tp = make_float3(p.tp_r, p.tp_g, p.tp_b) * volume_transmittance(&s, &h, d, hit.t);

  PR_GLOBAL const Material* mat = s.sd.materials + h.material;
  if (mat->flags & PR_MAT_EMISSIVE) {
    const float3 le = surface_emission(&s, &h);
    float w = 1.0f;
    if (!(p.flags & PR_PATH_SPECULAR))
      w = power_heuristic(p.last_pdf, emitter_pdf(&s, &h, make_float3(p.prev_x, p.prev_y, p.prev_z),
                                                  make_float3(p.prev_nx, p.prev_ny, p.prev_nz)));
    const float3 add = tp * le * w;
    radiance[i] += (float4)(add.x, add.y, add.z, 0.0f);
  }
  p.depth += 1u;
  if (p.depth >= max_depth) {
    p.alive = 0u;
  } else {
    const ShadingFrame f = shading_frame(&s, &h, wo);
    if (!bsdf_is_delta(&f.bsdf)) {
      Ray shadow;
      float3 c;
      if (next_event(&s, &h, &f, wo, 1, &rng, &shadow, &c)) {
        c = tp * c;
        shadows[i].ray = shadow;
        shadows[i].c_r = c.x;
        shadows[i].c_g = c.y;
        shadows[i].c_b = c.z;
        shadows[i].valid = 1u;
      }
    } else {
      rng_skip(&rng, PR_NEXT_EVENT_DRAWS);  // the same dimensions whatever the material
    }
    const float u0 = rng_next(&rng);
    const float2 u12 = rng_next2(&rng);
    PathStep step;
    if (!path_step(&f, wo, u0, u12.x, u12.y, PR_RADIANCE, &step)) {
      p.alive = 0u;
    } else {
      tp = tp * step.weight;
      // From the third vertex on (the camera's throughput starts at 1).
      const float rr = rng_next(&rng);
      if (p.depth >= 3u && !russian_roulette(max3(tp), rr, &tp)) p.alive = 0u;
      p.ray = spawn_ray(h.p, f.ng, step.wi, PR_INF_F);
      p.prev_x = h.p.x;
      p.prev_y = h.p.y;
      p.prev_z = h.p.z;
      p.prev_nx = f.n.x;
      p.prev_ny = f.n.y;
      p.prev_nz = f.n.z;
      p.last_pdf = step.pdf;
      p.flags = step.delta ? PR_PATH_SPECULAR : 0u;
    }
  }
  if (!(max3(tp) < PR_INF_F)) p.alive = 0u;  // NaN or Inf throughput ends the path
  p.tp_r = tp.x;
  p.tp_g = tp.y;
  p.tp_b = tp.z;
  p.rng_dim = rng.dim;
  states[i] = p;
}
