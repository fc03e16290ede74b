// Every kernel's parameters, one table per kernel: the kernels' parameter lists, the host's
// argument structs and setters (host/cl/kernel_binding.h) and the start-up check of each built
// kernel against its table (clGetKernelArgInfo) all come from these lists, so that an argument
// is named once and never counted by hand.
//
// A table is a macro of two entry macros, F for its first entry and X for every other, so that a
// parameter list is made without a variadic macro (OpenCL C 1.2 has none; NVIDIA's compiler
// refuses them): F(...) gives `param`, X(...) gives `, param`. A table that begins with another
// passes it (F, X); one included after an entry passes it (X, X). Where the separator does not
// matter (the host's structs, the gathers below) both are the same macro.
//
// An entry is X(role, kind, type, name):
//   role  GEOM, SHADING, LIGHTS: the scene (GpuScene sets them; kernels get SceneData);
//         FRAME: set once per frame; PASS: changes between the launches of one frame (the
//         sample index of each pass; the wavefront's queues and their sizes at each bounce).
//   kind  IN: `__global const type*`; OUT: `__global type*` (written, maybe read); VAL: `type`.
// Scene entries' parameters are named pr_g_*, pr_sd_*, pr_l_* (PR_ARG_NAME) and reach kernel
// code only through PR_SCENE() / PR_SCENE_GEOM().
#pragma once

// Motion blur's instance transforms and the path's time (shared/motion.h), which both the
// geometry and shading read: entries of group `role`.
#define PR_ARGS_MOTION(role, X)    \
  X(role, IN, float, motion)       \
  X(role, VAL, uint, motion_steps) \
  X(role, VAL, float, time)

// The scene's geometry: the two BVHs (SSG, and DSG's top level over instances of mesh BVHs).
#define PR_ARGS_SCENE_GEOM(F, X)         \
  F(GEOM, IN, BvhNode, static_nodes)     \
  X(GEOM, IN, BvhTriPacket, static_tris) \
  X(GEOM, IN, BvhNode, tlas_nodes)       \
  X(GEOM, IN, BvhInstance, instances)    \
  X(GEOM, IN, BvhNode, mesh_nodes)       \
  X(GEOM, IN, BvhTriPacket, mesh_tris)   \
  X(GEOM, VAL, uint, instance_count)     \
  PR_ARGS_MOTION(GEOM, X)                \
  X(GEOM, IN, BvhTriPacket, motion_tris) \
  X(GEOM, IN, uint, mesh_motion)         \
  X(GEOM, IN, float, motion_bounds)

// What shading reads: vertices, triangles, per-instance records, materials, textures.
#define PR_ARGS_SHADING(F, X)                    \
  F(SHADING, IN, ShadingVertex, vertices)        \
  X(SHADING, IN, ShadingTriangle, triangles)     \
  X(SHADING, IN, ShadingInstance, instances)     \
  X(SHADING, IN, Material, materials)            \
  X(SHADING, IN, TextureInfo, textures)          \
  X(SHADING, IN, uint, texels)                   \
  PR_ARGS_MOTION(SHADING, X)                     \
  X(SHADING, IN, ShadingVertex, motion_vertices) \
  X(SHADING, IN, uint, vertex_motion)

// The light table, its light BVH and the environment.
#define PR_ARGS_LIGHTS(F, X)         \
  F(LIGHTS, IN, Light, lights)       \
  X(LIGHTS, IN, float, cdf)          \
  X(LIGHTS, IN, LightNode, nodes)    \
  X(LIGHTS, IN, uint, prim_light)    \
  X(LIGHTS, IN, float, env)          \
  X(LIGHTS, VAL, uint, count)        \
  X(LIGHTS, VAL, uint, tree_count)   \
  X(LIGHTS, VAL, float, total_power) \
  X(LIGHTS, VAL, uint, env_light)    \
  X(LIGHTS, IN, Light, motion)       \
  X(LIGHTS, VAL, uint, motion_first) \
  X(LIGHTS, VAL, uint, motion_count) \
  X(LIGHTS, VAL, uint, motion_steps) \
  X(LIGHTS, IN, float, sweeps)       \
  X(LIGHTS, VAL, uint, sweep_count)  \
  X(LIGHTS, VAL, uint, camera_moves)

