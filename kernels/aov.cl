// aov (--aov): one work-item per pixel of the range [0, end); every sample pass in one launch.
// Each pass's camera ray goes through the point of the pixel that pass's colour sample used
// (the same key: seed, jitter_frame, pixel, pass), so the auxiliary images are filtered as the
// colour is. Writes PR_AOV_FLOATS per pixel (docs/design.md section 5, "Auxiliary images"):
//   0-2 albedo sum, 3-5 normal sum: at the first non-delta surface, through mirrors and glass
//       (their tints applied to the albedo), or the environment (albedo its radiance clamped to
//       1, normal 0) where the ray leaves the scene; under --shutter at each pass's time;
//   6   Z of pass 0's first hit: its distance along the camera's axis (+inf: none);
//   7-8 motion sum: from the film point of the first hit this frame to where the previous
//       frame's camera saw the same point of its surface (instances at their previous
//       transforms, deformed meshes at their previous shapes);
//   9   object of pass 0's first hit (its glTF node; -1: none); 10 its material (-1: none);
//   11  the passes summed.
#include "shared/camera.h"
#include "shared/motion.h"
#include "shared/transport.h"
#include "shared/kernel_args.h"

#define PR_AOV_FLOATS 12

// The surface point (prim, inst, b1, b2) where it was when the previous frame was rendered.
PR_INLINE float3 aov_previous_point(const ShadingData* sd, __global const float* prev_inst,
                                    __global const float4* prev_pos, uint static_vertices,
                                    uint prim, uint inst, float b1, float b2) {
  const ShadingTriangle tri = sd->triangles[prim];
  float3 p[3];
  const uint v[3] = {tri.v0, tri.v1, tri.v2};
  for (int k = 0; k < 3; ++k) {
    if (inst == PR_INVALID_INDEX) {
      const ShadingVertex sv = sd->vertices[v[k]];
      p[k] = make_float3(sv.px, sv.py, sv.pz);
    } else {
      const float4 q = prev_pos[v[k] - static_vertices];
      p[k] = make_float3(q.x, q.y, q.z);
    }
  }
  const float3 o = p[0] + (p[1] - p[0]) * b1 + (p[2] - p[0]) * b2;
  return inst == PR_INVALID_INDEX ? o : xform_point12(prev_inst + (size_t)inst * 12u, o);
}

// The first hit's share of pass `pass`: its motion vector, and in pass 0 its Z and ids.
PR_INLINE void aov_first_hit(PR_PARAMS(PR_ARGS_AOV), const SceneData* s, const Hit* hit,
                             const SurfaceHit* h, uint pass, float2* motion, float* depth,
                             float* object, float* material) {
  // Both points from the same interpolation, so that what did not move moves by 0.
  float3 v0, e1, e2;
  triangle_world(&s->sd, hit->prim, hit->inst, &v0, &e1, &e2);
  const float3 now = v0 + e1 * h->b1 + e2 * h->b2;
  const float3 then = aov_previous_point(&s->sd, prev_inst, prev_pos, static_vertices, hit->prim,
                                         hit->inst, h->b1, h->b2);
  float2 a, b;
  if (camera_project(&cam, now, &a) && camera_project(&prev_cam, then, &b)) *motion += b - a;
  if (pass == 0u) {
    *depth = dot(now - camera_position(&cam), make_float3(cam.fx, cam.fy, cam.fz));
    *object = (float)(hit->inst == PR_INVALID_INDEX
                          ? (hit->prim < static_triangles ? tri_object[hit->prim] : 0u)
                          : inst_object[hit->inst]);
    *material = (float)h->material;
  }
}

PR_KERNEL void aov(PR_PARAMS(PR_ARGS_AOV)) {
  const uint i = (uint)get_global_id(0);
  if (i >= end) return;
  const SceneData s = PR_SCENE();
  // Under --shutter, albedo and normals are of each pass's time (the denoiser's guides blurred as
  // the colour is); Z, ids and motion of the frame's, from a ray of their own.
  const int blur = cam_step_count > 1u || s.geom.motion_steps > 1u || s.lights.motion_steps > 1u;
  float3 albedo = make_float3(0.0f, 0.0f, 0.0f), normal = albedo;
  float2 motion = (float2)(0.0f, 0.0f);
  float depth = PR_INF_F, object = -1.0f, material = -1.0f;
  for (uint pass = 0u; pass < spp; ++pass) {
    Rng rng = rng_make(seed, PR_RNG_CAMERA, jitter_frame, i, pass);
    const float2 jitter = rng_next2(&rng);
    SceneData st = s;
    CameraParams ct = cam;
    if (blur) {
      Hit hit;
      if (trace_closest(&s, camera_ray(&cam, i, jitter), &hit)) {
        const SurfaceHit h = surface_at(&s.sd, hit.prim, hit.inst, hit.u, hit.v);
        aov_first_hit(PR_ARG_VALUES(PR_ARGS_AOV), &s, &hit, &h, pass, &motion, &depth, &object,
                      &material);
      }
      const float t = shutter_time(seed, jitter_frame, i, pass);
      st.geom.time = st.sd.time = t;
      if (cam_step_count > 1u) ct = camera_at_time(cam_steps, cam_step_count, t);
    }
    Ray ray = camera_ray(&ct, i, jitter);
    float3 tp = make_float3(1.0f, 1.0f, 1.0f);
    for (uint depth_k = 1u; depth_k <= max_depth; ++depth_k) {
      const float3 d = make_float3(ray.dx, ray.dy, ray.dz);
      Hit hit;
      if (!trace_closest(&st, ray, &hit)) {
        albedo += tp * clamp(environment_radiance(&st, d), 0.0f, 1.0f);
        break;
      }
      const SurfaceHit h = surface_at(&st.sd, hit.prim, hit.inst, hit.u, hit.v);
      if (depth_k == 1u && !blur)
        aov_first_hit(PR_ARG_VALUES(PR_ARGS_AOV), &st, &hit, &h, pass, &motion, &depth, &object,
                      &material);
      const float3 wo = -d;
      const ShadingFrame f = shading_frame(&st, &h, wo);
      if (!bsdf_is_delta(&f.bsdf) || depth_k == max_depth) {
        albedo += tp * bsdf_albedo(&f.bsdf, to_local(wo, f.t, f.b, f.n));
        normal += f.n;
        break;
      }
      const float u0 = rng_next(&rng);
      const float2 u12 = rng_next2(&rng);
      PathStep step;
      if (!path_step(&st, &h, &f, wo, u0, u12.x, u12.y, PR_RADIANCE, &step)) break;
      tp = tp * step.weight;
      ray = surface_ray(&st, &h, step.wi, PR_INF_F);
    }
  }
  __global float* o = aov + (size_t)i * PR_AOV_FLOATS;
  o[0] = albedo.x, o[1] = albedo.y, o[2] = albedo.z;
  o[3] = normal.x, o[4] = normal.y, o[5] = normal.z;
  o[6] = depth;
  o[7] = motion.x, o[8] = motion.y;
  o[9] = object, o[10] = material;
  o[11] = (float)spp;
}
