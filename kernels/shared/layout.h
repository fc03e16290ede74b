// The list of shared structs and the fields whose offsets the layout test compares between
// host and device. Add every new shared struct here.
#pragma once

#include "shared/arena.h"
#include "shared/camera.h"
#include "shared/geometry.h"
#include "shared/lights.h"
#include "shared/material.h"
#include "shared/path_state.h"
#include "shared/reuse.h"
#include "shared/types.h"

#define PR_SHARED_STRUCTS(S) \
  S(Ray)                     \
  S(Hit)                     \
  S(BvhNode)                 \
  S(BvhTriangle)             \
  S(BvhTriPacket)            \
  S(BvhInstance)             \
  S(Material)                \
  S(TextureInfo)             \
  S(CameraParams)            \
  S(Light)                   \
  S(LightNode)               \
  S(ShadingVertex)           \
  S(ShadingTriangle)         \
  S(ShadingInstance)         \
  S(PathState)               \
  S(ShadowRay)               \
  S(PathReservoir)           \
  S(PathTrack)               \
  S(PathHistory)             \
  S(DirectReservoir)         \
  S(MovedInstance)           \
  S(ResampleParams)          \
  S(PathHeader)              \
  S(LightVertex)             \
  S(EyeVertex)               \
  S(EyePathRatio)            \
  S(ConnectionHistory)       \
  S(ReuseParams)

#define PR_SHARED_FIELDS(F)           \
  F(Ray, ox)                          \
  F(Ray, tmin)                        \
  F(Ray, dx)                          \
  F(Ray, tmax)                        \
  F(Hit, t)                           \
  F(Hit, v)                           \
  F(Hit, prim)                        \
  F(Hit, inst)                        \
  F(Hit, pad2)                        \
  F(BvhNode, bounds)                  \
  F(BvhNode, child)                   \
  F(BvhTriPacket, e1x)                \
  F(BvhTriPacket, e2z)                \
  F(BvhTriPacket, prim)               \
  F(BvhTriangle, prim)                \
  F(BvhTriangle, e1x)                 \
  F(BvhTriangle, e2x)                 \
  F(BvhTriangle, pad1)                \
  F(BvhInstance, world_to_object)     \
  F(BvhInstance, object_to_world)     \
  F(BvhInstance, root_node)           \
  F(BvhInstance, first_triangle)      \
  F(BvhInstance, mesh)                \
  F(BvhInstance, instance_id)         \
  F(Material, emit_r)                 \
  F(Material, flags)                  \
  F(Material, alpha_cutoff)           \
  F(Material, emission_texture)       \
  F(Material, base_uv)                \
  F(Material, mr_uv)                  \
  F(Material, emission_uv)            \
  F(Material, normal_texture)         \
  F(Material, normal_uv)              \
  F(Material, uv_sets)                \
  F(Material, spec_f0)                \
  F(Material, coat_roughness)         \
  F(Material, sigma_a)                \
  F(Material, spec_texture)           \
  F(Material, coat_roughness_uv)      \
  F(Material, coat_normal_texture)    \
  F(Material, coat_normal_uv)         \
  F(Material, sheen)                  \
  F(Material, sheen_roughness_uv)     \
  F(Material, aniso_strength)         \
  F(Material, aniso_uv)               \
  F(TextureInfo, flags)               \
  F(CameraParams, fx)                 \
  F(CameraParams, aspect)             \
  F(CameraParams, ux)                 \
  F(CameraParams, width)              \
  F(CameraParams, height)             \
  F(Light, type)                      \
  F(Light, inst)                      \
  F(Light, prim)                      \
  F(Light, le_r)                      \
  F(Light, area)                      \
  F(Light, power)                     \
  F(Light, material)                  \
  F(ShadingVertex, nx)                \
  F(ShadingVertex, v)                 \
  F(ShadingVertex, u1)                \
  F(ShadingVertex, tx)                \
  F(ShadingVertex, tw)                \
  F(ShadingTriangle, material)        \
  F(ShadingInstance, world_to_object) \
  F(ShadingInstance, first_triangle)  \
  F(ShadingInstance, moved)           \
  F(PathState, tp_r)                  \
  F(PathState, last_pdf)              \
  F(PathState, depth)                 \
  F(PathState, rng_dim)               \
  F(PathState, flags)                 \
  F(PathState, prev_x)                \
  F(PathState, prev_nx)               \
  F(PathState, lt)                    \
  F(LightNode, power)                 \
  F(LightNode, index)                 \
  F(LightNode, cos_o)                 \
  F(LightNode, r2)                    \
  F(LightNode, parent)                \
  F(ShadowRay, c_r)                   \
  F(ShadowRay, op)                    \
  F(PathReservoir, g_src)             \
  F(PathReservoir, f_r)               \
  F(PathReservoir, w_sum)             \
  F(PathReservoir, sp)                \
  F(PathHistory, d)                   \
  F(PathHistory, prim)                \
  F(PathHistory, stamp)               \
  F(DirectReservoir, wx)              \
  F(DirectReservoir, p_hat)           \
  F(DirectReservoir, m)               \
  F(MovedInstance, root)              \
  F(MovedInstance, root_before)       \
  F(MovedInstance, skip)              \
  F(MovedInstance, node)              \
  F(MovedInstance, before)            \
  F(MovedInstance, after)             \
  F(PathTrack, x1_ok)                 \
  F(PathTrack, pdf)                   \
  F(PathTrack, g_src)                 \
  F(ResampleParams, min_dist2)        \
  F(ResampleParams, moved_count)      \
  F(ResampleParams, lt_scale)         \
  F(ResampleParams, prev_known)       \
  F(PathHeader, end)                  \
  F(PathHeader, valid)                \
  F(PathHeader, escape_z)             \
  F(LightVertex, t)                   \
  F(LightVertex, ng_oct)              \
  F(LightVertex, tp_r)                \
  F(LightVertex, ns_oct)              \
  F(LightVertex, inst)                \
  F(LightVertex, b2)                  \
  F(EyeVertex, ng_oct)                \
  F(EyeVertex, ns_oct)                \
  F(EyeVertex, depth)                 \
  F(EyeVertex, b2)                    \
  F(EyePathRatio, h)                  \
  F(ConnectionHistory, tp_r)          \
  F(ConnectionHistory, slot)          \
  F(ConnectionHistory, frame)         \
  F(Light, moved)                     \
  F(Light, leaf)                      \
  F(ReuseParams, clamp)               \
  F(ReuseParams, cx)                  \
  F(ReuseParams, resample)            \
  F(ReuseParams, lt_scale)