#define PR_ARGS_SCENE(F, X) PR_ARGS_SCENE_GEOM(F, X) PR_ARGS_SHADING(X, X) PR_ARGS_LIGHTS(X, X)

// --noise-threshold: the pass's samples are taken at pixels whose budget (total passes,
// kernels/adaptive.cl) exceeds the sample index, where `masked`; at every pixel otherwise.
#define PR_ARGS_PIXEL_MASK(F, X) \
  F(FRAME, IN, uint, budget)     \
  X(PASS, VAL, uint, masked)

// The same pass's pixels as a list (Film::beginPass): where `listed`, a launch's work-item k
// < list_count stands for pixel pixels[k] (in no particular order); otherwise for pixel k.
#define PR_ARGS_PIXEL_LIST(F, X) \
  F(PASS, IN, uint, pixels)      \
  X(PASS, VAL, uint, listed)     \
  X(PASS, VAL, uint, list_count)

// ---- Path reuse (kernels/reuse/) ----

#define PR_ARGS_INVALIDATE(F, X)      \
  PR_ARGS_SCENE(F, X)                 \
  X(FRAME, VAL, ReuseParams, rp)      \
  X(FRAME, VAL, uint, test_segments)  \
  X(FRAME, OUT, PathHeader, headers)  \
  X(FRAME, IN, LightVertex, vertices) \
  X(FRAME, OUT, uint, list)           \
  X(FRAME, OUT, uint, counters)       \
  X(FRAME, VAL, uint, mark_only)      \
  X(FRAME, VAL, uint, frame_stamp)    \
  X(FRAME, OUT, uint, changed)

#define PR_ARGS_LIGHT_TRACE(F, X)      \
  PR_ARGS_SCENE(F, X)                  \
  X(FRAME, VAL, ReuseParams, rp)       \
  X(FRAME, IN, float, trace_cdf)       \
  X(FRAME, OUT, PathHeader, headers)   \
  X(FRAME, OUT, LightVertex, vertices) \
  X(FRAME, OUT, EyePathRatio, ratios)  \
  X(FRAME, IN, uint, list)             \
  X(FRAME, VAL, uint, list_count)      \
  X(FRAME, OUT, uint, counters)

#define PR_ARGS_EYE_HIT(F, X)      \
  PR_ARGS_SCENE(F, X)              \
  X(FRAME, VAL, ReuseParams, rp)   \
  X(FRAME, VAL, CameraParams, cam) \
  X(PASS, VAL, uint, sample)       \
  X(FRAME, OUT, EyeVertex, eye)    \
  X(FRAME, OUT, float4, radiance)  \
  X(FRAME, OUT, uint, counters)    \
  PR_ARGS_PIXEL_MASK(X, X)

#define PR_ARGS_CONNECT(F, X)               \
  PR_ARGS_SCENE(F, X)                       \
  X(FRAME, VAL, ReuseParams, rp)            \
  X(FRAME, VAL, CameraParams, cam)          \
  X(PASS, VAL, uint, sample)                \
  X(FRAME, IN, EyeVertex, eye)              \
  X(FRAME, IN, PathHeader, headers)         \
  X(FRAME, IN, LightVertex, vertices)       \
  X(FRAME, OUT, float4, radiance)           \
  X(FRAME, OUT, uint, counters)             \
  X(FRAME, VAL, uint, history_cap)          \
  X(FRAME, VAL, uint, slot_offset)          \
  X(FRAME, VAL, uint, frame_stamp)          \
  X(FRAME, IN, uint, changed)               \
  X(FRAME, OUT, ConnectionHistory, history) \
  X(FRAME, IN, EyePathRatio, ratios)        \
  X(FRAME, IN, CameraParams, cam_steps)     \
  X(FRAME, VAL, uint, cam_step_count)       \
  PR_ARGS_CONNECT_RECORDS(X, X, OUT)

