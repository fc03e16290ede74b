// Every struct that host and kernels share. Explicit padding, no float3 members, no bool, no
// size_t: the layout is the same on every compiler. Each struct is listed in shared/layout.h,
// which the layout test uses to compare the host's sizeof/offsetof with the device's.
#pragma once

#include "shared/common.h"

PR_NAMESPACE_BEGIN

// A ray segment [tmin, tmax] along origin + t * dir. 32 bytes.
typedef struct {
  float ox, oy, oz, tmin;
  float dx, dy, dz, tmax;
} Ray;

// The result of a closest-hit query. prim == PR_INVALID_INDEX: no hit. inst == PR_INVALID_INDEX:
// the hit is on static geometry (SSG), else the index of the dynamic instance (DSG). 32 bytes.
typedef struct {
  float t, u, v;
  u32 prim;
  u32 inst;
  u32 pad0, pad1, pad2;
} Hit;

#define PR_INVALID_INDEX 0xffffffffu

PR_NAMESPACE_END

PR_STATIC_ASSERT(sizeof(pr::dev::Ray) == 32, "Ray layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Ray, tmin) == 12, "Ray layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Ray, dx) == 16, "Ray layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Ray, tmax) == 28, "Ray layout");
PR_STATIC_ASSERT(sizeof(pr::dev::Hit) == 32, "Hit layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Hit, prim) == 12, "Hit layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Hit, inst) == 16, "Hit layout");
