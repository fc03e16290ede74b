// The list of shared structs and the fields whose offsets the layout test compares between
// host and device. Add every new shared struct here.
#pragma once

#define PR_SHARED_STRUCTS(S) \
  S(Ray)                     \
  S(Hit)

#define PR_SHARED_FIELDS(F) \
  F(Ray, ox)                \
  F(Ray, tmin)              \
  F(Ray, dx)                \
  F(Ray, tmax)              \
  F(Hit, t)                 \
  F(Hit, v)                 \
  F(Hit, prim)              \
  F(Hit, inst)              \
  F(Hit, pad2)