// The pixel samples [record_first, record_end) of one launch of connect and connect_shadow, and
// their terms, record_cap per sample (--eye-paths; ShadowRay with op, shared/reuse.h).
#define PR_ARGS_CONNECT_RECORDS(F, X, kind) \
  F(FRAME, kind, ShadowRay, records)        \
  X(FRAME, kind, uint, record_counts)       \
  X(FRAME, VAL, uint, record_cap)           \
  X(PASS, VAL, uint, record_first)          \
  X(PASS, VAL, uint, record_end)            \
  PR_ARGS_PIXEL_LIST(X, X)

// camera_splat (strategy T): the arena's vertices joined to the camera, into `splat` (fixed
// point per pixel of [first, end), shared/splat.h) times film_scale.
#define PR_ARGS_CAMERA_SPLAT(F, X)      \
  PR_ARGS_SCENE(F, X)                   \
  X(FRAME, VAL, ReuseParams, rp)        \
  X(FRAME, VAL, CameraParams, cam)      \
  X(FRAME, IN, PathHeader, headers)     \
  X(FRAME, IN, LightVertex, vertices)   \
  X(FRAME, IN, EyePathRatio, ratios)    \
  X(FRAME, OUT, uint, splat)            \
  X(FRAME, VAL, uint, first)            \
  X(FRAME, VAL, uint, end)              \
  X(FRAME, VAL, float, film_scale)      \
  X(FRAME, OUT, uint, counters)         \
  X(FRAME, IN, CameraParams, cam_steps) \
  X(FRAME, VAL, uint, cam_step_count)

#define PR_ARGS_CONNECT_SHADOW(F, X) \
  PR_ARGS_SCENE(F, X)                \
  PR_ARGS_CONNECT_RECORDS(X, X, IN)  \
  X(FRAME, OUT, float4, radiance)    \
  X(FRAME, OUT, uint, counters)      \
  X(FRAME, VAL, uint, seed)          \
  X(FRAME, VAL, uint, frame)         \
  X(PASS, VAL, uint, sample)

// ---- The wavefront path tracer (kernels/pathtrace/) ----
// Paths are indexed by pixel; each bounce's stages run over queues of path indices (`queue`,
// `count` of them), which pt_shade compacts: the live paths into next_queue, the paths with a
// shadow ray into shadow_queue, counted in queue_sizes (PR_QUEUE_*, shared/path_state.h). A pass
// runs over bands of pixels: a path's own state (states, hits, shadows, rs_track, rs_pending,
// di_pending) is at its pixel - `base`, the band's first (pt_generate's `first`); what the frame
// keeps (radiance, eye, rs_res, di_res) at its pixel.

#define PR_ARGS_PT_GENERATE(F, X)        \
  F(FRAME, VAL, CameraParams, cam)       \
  X(FRAME, VAL, uint, seed)              \
  X(FRAME, VAL, uint, frame)             \
  X(PASS, VAL, uint, sample)             \
  X(FRAME, OUT, PathState, states)       \
  X(FRAME, OUT, float4, radiance)        \
  X(PASS, VAL, uint, count)              \
  X(FRAME, OUT, EyeVertex, eye)          \
  X(FRAME, VAL, uint, write_eye)         \
  X(FRAME, OUT, uint, queue)             \
  X(PASS, VAL, uint, first)              \
  X(FRAME, VAL, uint, resample)          \
  X(FRAME, OUT, PathReservoir, rs_res)   \
  X(FRAME, OUT, DirectReservoir, di_res) \
  X(FRAME, OUT, uint, queue_size)        \
  X(FRAME, IN, CameraParams, cam_steps)  \
  X(FRAME, VAL, uint, cam_step_count)    \
  PR_ARGS_PIXEL_MASK(X, X)

