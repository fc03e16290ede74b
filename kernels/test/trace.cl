// Test kernel trace_rays: traces rays[i] against the SSG + DSG. Reads rays and the scene
// geometry; writes hits[i] (closest hit) and occluded[i] (any hit within [tmin, tmax]).
// mode 0: whole scene, 1: SSG only, 2: DSG only.
#include "shared/bvh.h"

PR_KERNEL void trace_rays(__global const Ray* rays, __global Hit* hits, __global uint* occluded,
                          uint n, uint mode, PR_PARAMS(PR_ARGS_SCENE_GEOM)) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  const SceneGeom g = PR_SCENE_GEOM();
  const Ray ray = rays[i];
  Hit hit;
  uint occ;
  if (mode == 1u) {
    intersect_static(&g, ray, &hit);
    occ = (uint)occluded_static(&g, ray);
  } else if (mode == 2u) {
    intersect_dynamic(&g, ray, &hit);
    occ = (uint)occluded_dynamic(&g, ray);
  } else {
    intersect_scene(&g, ray, &hit);
    occ = (uint)occluded_scene(&g, ray);
  }
  hits[i] = hit;
  occluded[i] = occ;
}

// Benchmark kernels (tools/bench/ray_bench): closest hit only, any hit only, on the whole scene.
PR_KERNEL void trace_closest(__global const Ray* rays, __global Hit* hits, uint n,
                             PR_PARAMS(PR_ARGS_SCENE_GEOM)) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  const SceneGeom g = PR_SCENE_GEOM();
  Hit hit;
  intersect_scene(&g, rays[i], &hit);
  hits[i] = hit;
}

PR_KERNEL void trace_any(__global const Ray* rays, __global uint* occluded, uint n,
                         PR_PARAMS(PR_ARGS_SCENE_GEOM)) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  const SceneGeom g = PR_SCENE_GEOM();
  occluded[i] = (uint)occluded_scene(&g, rays[i]);
}
