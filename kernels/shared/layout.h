// The list of shared structs and the fields whose offsets the layout test compares between
// host and device. Add every new shared struct here.
#pragma once

#define PR_SHARED_STRUCTS(S) \
  S(Ray)                     \
  S(Hit)                     \
  S(BvhNode)                 \
  S(BvhTriangle)             \
  S(BvhInstance)

#define PR_SHARED_FIELDS(F) \
  F(Ray, ox)                \
  F(Ray, tmin)              \
  F(Ray, dx)                \
  F(Ray, tmax)              \
  F(Hit, t)                 \
  F(Hit, v)                 \
  F(Hit, prim)              \
  F(Hit, inst)              \
  F(Hit, pad2)              \
  F(BvhNode, lo_x)          \
  F(BvhNode, hi_x)          \
  F(BvhNode, index)         \
  F(BvhNode, meta)          \
  F(BvhTriangle, prim)      \
  F(BvhTriangle, e1x)       \
  F(BvhTriangle, e2x)       \
  F(BvhTriangle, pad1)      \
  F(BvhInstance, world_to_object) \
  F(BvhInstance, object_to_world) \
  F(BvhInstance, root_node) \
  F(BvhInstance, first_triangle) \
  F(BvhInstance, mesh)      \
  F(BvhInstance, instance_id)