#define PR_ARGS_PT_EXTEND(F, X)   \
  PR_ARGS_SCENE(F, X)             \
  X(FRAME, IN, PathState, states) \
  X(FRAME, OUT, Hit, hits)        \
  X(FRAME, OUT, uint, rays)       \
  X(PASS, IN, uint, queue)        \
  X(PASS, VAL, uint, count)       \
  X(PASS, VAL, uint, base)        \
  X(FRAME, VAL, uint, seed)       \
  X(FRAME, VAL, uint, frame)      \
  X(PASS, VAL, uint, sample)

#define PR_ARGS_PT_SHADE(F, X)         \
  PR_ARGS_SCENE(F, X)                  \
  X(FRAME, OUT, PathState, states)     \
  X(FRAME, IN, Hit, hits)              \
  X(FRAME, OUT, float4, radiance)      \
  X(FRAME, OUT, ShadowRay, shadows)    \
  X(PASS, IN, uint, queue)             \
  X(PASS, VAL, uint, count)            \
  X(PASS, VAL, uint, base)             \
  X(PASS, OUT, uint, next_queue)       \
  X(FRAME, OUT, uint, shadow_queue)    \
  X(FRAME, OUT, uint, queue_sizes)     \
  X(FRAME, VAL, uint, seed)            \
  X(FRAME, VAL, uint, frame)           \
  X(PASS, VAL, uint, sample)           \
  X(FRAME, VAL, uint, max_depth)       \
  X(FRAME, VAL, uint, paths_per_pixel) \
  X(FRAME, IN, float, trace_cdf)       \
  X(FRAME, VAL, float, trace_total)    \
  X(FRAME, OUT, EyeVertex, eye)        \
  PR_ARGS_PT_RESAMPLE(X, X)

// --resample: the paths' candidates, offered by pt_shade and pt_shadow to their pixel's
// reservoir (shared/resample.h).
#define PR_ARGS_PT_RESAMPLE(F, X)          \
  F(FRAME, VAL, ResampleParams, rsp)       \
  X(FRAME, OUT, PathTrack, rs_track)       \
  X(FRAME, OUT, PathReservoir, rs_res)     \
  X(FRAME, OUT, PathReservoir, rs_pending) \
  X(FRAME, OUT, DirectReservoir, di_res)   \
  X(FRAME, OUT, DirectReservoir, di_pending)

#define PR_ARGS_PT_SHADOW(F, X)           \
  PR_ARGS_SCENE(F, X)                     \
  X(FRAME, OUT, float4, radiance)         \
  X(FRAME, IN, ShadowRay, shadows)        \
  X(FRAME, OUT, uint, rays)               \
  X(FRAME, IN, uint, shadow_queue)        \
  X(PASS, VAL, uint, count)               \
  X(PASS, VAL, uint, base)                \
  X(FRAME, VAL, uint, seed)               \
  X(FRAME, VAL, uint, frame)              \
  X(PASS, VAL, uint, sample)              \
  X(FRAME, VAL, uint, resample)           \
  X(FRAME, OUT, PathReservoir, rs_res)    \
  X(FRAME, IN, PathReservoir, rs_pending) \
  X(FRAME, OUT, DirectReservoir, di_res)  \
  X(FRAME, IN, DirectReservoir, di_pending)

// pt_resample: each pixel sample's reservoir with its neighbours' and the previous frame's by
// reconnection, into its radiance and history_out (one pass over the film's pixels [first, end)).
// temporal: `history` holds this pass's reservoirs of the previous frame, seen by prev_cam, and
// `moved` (rsp.moved_count boxes) where the scene changed since, prev_vertices and prev_instances
// the previous frame's shapes (GpuScene::previousVertices), prev_sweeps its sweeps (--shutter);
// cam_steps the camera over the shutter, as pt_generate's.
#define PR_ARGS_PT_RESAMPLE_SPATIAL(F, X)       \
  PR_ARGS_SCENE(F, X)                           \
  X(FRAME, VAL, ResampleParams, rsp)            \
  X(FRAME, IN, EyeVertex, eye)                  \
  X(FRAME, IN, PathReservoir, rs_res)           \
  X(FRAME, IN, DirectReservoir, di_res)         \
  X(FRAME, OUT, float4, radiance)               \
  X(FRAME, VAL, uint, seed)                     \
  X(FRAME, VAL, uint, frame)                    \
  X(PASS, VAL, uint, sample)                    \
  X(FRAME, VAL, uint, first)                    \
  X(FRAME, VAL, uint, end)                      \
  X(FRAME, OUT, uint, rays)                     \
  X(PASS, VAL, uint, temporal)                  \
  X(PASS, IN, PathHistory, history)             \
  X(PASS, OUT, PathHistory, history_out)        \
  X(FRAME, VAL, CameraParams, prev_cam)         \
  X(FRAME, VAL, CameraParams, cam)              \
  X(FRAME, IN, MovedInstance, moved)            \
  X(FRAME, IN, ShadingVertex, prev_vertices)    \
  X(FRAME, IN, ShadingInstance, prev_instances) \
  X(FRAME, VAL, uint, stamp)                    \
  X(FRAME, IN, float, prev_sweeps)              \
  X(FRAME, VAL, uint, prev_sweep_count)         \
  X(FRAME, IN, CameraParams, cam_steps)         \
  X(FRAME, VAL, uint, cam_step_count)           \
  PR_ARGS_PIXEL_LIST(X, X)

// ---- The film (kernels/accumulate.cl) ----

#define PR_ARGS_ACCUMULATE(F, X)   \
  F(FRAME, IN, float4, radiance)   \
  X(FRAME, OUT, float4, film)      \
  X(FRAME, OUT, uint, bad_samples) \
  X(FRAME, VAL, uint, count)       \
  X(FRAME, VAL, uint, pixel_count) \
  PR_ARGS_PIXEL_LIST(X, X)

#define PR_ARGS_SPLAT_FILM(F, X) \
  F(FRAME, OUT, uint, splat)     \
  X(FRAME, OUT, float4, film)    \
  X(FRAME, VAL, float, scale)    \
  X(FRAME, VAL, uint, clear)     \
  X(FRAME, VAL, uint, by_count)  \
  X(FRAME, VAL, uint, first)     \
  X(FRAME, VAL, uint, end)

// adaptive_plan (--noise-threshold): one work-item per pixel of the film's range, after the
// pilot passes (kernels/adaptive.cl).
#define PR_ARGS_ADAPTIVE_PLAN(F, X) \
  F(FRAME, IN, float4, film)        \
  X(FRAME, IN, float4, odd)         \
  X(FRAME, OUT, uint, budget)       \
  X(FRAME, VAL, uint, width)        \
  X(FRAME, VAL, uint, first)        \
  X(FRAME, VAL, uint, end)          \
  X(FRAME, VAL, uint, radius)       \
  X(FRAME, VAL, uint, pilot)        \
  X(FRAME, VAL, uint, spp)          \
  X(FRAME, VAL, float, threshold)   \
  X(FRAME, OUT, uint, max_budget)

// adaptive_list: one work-item per pixel of the film's range; appends those that take pass
// `sample` to `pixels`, their count to *count.
#define PR_ARGS_ADAPTIVE_LIST(F, X) \
  F(FRAME, IN, uint, budget)        \
  X(PASS, VAL, uint, sample)        \
  X(FRAME, VAL, uint, end)          \
  X(FRAME, OUT, uint, pixels)       \
  X(FRAME, OUT, uint, count)

// aov (--aov): one work-item per pixel, every sample pass in one launch (kernels/aov.cl).
#define PR_ARGS_AOV(F, X)               \
  PR_ARGS_SCENE(F, X)                   \
  X(FRAME, VAL, CameraParams, cam)      \
  X(FRAME, IN, CameraParams, cam_steps) \
  X(FRAME, VAL, uint, cam_step_count)   \
  X(FRAME, VAL, CameraParams, prev_cam) \
  X(FRAME, IN, float, prev_inst)        \
  X(FRAME, IN, float4, prev_pos)        \
  X(FRAME, IN, uint, tri_object)        \
  X(FRAME, IN, uint, inst_object)       \
  X(FRAME, OUT, float, aov)             \
  X(FRAME, VAL, uint, static_vertices)  \
  X(FRAME, VAL, uint, static_triangles) \
  X(FRAME, VAL, uint, seed)             \
  X(FRAME, VAL, uint, jitter_frame)     \
  X(FRAME, VAL, uint, spp)              \
  X(FRAME, VAL, uint, max_depth)        \
  X(FRAME, VAL, uint, end)

// Every kernel with a table: K(kernel name, the host's argument struct, its table).
#define PR_KERNEL_TABLES(K)                                    \
  K(invalidate, InvalidateArgs, PR_ARGS_INVALIDATE)            \
  K(light_trace, LightTraceArgs, PR_ARGS_LIGHT_TRACE)          \
  K(eye_hit, EyeHitArgs, PR_ARGS_EYE_HIT)                      \
  K(connect, ConnectArgs, PR_ARGS_CONNECT)                     \
  K(connect_shadow, ConnectShadowArgs, PR_ARGS_CONNECT_SHADOW) \
  K(camera_splat, CameraSplatArgs, PR_ARGS_CAMERA_SPLAT)       \
  K(pt_generate, PtGenerateArgs, PR_ARGS_PT_GENERATE)          \
  K(pt_extend, PtExtendArgs, PR_ARGS_PT_EXTEND)                \
  K(pt_shade, PtShadeArgs, PR_ARGS_PT_SHADE)                   \
  K(pt_shadow, PtShadowArgs, PR_ARGS_PT_SHADOW)                \
  K(pt_resample, PtResampleArgs, PR_ARGS_PT_RESAMPLE_SPATIAL)  \
  K(accumulate, AccumulateArgs, PR_ARGS_ACCUMULATE)            \
  K(splat_film, SplatFilmArgs, PR_ARGS_SPLAT_FILM)             \
  K(adaptive_plan, AdaptivePlanArgs, PR_ARGS_ADAPTIVE_PLAN)    \
  K(adaptive_list, AdaptiveListArgs, PR_ARGS_ADAPTIVE_LIST)    \
  K(aov, AovArgs, PR_ARGS_AOV)

// A parameter's name: scene entries carry their group's prefix (geometry and shading both have
// `instances`), the others their own name.
#define PR_ARG_NAME(role, name) PR_ARG_NAME_##role(name)
#define PR_ARG_NAME_GEOM(name) pr_g_##name
#define PR_ARG_NAME_SHADING(name) pr_sd_##name
#define PR_ARG_NAME_LIGHTS(name) pr_l_##name
#define PR_ARG_NAME_FRAME(name) name
#define PR_ARG_NAME_PASS(name) name

#ifdef PR_DEVICE_CODE
#define PR_ARG_DECL_IN(type) __global const type*
#define PR_ARG_DECL_OUT(type) __global type*
#define PR_ARG_DECL_VAL(type) type
#define PR_ARG_PARAM_FIRST_(role, kind, type, name) PR_ARG_DECL_##kind(type) PR_ARG_NAME(role, name)
#define PR_ARG_PARAM_(role, kind, type, name) , PR_ARG_PARAM_FIRST_(role, kind, type, name)
#define PR_ARG_VALUE_FIRST_(role, kind, type, name) PR_ARG_NAME(role, name)
#define PR_ARG_VALUE_(role, kind, type, name) , PR_ARG_NAME(role, name)
#define PR_ARG_FIELD_(role, kind, type, name) d.name = PR_ARG_NAME(role, name);

// The parameter list of a kernel (or helper) from its table, and the names to pass them on.
#define PR_PARAMS(table) table(PR_ARG_PARAM_FIRST_, PR_ARG_PARAM_)
#define PR_ARG_VALUES(table) table(PR_ARG_VALUE_FIRST_, PR_ARG_VALUE_)

// The scene's structs, filled from their parameters field by field (field name = entry name).
#define PR_ARG_GATHER(Type, fn, table)            \
  PR_INLINE Type fn(PR_PARAMS(table)) {           \
    Type d;                                       \
    table(PR_ARG_FIELD_, PR_ARG_FIELD_) return d; \
  }
#endif
