// Acceleration structures: the BVH builder, the CPU reference traversal (kernels/shared/bvh.h
// compiled as C++) against brute force, the DSG's two levels, self-intersection, and the same
// rays traced on the OpenCL device.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "accel/bvh_builder.h"
#include "accel/device_accel.h"
#include "accel/scene_accel.h"
#include "shared/bvh.h"
#include "support/test_env.h"
#include "support/trace_rays.h"

namespace pr {
namespace {

using namespace pr::accel;
using dev::BvhTriangle;
using dev::Hit;
using dev::Ray;
using dev::SceneGeom;

struct Soup {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  size_t size() const { return indices.size() / 3; }
  glm::vec3 vertex(size_t t, int k) const { return positions[indices[3 * t + size_t(k)]]; }
};

// Random triangles in [-1, 1]^3 with edges of about `size`.
Soup randomSoup(size_t n, float size, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Soup s;
  for (size_t t = 0; t < n; ++t) {
    const glm::vec3 c(u(rng), u(rng), u(rng));
    for (int k = 0; k < 3; ++k) {
      s.positions.push_back(c + size * glm::vec3(u(rng), u(rng), u(rng)));
      s.indices.push_back(uint32_t(s.positions.size() - 1));
    }
  }
  return s;
}

glm::vec3 randomDir(std::mt19937& rng) {
  std::normal_distribution<float> g;
  for (;;) {
    const glm::vec3 d(g(rng), g(rng), g(rng));
    const float l = glm::length(d);
    if (l > 1e-3f) return d / l;
  }
}

Ray makeRay(glm::vec3 o, glm::vec3 d, float tmin, float tmax) {
  return Ray{o.x, o.y, o.z, tmin, d.x, d.y, d.z, tmax};
}

// Half the rays random, half aimed at a random point of a random triangle of `aim` (if any).
std::vector<Ray> randomRays(size_t n, const std::vector<glm::vec3>& aim, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-2.5f, 2.5f), t01(0.0f, 1.0f);
  std::vector<Ray> rays;
  for (size_t i = 0; i < n; ++i) {
    const glm::vec3 o(u(rng), u(rng), u(rng));
    glm::vec3 d = randomDir(rng);
    if (i % 2 == 1 && !aim.empty()) {
      const glm::vec3 target = aim[rng() % aim.size()];
      if (glm::length(target - o) > 1e-3f) d = glm::normalize(target - o);
    }
    // Some rays end early, some start late: the [tmin, tmax] window must be honoured.
    const float tmax = i % 5 == 0 ? 0.5f + 3.0f * t01(rng) : PR_INF_F;
    const float tmin = i % 7 == 0 ? t01(rng) : 0.0f;
    rays.push_back(makeRay(o, d, tmin, tmax));
  }
  return rays;
}

std::vector<glm::vec3> triangleCentres(const Soup& s) {
  std::vector<glm::vec3> c;
  for (size_t t = 0; t < s.size(); ++t)
    c.push_back((s.vertex(t, 0) + s.vertex(t, 1) + s.vertex(t, 2)) / 3.0f);
  return c;
}

std::vector<BvhTriangle> packSoup(const Soup& s, uint32_t primBase = 0) {
  std::vector<BvhTriangle> out;
  for (size_t t = 0; t < s.size(); ++t) {
    const BvhTriangle tri =
        packTriangle(s.vertex(t, 0), s.vertex(t, 1), s.vertex(t, 2), primBase + uint32_t(t));
    if (!zeroArea(tri)) out.push_back(tri);
  }
  return out;
}

// Every triangle, nearest strictly closer hit wins: what the BVH must reproduce.
Hit bruteForce(const std::vector<BvhTriangle>& tris, Ray ray, uint32_t inst = PR_INVALID_INDEX) {
  Hit best = dev::hit_none();
  const dev::float3 o = dev::make_float3(ray.ox, ray.oy, ray.oz);
  const dev::float3 d = dev::make_float3(ray.dx, ray.dy, ray.dz);
  float tmax = ray.tmax;
  for (const BvhTriangle& tri : tris) {
    float t, u, v;
    if (dev::intersect_triangle(&tri, o, d, ray.tmin, tmax, &t, &u, &v)) {
      tmax = t;
      best.t = t, best.u = u, best.v = v, best.prim = tri.prim, best.inst = inst;
    }
  }
  return best;
}

bool relClose(float a, float b, float rel) {
  return std::fabs(a - b) <= rel * std::fmax(std::fabs(a), std::fabs(b));
}

// Compares closest hits; failures are counted and the first few described.
struct HitChecker {
  int failures = 0;
  int hits = 0;
  void check(const Hit& got, const Hit& want, size_t ray, const std::string& what,
             float rel = 1e-5f) {
    const bool ok = got.prim == want.prim && got.inst == want.inst &&
                    (want.prim == PR_INVALID_INDEX || relClose(got.t, want.t, rel));
    hits += want.prim != PR_INVALID_INDEX;
    if (!ok && ++failures <= 5)
      ADD_FAILURE() << what << " ray " << ray << ": got prim " << got.prim << " inst " << got.inst
                    << " t " << got.t << ", want prim " << want.prim << " inst " << want.inst
                    << " t " << want.t;
  }
};

// ---------------------------------------------------------------------------------------------
// Builder

// Every node's box holds its children's boxes / its triangles; every triangle is in one leaf.
void checkStructure(const std::vector<BinaryNode>& nodes, const std::vector<BvhTriangle>& tris) {
  ASSERT_FALSE(nodes.empty());
  EXPECT_LE(bvhDepth(nodes), PR_BVH_STACK_SIZE);
  std::vector<int> seen(tris.size(), 0);
  auto inside = [](const BinaryNode& outer, const BinaryNode& inner) {
    return outer.lo_x <= inner.lo_x && outer.lo_y <= inner.lo_y && outer.lo_z <= inner.lo_z &&
           outer.hi_x >= inner.hi_x && outer.hi_y >= inner.hi_y && outer.hi_z >= inner.hi_z;
  };
  for (uint32_t i = 0; i < nodes.size(); ++i) {
    const BinaryNode& n = nodes[i];
    if (n.meta & PR_BVH_LEAF_BIT) {
      const uint32_t count = n.meta & ~PR_BVH_LEAF_BIT;
      EXPECT_LE(count, 4u);
      ASSERT_LE(uint64_t(n.index) + count, tris.size());
      for (uint32_t k = n.index; k < n.index + count; ++k) {
        ++seen[k];
        const BvhTriangle& t = tris[k];
        for (const glm::vec3 p : {glm::vec3(t.v0x, t.v0y, t.v0z),
                                  glm::vec3(t.v0x + t.e1x, t.v0y + t.e1y, t.v0z + t.e1z),
                                  glm::vec3(t.v0x + t.e2x, t.v0y + t.e2y, t.v0z + t.e2z)}) {
          // v0 + e is rounded: allow an ulp or two.
          const float eps = 1e-6f * (1.0f + glm::length(p));
          EXPECT_TRUE(p.x >= n.lo_x - eps && p.x <= n.hi_x + eps && p.y >= n.lo_y - eps &&
                      p.y <= n.hi_y + eps && p.z >= n.lo_z - eps && p.z <= n.hi_z + eps);
        }
      }
    } else {
      EXPECT_TRUE(inside(n, nodes[i + 1])) << "node " << i;
      EXPECT_TRUE(inside(n, nodes[n.index])) << "node " << i;
    }
  }
  for (size_t k = 0; k < seen.size(); ++k) ASSERT_EQ(seen[k], 1) << "triangle slot " << k;
}

// Exponentially spaced triangles make SAH peel one off at a time: a chain far deeper than the
// stack unless the depth cap steps in.
Soup exponentialSoup(size_t n) {
  Soup s;
  float x = 1.0f;
  for (size_t t = 0; t < n; ++t, x *= 1.5f) {
    const float w = x * 0.01f;
    for (const glm::vec3 p : {glm::vec3(x, 0, 0), glm::vec3(x + w, 0, w), glm::vec3(x, w, w)}) {
      s.positions.push_back(p);
      s.indices.push_back(uint32_t(s.positions.size() - 1));
    }
  }
  return s;
}

float wideBoundOf(const WideBvh& w, uint32_t node, int b, int i) {
  float f;
  std::memcpy(&f, &w.words[wideBound(w.width, node, b, i)], 4);
  return f;
}

// The wide tree: every child box holds what lies below it, every leaf is one packet referenced
// once, every triangle sits in exactly one packet lane, unused slots and lanes are inert, and
// no path needs more stack than the traversal has.
void checkWide(const TriangleBvh& t) {
  const WideBvh& w = t.wide;
  ASSERT_GT(w.nodeCount(), 0u);
  EXPECT_LE(w.stackNeed, PR_BVH_STACK_SIZE);
  ASSERT_EQ(t.packets.size(), w.leaves.size());
  std::vector<int> packetSeen(t.packets.size(), 0), nodeSeen(w.nodeCount(), 0);
  std::vector<int> primSeen(t.triangles.size() + 1, 0);
  uint32_t primMax = 0;
  for (const auto& tri : t.triangles) primMax = std::max(primMax, tri.prim);
  primSeen.assign(size_t(primMax) + 1, 0);
  // Box of a subtree's triangles, from its packets.
  std::function<Aabb(uint32_t)> content = [&](uint32_t ref) {
    Aabb box;
    if (ref & PR_BVH_LEAF_BIT) {
      const dev::BvhTriPacket& p = t.packets[ref & ~PR_BVH_LEAF_BIT];
      for (int l = 0; l < PR_BVH_PACKET; ++l) {
        if (p.prim[l] == PR_INVALID_INDEX) {
          EXPECT_EQ(p.e1x[l] * p.e2y[l] - p.e1y[l] * p.e2x[l], 0.0f);
          continue;
        }
        const glm::vec3 v0(p.v0x[l], p.v0y[l], p.v0z[l]);
        box.grow(v0);
        box.grow(v0 + glm::vec3(p.e1x[l], p.e1y[l], p.e1z[l]));
        box.grow(v0 + glm::vec3(p.e2x[l], p.e2y[l], p.e2z[l]));
      }
      return box;
    }
    for (int i = 0; i < w.width; ++i) {
      const uint32_t c = w.words[wideChild(w.width, ref, i)];
      if (c == PR_INVALID_INDEX) {
        EXPECT_EQ(wideBoundOf(w, ref, 0, i), INFINITY);
        EXPECT_EQ(wideBoundOf(w, ref, 1, i), -INFINITY);
        continue;
      }
      const Aabb inner = content(c);
      const float eps = 1e-6f * (1.0f + glm::length(inner.hi) + glm::length(inner.lo));
      for (int a = 0; a < 3; ++a) {
        EXPECT_LE(wideBoundOf(w, ref, 2 * a, i), inner.lo[a] + eps)
            << "node " << ref << " child " << i;
        EXPECT_GE(wideBoundOf(w, ref, 2 * a + 1, i), inner.hi[a] - eps)
            << "node " << ref << " child " << i;
      }
      box.grow(inner);
      if (c & PR_BVH_LEAF_BIT) {
        ++packetSeen[c & ~PR_BVH_LEAF_BIT];
        const dev::BvhTriPacket& p = t.packets[c & ~PR_BVH_LEAF_BIT];
        for (int l = 0; l < PR_BVH_PACKET; ++l)
          if (p.prim[l] != PR_INVALID_INDEX) ++primSeen[p.prim[l]];
      } else {
        EXPECT_GT(c, ref) << "children follow their parent";
        ++nodeSeen[c];
      }
    }
    return box;
  };
  content(0);
  for (size_t k = 1; k < nodeSeen.size(); ++k) EXPECT_EQ(nodeSeen[k], 1) << "node " << k;
  for (size_t k = 0; k < packetSeen.size(); ++k) EXPECT_EQ(packetSeen[k], 1) << "packet " << k;
  for (const auto& tri : t.triangles) EXPECT_EQ(primSeen[tri.prim], 1) << "prim " << tri.prim;
}

// A box moved by a matrix holds its eight corners moved; an empty one stays empty, its bounds
// the infinities they were.
TEST(Aabb, TransformedHoldsTheCornersAndAnEmptyBoxStaysEmpty) {
  Aabb box;
  box.grow(glm::vec3(-1.0f, 0.0f, 2.0f));
  box.grow(glm::vec3(1.0f, 2.0f, 3.0f));
  const glm::mat4 m = glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(5.0f, 0.0f, 0.0f)),
                                  glm::radians(90.0f), glm::vec3(0.0f, 0.0f, 1.0f));
  const Aabb moved = box.transformed(m);
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 p = glm::vec3(m * glm::vec4(box.corner(c), 1.0f));
    for (int a = 0; a < 3; ++a) {
      EXPECT_LE(moved.lo[a], p[a]);
      EXPECT_GE(moved.hi[a], p[a]);
    }
  }
  EXPECT_NEAR(moved.lo.x, 3.0f, 1e-5f);  // y in [0, 2] turned to x in [-2, 0], then moved by 5
  EXPECT_NEAR(moved.hi.x, 5.0f, 1e-5f);
  for (const glm::mat4& t : {glm::mat4(1.0f), m}) {
    const Aabb e = Aabb{}.transformed(t);
    EXPECT_TRUE(e.empty());
    EXPECT_EQ(e.lo, Aabb{}.lo);
    EXPECT_EQ(e.hi, Aabb{}.hi);
  }
}

TEST(BvhBuild, WideTreesOfEveryWidth) {
  for (int width : {2, 4, 8}) {
    for (size_t n : {0, 1, 3, 5, 100, 3000}) {
      SCOPED_TRACE("width " + std::to_string(width) + ", n = " + std::to_string(n));
      const Soup s = randomSoup(n, 0.1f, 21 + uint32_t(n));
      BuildOptions o;
      o.width = width;
      const TriangleBvh t = buildTriangleBvh(s.positions, s.indices, 7, o, "soup");
      EXPECT_EQ(t.wide.width, width);
      checkWide(t);
      if (n > 100) {
        // The collapse opens children until `width` are gathered: no node of one child, and
        // more than 3 children on average once nodes may hold 4 or more.
        const double children = double(t.wide.nodeCount() - 1 + t.packets.size());
        const double fill = children / double(t.wide.nodeCount());
        EXPECT_GE(fill, width == 2 ? 1.99 : 3.0) << fill;
      }
    }
  }
  // The deepest chain SAH can make still fits the stack at every width (the depth cap is
  // lowered until it does).
  const Soup deep = exponentialSoup(150);
  for (int width : {2, 4, 8}) {
    BuildOptions o;
    o.width = width;
    checkWide(buildTriangleBvh(deep.positions, deep.indices, 0, o, "deep"));
  }
}

TEST(BvhBuild, StructureOfRandomSoups) {
  for (size_t n : {0, 1, 2, 5, 100, 3000}) {
    SCOPED_TRACE("n = " + std::to_string(n));
    const Soup s = randomSoup(n, 0.1f, 11 + uint32_t(n));
    StaticAccel a;
    a.build(s.positions, s.indices);
    checkStructure(a.nodes(), a.triangles());
    EXPECT_EQ(a.triangles().size(), n);
    std::vector<int> prims(n, 0);
    for (const auto& t : a.triangles()) ++prims[t.prim];
    for (int c : prims) EXPECT_EQ(c, 1);
  }
}

TEST(BvhBuild, ThreadedBuildEqualsSerialBuild) {
  const Soup s = randomSoup(40000, 0.02f, 8);
  BuildOptions serial;
  serial.threads = false;
  const TriangleBvh a = buildTriangleBvh(s.positions, s.indices, 0, serial, "serial");
  const TriangleBvh b = buildTriangleBvh(s.positions, s.indices, 0, BuildOptions{}, "threaded");
  ASSERT_EQ(a.binary.size(), b.binary.size());
  EXPECT_EQ(std::memcmp(a.binary.data(), b.binary.data(), a.binary.size() * sizeof(BinaryNode)), 0);
  EXPECT_EQ(a.wide.words, b.wide.words);
  ASSERT_EQ(a.packets.size(), b.packets.size());
  EXPECT_EQ(
      std::memcmp(a.packets.data(), b.packets.data(), a.packets.size() * sizeof(dev::BvhTriPacket)),
      0);
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  EXPECT_EQ(
      std::memcmp(a.triangles.data(), b.triangles.data(), a.triangles.size() * sizeof(BvhTriangle)),
      0);
  EXPECT_EQ(a.stats.depth, b.stats.depth);
  EXPECT_EQ(a.stats.leaves, b.stats.leaves);
  checkStructure(b.binary, b.triangles);
}

TEST(BvhBuild, RejectsBadInput) {
  StaticAccel a;
  EXPECT_THROW(a.build({glm::vec3(0.0f)}, {0, 0}), InputError);
  EXPECT_THROW(a.build({glm::vec3(0.0f)}, {0, 0, 1}), InputError);
  EXPECT_THROW(a.build({glm::vec3(NAN, 0.0f, 0.0f)}, {0, 0, 0}), InputError);
  BuildOptions o;
  o.maxDepth = PR_BVH_STACK_SIZE + 1;
  EXPECT_THROW(buildBvh({}, o), RuntimeError);
}

TEST(BvhBuild, DepthNeverExceedsTheStack) {
  const Soup deep = exponentialSoup(150);
  StaticAccel a;
  a.build(deep.positions, deep.indices);
  EXPECT_LE(a.stats().depth, PR_BVH_STACK_SIZE);
  checkStructure(a.nodes(), a.triangles());
  // A tight cap on an ordinary soup, and the result still traces right.
  const Soup s = randomSoup(2000, 0.1f, 5);
  BuildOptions o;
  o.maxDepth = 10;
  a.build(s.positions, s.indices, o);
  EXPECT_LE(a.stats().depth, 10);
  checkStructure(a.nodes(), a.triangles());
  const HostGeom hg(a, nullptr);
  const SceneGeom g = hg.geom();
  const auto tris = packSoup(s);
  HitChecker c;
  const auto rays = randomRays(500, triangleCentres(s), 9);
  for (size_t i = 0; i < rays.size(); ++i) {
    Hit h;
    dev::intersect_static(&g, rays[i], &h);
    c.check(h, bruteForce(tris, rays[i]), i, "depth-capped");
  }
  EXPECT_GT(c.hits, 100);
}

// ---------------------------------------------------------------------------------------------
// SSG traversal against brute force

void expectStaticMatchesBruteForce(const Soup& s, size_t rayCount, uint32_t seed, bool exactPrim) {
  StaticAccel a;
  a.build(s.positions, s.indices);
  const HostGeom hg(a, nullptr);
  const SceneGeom g = hg.geom();
  const auto tris = packSoup(s);
  const auto rays = randomRays(rayCount, triangleCentres(s), seed);
  HitChecker c;
  for (size_t i = 0; i < rays.size(); ++i) {
    Hit h;
    const int any = dev::intersect_static(&g, rays[i], &h);
    const Hit want = bruteForce(tris, rays[i]);
    EXPECT_EQ(any, want.prim != PR_INVALID_INDEX);
    if (!exactPrim && h.prim != want.prim && h.prim != PR_INVALID_INDEX &&
        want.prim != PR_INVALID_INDEX) {
      // Coincident or coplanar triangles: either is right if it is hit at the same t (an ulp
      // apart for coplanar ones: a box may then cull the other by that ulp).
      EXPECT_TRUE(relClose(h.t, want.t, 1e-6f)) << "ray " << i << ": " << h.t << " vs " << want.t;
      continue;
    }
    c.check(h, want, i, "static");
    // Any hit agrees with the closest hit's existence, for the full window and a shorter one.
    EXPECT_EQ(dev::occluded_static(&g, rays[i]), want.prim != PR_INVALID_INDEX) << "ray " << i;
    if (want.prim != PR_INVALID_INDEX) {
      Ray shorter = rays[i];
      shorter.tmax = want.t * 0.999f;
      EXPECT_EQ(dev::occluded_static(&g, shorter), 0) << "ray " << i;
      EXPECT_EQ(dev::occluded_scene(&g, rays[i]), 1) << "ray " << i;
    }
  }
  if (exactPrim && s.size() > 10) {
    EXPECT_GT(c.hits, int(rayCount / 5));
  }
}

TEST(StaticTraversal, MatchesBruteForceOnRandomSoups) {
  for (size_t n : {0, 1, 2, 3, 17, 200, 10000}) {
    SCOPED_TRACE("n = " + std::to_string(n));
    expectStaticMatchesBruteForce(randomSoup(n, n > 1000 ? 0.05f : 0.3f, 100 + uint32_t(n)),
                                  n > 1000 ? 1500 : 3000, 7 + uint32_t(n), true);
  }
}

TEST(StaticTraversal, DegenerateSoups) {
  // Many copies of one triangle: all centroids equal.
  Soup same;
  same.positions = {{-0.5f, -0.5f, 0.0f}, {0.5f, -0.5f, 0.1f}, {0.0f, 0.5f, -0.1f}};
  for (int i = 0; i < 500; ++i) same.indices.insert(same.indices.end(), {0, 1, 2});
  {
    SCOPED_TRACE("identical");
    expectStaticMatchesBruteForce(same, 1000, 1, false);
  }
  // Same centroid, different sizes (nested triangles).
  Soup nested;
  for (int i = 0; i < 300; ++i) {
    const float k = 0.01f + 0.005f * float(i);
    for (const glm::vec3 p : {glm::vec3(-k, -k, 0.2f * k), glm::vec3(2 * k, -k, -0.4f * k),
                              glm::vec3(-k, 2 * k, 0.2f * k)}) {
      nested.positions.push_back(p);
      nested.indices.push_back(uint32_t(nested.positions.size() - 1));
    }
  }
  {
    SCOPED_TRACE("nested");
    expectStaticMatchesBruteForce(nested, 1000, 2, false);
  }
  // Zero-area triangles (points, repeated vertices) among ordinary ones: never hit.
  Soup mixed = randomSoup(300, 0.3f, 3);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 300; ++i) {
    const glm::vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    mixed.positions.insert(mixed.positions.end(), {a, i % 3 ? b : a, i % 3 == 1 ? b : a});
    const uint32_t base = uint32_t(mixed.positions.size() - 3);
    mixed.indices.insert(mixed.indices.end(), {base, base + 1, base + 2});
  }
  {
    SCOPED_TRACE("zero-area");
    expectStaticMatchesBruteForce(mixed, 2000, 5, true);
  }
  // Flat: every triangle in the plane z = 0, rays from both sides and in the plane.
  Soup flat = randomSoup(1000, 0.1f, 6);
  for (auto& p : flat.positions) p.z = 0.0f;
  {
    SCOPED_TRACE("flat");
    expectStaticMatchesBruteForce(flat, 2000, 7, false);  // overlapping coplanar triangles
  }
  // Deep chain (the depth-capped case).
  {
    SCOPED_TRACE("exponential");
    expectStaticMatchesBruteForce(exponentialSoup(150), 500, 8, true);
  }
}

TEST(StaticTraversal, EmptySceneHitsNothing) {
  StaticAccel a;
  a.build({}, {});
  const HostGeom hg(a, nullptr);
  const SceneGeom g = hg.geom();
  Hit h;
  EXPECT_EQ(dev::intersect_scene(&g, makeRay({0, 0, 0}, {0, 0, 1}, 0.0f, PR_INF_F), &h), 0);
  EXPECT_EQ(h.prim, PR_INVALID_INDEX);
  EXPECT_EQ(dev::occluded_scene(&g, makeRay({0, 0, 0}, {0, 0, 1}, 0.0f, PR_INF_F)), 0);
}

TEST(StaticTraversal, AxisAlignedRaysAndFaces) {
  // A grid of axis-aligned quads probed by axis-aligned rays (zero direction components).
  Soup s;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const float x = float(i) * 0.2f - 1.0f, y = float(j) * 0.2f - 1.0f, z = float(i + j) * 0.05f;
      const uint32_t b = uint32_t(s.positions.size());
      s.positions.insert(s.positions.end(),
                         {{x, y, z}, {x + 0.2f, y, z}, {x + 0.2f, y + 0.2f, z}, {x, y + 0.2f, z}});
      s.indices.insert(s.indices.end(), {b, b + 1, b + 2, b, b + 2, b + 3});
    }
  StaticAccel a;
  a.build(s.positions, s.indices);
  const HostGeom hg(a, nullptr);
  const SceneGeom g = hg.geom();
  const auto tris = packSoup(s);
  HitChecker c;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.1f, 1.1f);
  for (int i = 0; i < 2000; ++i) {
    const Ray r = makeRay({u(rng), u(rng), -1.0f}, {0, 0, 1}, 0.0f, PR_INF_F);
    Hit h;
    dev::intersect_static(&g, r, &h);
    const Hit want = bruteForce(tris, r);
    if (h.prim != want.prim && want.prim != PR_INVALID_INDEX && h.prim != PR_INVALID_INDEX) {
      EXPECT_EQ(h.t, want.t);  // on a shared diagonal or edge: either quad half
      continue;
    }
    c.check(h, want, size_t(i), "axis-aligned");
  }
  EXPECT_GT(c.hits, 1500);
}

// ---------------------------------------------------------------------------------------------
// DSG

struct DynamicScene {
  explicit DynamicScene(int width = PR_BVH_WIDTH) : accel(width) {}
  std::vector<Soup> meshes;
  DynamicAccel accel;
  std::vector<InstanceInput> instances;
};

glm::mat4 randomTransform(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), s(0.3f, 1.5f);
  const glm::quat q =
      glm::normalize(glm::quat(u(rng), u(rng), u(rng), u(rng)) + glm::quat(0.01f, 0, 0, 0));
  glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(u(rng), u(rng), u(rng)) * 1.5f);
  m = m * glm::mat4_cast(q);
  return glm::scale(m, glm::vec3(s(rng), s(rng), s(rng)));  // non-uniform
}

void makeDynamic(DynamicScene& d, uint32_t seed) {
  d.meshes = {randomSoup(400, 0.25f, seed), randomSoup(1, 0.8f, seed + 1),
              randomSoup(0, 0.1f, seed + 2), randomSoup(1500, 0.1f, seed + 3)};
  for (const Soup& m : d.meshes) d.accel.addMesh(m.positions, m.indices);
}

void setFrame(DynamicScene& d, int frame) {
  std::mt19937 rng(1000 + uint32_t(frame));
  d.instances.clear();
  for (uint32_t i = 0; i < 9; ++i) d.instances.push_back({i % 4, randomTransform(rng)});
  if (frame == 2)
    d.instances[5].objectToWorld = glm::scale(glm::mat4(1.0f), glm::vec3(1, 0, 1));  // singular
  d.accel.setInstances(d.instances);
}

// Brute force over every instance in object space, using the records' world-to-object matrix.
Hit bruteForceDynamic(const DynamicScene& d, const std::vector<std::vector<BvhTriangle>>& packed,
                      Ray ray) {
  Hit best = dev::hit_none();
  const dev::BvhRay world = dev::bvh_ray_from(ray);
  dev::SceneGeom still{};  // no motion: the records' own transforms
  still.motion_steps = 1;
  for (const dev::BvhInstance& rec : d.accel.instances()) {
    const dev::BvhRay local = dev::instance_ray(&still, &rec, &world);
    Ray r = makeRay({local.o.x, local.o.y, local.o.z}, {local.d.x, local.d.y, local.d.z}, ray.tmin,
                    ray.tmax);
    r.tmax = best.prim == PR_INVALID_INDEX ? ray.tmax : best.t;
    const Hit h = bruteForce(packed[rec.mesh], r, rec.instance_id);
    if (h.prim != PR_INVALID_INDEX) best = h;
  }
  return best;
}

std::vector<std::vector<BvhTriangle>> packMeshes(const DynamicScene& d) {
  std::vector<std::vector<BvhTriangle>> out;
  uint32_t base = 0;
  for (const Soup& m : d.meshes) {
    out.push_back(packSoup(m, base));
    base += uint32_t(m.size());
  }
  return out;
}

// World-space triangles of every instance (the transform checked independently).
std::vector<std::vector<BvhTriangle>> worldTriangles(const DynamicScene& d) {
  std::vector<std::vector<BvhTriangle>> out;
  std::vector<uint32_t> bases;
  uint32_t base = 0;
  for (const Soup& m : d.meshes) bases.push_back(base), base += uint32_t(m.size());
  for (const InstanceInput& in : d.instances) {
    const Soup& m = d.meshes[in.mesh];
    std::vector<BvhTriangle> tris;
    for (size_t t = 0; t < m.size(); ++t) {
      glm::vec3 v[3];
      for (int k = 0; k < 3; ++k)
        v[k] = glm::vec3(in.objectToWorld * glm::vec4(m.vertex(t, k), 1.0f));
      tris.push_back(packTriangle(v[0], v[1], v[2], bases[in.mesh] + uint32_t(t)));
    }
    out.push_back(tris);
  }
  return out;
}

std::vector<glm::vec3> instanceCentres(const DynamicScene& d) {
  std::vector<glm::vec3> c;
  for (const InstanceInput& in : d.instances)
    for (const glm::vec3& p : triangleCentres(d.meshes[in.mesh]))
      c.push_back(glm::vec3(in.objectToWorld * glm::vec4(p, 1.0f)));
  return c;
}

TEST(DynamicTraversal, MatchesBruteForceOverFrames) {
  DynamicScene d;
  makeDynamic(d, 40);
  const auto packed = packMeshes(d);
  StaticAccel empty;
  empty.build({}, {});
  for (int frame = 0; frame < 4; ++frame) {
    SCOPED_TRACE("frame " + std::to_string(frame));
    setFrame(d, frame);
    EXPECT_LE(d.accel.tlas().stackNeed, PR_BVH_STACK_SIZE);
    // Meshes 0, 1, 3 are hittable; mesh 2 is empty, and frame 2 has one singular instance.
    EXPECT_EQ(d.accel.instances().size(), frame == 2 ? 6u : 7u);
    const HostGeom hg(empty, &d.accel);
    const SceneGeom g = hg.geom();
    const auto world = worldTriangles(d);
    const auto rays = randomRays(2000, instanceCentres(d), 50 + uint32_t(frame));
    HitChecker c;
    int worldMismatch = 0, worldFar = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      Hit h;
      dev::intersect_dynamic(&g, rays[i], &h);
      const Hit want = bruteForceDynamic(d, packed, rays[i]);
      c.check(h, want, i, "dynamic");
      EXPECT_EQ(dev::occluded_dynamic(&g, rays[i]), want.prim != PR_INVALID_INDEX) << "ray " << i;
      Hit whole;
      dev::intersect_scene(&g, rays[i], &whole);
      c.check(whole, want, i, "scene (DSG only)");
      // Against world-space triangles: same answer up to the transform's rounding.
      Hit ws = dev::hit_none();
      for (size_t k = 0; k < d.instances.size(); ++k) {
        if (d.accel.instanceBounds()[k].empty()) continue;
        Ray r = rays[i];
        if (ws.prim != PR_INVALID_INDEX) r.tmax = ws.t;
        const Hit hk = bruteForce(world[k], r, uint32_t(k));
        if (hk.prim != PR_INVALID_INDEX) ws = hk;
      }
      if (ws.prim != h.prim || ws.inst != h.inst) {
        ++worldMismatch;
      } else if (ws.prim != PR_INVALID_INDEX) {
        // Grazing hits magnify the vertices' rounding into t: a few may differ more.
        EXPECT_TRUE(relClose(ws.t, h.t, 1e-2f)) << ws.t << " vs " << h.t;
        worldFar += !relClose(ws.t, h.t, 1e-4f);
      }
    }
    EXPECT_GT(c.hits, 400);
    EXPECT_LE(worldMismatch, 4) << "object-space and world-space answers differ too often";
    EXPECT_LE(worldFar, 10) << "object-space and world-space t differ too often";
  }
}

TEST(DynamicTraversal, NoInstancesAndBadMesh) {
  DynamicAccel d;
  d.setInstances({});
  EXPECT_EQ(d.instances().size(), 0u);
  EXPECT_THROW(d.setInstances({{3, glm::mat4(1.0f)}}), InputError);
}

// Deforming meshes under a shutter: meshes 0 and 2 of three each have their own motion steps
// (mesh 1 none), so their steps' packets lie in two runs end to end.
struct DeformingScene {
  DynamicScene d;
  std::vector<std::vector<std::vector<glm::vec3>>> steps;  // per mesh; empty: it does not deform
};

constexpr uint32_t kDeformSteps = 4;  // even: at the frame's time a ray blends two of them

void makeDeforming(DeformingScene* s) {
  s->d.meshes = {randomSoup(500, 0.2f, 61), randomSoup(300, 0.2f, 62), randomSoup(700, 0.15f, 63)};
  for (const Soup& m : s->d.meshes) s->d.accel.addMesh(m.positions, m.indices);
  s->steps.assign(3, {});
  std::mt19937 rng(64);
  std::uniform_real_distribution<float> u(-0.05f, 0.05f);
  for (uint32_t m : {0u, 2u}) {
    const Soup& soup = s->d.meshes[m];
    const glm::vec3 drift = m == 0 ? glm::vec3(0.3f, 0.0f, 0.1f) : glm::vec3(-0.1f, 0.4f, 0.0f);
    std::vector<glm::vec3> wobble(soup.positions.size());
    for (glm::vec3& w : wobble) w = glm::vec3(u(rng), u(rng), u(rng));
    for (uint32_t k = 0; k < kDeformSteps; ++k) {
      const float x = float(k) - 0.5f * float(kDeformSteps - 1);
      std::vector<glm::vec3> at(soup.positions.size());
      for (size_t v = 0; v < at.size(); ++v) at[v] = soup.positions[v] + (drift + wobble[v]) * x;
      s->steps[m].push_back(at);
    }
    s->d.accel.replaceMesh(m, soup.positions, soup.indices, BuildOptions{}, &s->steps[m]);
  }
  const std::vector<glm::mat4> still(kDeformSteps, glm::mat4(1.0f));
  for (uint32_t i = 0; i < 3; ++i) s->d.instances.push_back({i, glm::mat4(1.0f)});
  s->d.accel.setInstances(s->d.instances, {still, still, still});
}

// Each mesh's triangles at `time`, blended as the kernels blend a packet's two steps.
std::vector<std::vector<BvhTriangle>> trianglesAt(const DeformingScene& s, float time) {
  std::vector<std::vector<BvhTriangle>> out;
  uint32_t base = 0;
  for (size_t m = 0; m < s.d.meshes.size(); ++m) {
    const Soup& soup = s.d.meshes[m];
    std::vector<BvhTriangle> tris;
    float a = 0.0f;
    const uint32_t k = dev::motion_step(kDeformSteps, time, &a);
    for (size_t t = 0; t < soup.size(); ++t) {
      const uint32_t prim = base + uint32_t(t);
      if (s.steps[m].empty()) {
        tris.push_back(packTriangle(soup.vertex(t, 0), soup.vertex(t, 1), soup.vertex(t, 2), prim));
        continue;
      }
      auto at = [&](uint32_t step, int c) {
        return s.steps[m][step][soup.indices[3 * t + size_t(c)]];
      };
      const BvhTriangle p0 = packTriangle(at(k, 0), at(k, 1), at(k, 2), prim);
      const BvhTriangle p1 = packTriangle(at(k + 1, 0), at(k + 1, 1), at(k + 1, 2), prim);
      BvhTriangle q = p0;  // v0, e1, e2 blended as the kernel's
      for (float BvhTriangle::*f : {&BvhTriangle::v0x, &BvhTriangle::v0y, &BvhTriangle::v0z,
                                    &BvhTriangle::e1x, &BvhTriangle::e1y, &BvhTriangle::e1z,
                                    &BvhTriangle::e2x, &BvhTriangle::e2y, &BvhTriangle::e2z})
        q.*f += (p1.*f - p0.*f) * a;
      tris.push_back(q);
    }
    out.push_back(tris);
    base += uint32_t(soup.size());
  }
  return out;
}

std::vector<glm::vec3> centresOf(const std::vector<std::vector<BvhTriangle>>& meshes) {
  std::vector<glm::vec3> c;
  for (const auto& tris : meshes)
    for (const BvhTriangle& t : tris)
      c.push_back(glm::vec3(t.v0x, t.v0y, t.v0z) +
                  (glm::vec3(t.e1x, t.e1y, t.e1z) + glm::vec3(t.e2x, t.e2y, t.e2z)) / 3.0f);
  return c;
}

TEST(DeformingTraversal, EachMeshHitsItsOwnStepsAtEveryTime) {
  DeformingScene s;
  makeDeforming(&s);
  const auto runs = s.d.accel.motionPacketRuns();
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(s.d.accel.motionPacketCount(), runs[0].count + runs[1].count);
  const std::vector<uint32_t>& mm = s.d.accel.meshMotion();
  EXPECT_EQ(mm[2 * PR_MESH_MOTION_WORDS + 2], runs[0].count);  // mesh 2's run after mesh 0's
  EXPECT_EQ(mm[PR_MESH_MOTION_WORDS + 3], 1u);                 // mesh 1: no steps
  StaticAccel empty;
  empty.build({}, {});
  const HostGeom hg(empty, &s.d.accel);
  for (float time : {0.0f, 0.3f, 0.5f, 0.77f, 1.0f}) {
    SCOPED_TRACE("time " + std::to_string(time));
    SceneGeom g = hg.geom();
    g.time = time;
    const auto tris = trianglesAt(s, time);
    const auto rays = randomRays(1500, centresOf(tris), 70 + uint32_t(time * 100.0f));
    HitChecker c;
    for (size_t i = 0; i < rays.size(); ++i) {
      Hit want = dev::hit_none();
      for (uint32_t m = 0; m < 3; ++m) {
        Ray r = rays[i];
        if (want.prim != PR_INVALID_INDEX) r.tmax = want.t;
        const Hit h = bruteForce(tris[m], r, m);
        if (h.prim != PR_INVALID_INDEX) want = h;
      }
      Hit got;
      dev::intersect_dynamic(&g, rays[i], &got);
      c.check(got, want, i, "dynamic");
      EXPECT_EQ(dev::occluded_dynamic(&g, rays[i]), want.prim != PR_INVALID_INDEX) << "ray " << i;
    }
    EXPECT_GT(c.hits, 300);
  }
}

// The whole scene: the nearer of the SSG and the DSG hit.
TEST(SceneTraversal, NearerOfStaticAndDynamic) {
  const Soup s = randomSoup(2000, 0.1f, 77);
  StaticAccel a;
  a.build(s.positions, s.indices);
  const auto stris = packSoup(s);
  DynamicScene d;
  makeDynamic(d, 60);
  const auto packed = packMeshes(d);
  for (int frame = 0; frame < 2; ++frame) {
    setFrame(d, frame);
    const HostGeom hg(a, &d.accel);
    const SceneGeom g = hg.geom();
    auto aim = instanceCentres(d);
    for (const auto& c : triangleCentres(s)) aim.push_back(c);
    const auto rays = randomRays(2000, aim, 90 + uint32_t(frame));
    HitChecker c;
    int fromDsg = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      const Hit hs = bruteForce(stris, rays[i]);
      const Hit hd = bruteForceDynamic(d, packed, rays[i]);
      const Hit want =
          hd.prim != PR_INVALID_INDEX && (hs.prim == PR_INVALID_INDEX || hd.t < hs.t) ? hd : hs;
      fromDsg += want.inst != PR_INVALID_INDEX;
      Hit h;
      EXPECT_EQ(dev::intersect_scene(&g, rays[i], &h), want.prim != PR_INVALID_INDEX);
      c.check(h, want, i, "scene");
      EXPECT_EQ(dev::occluded_scene(&g, rays[i]), want.prim != PR_INVALID_INDEX) << "ray " << i;
    }
    EXPECT_GT(fromDsg, 100);
    EXPECT_GT(c.hits - fromDsg, 100);
  }
}

// ---------------------------------------------------------------------------------------------
// Self-intersection

TEST(SelfIntersection, RaysLeavingASurfaceNeverHitIt) {
  // Sizes and positions over several magnitudes, so the offset's scaling is exercised.
  for (float scale : {1e-2f, 1.0f, 1e3f}) {
    SCOPED_TRACE("scale " + std::to_string(scale));
    Soup s = randomSoup(3000, 0.2f, 21);
    for (auto& p : s.positions) p = p * scale + glm::vec3(0.0f, 0.0f, scale > 100 ? 5000.0f : 0.0f);
    StaticAccel a;
    a.build(s.positions, s.indices);
    DynamicScene d;
    makeDynamic(d, 30);
    setFrame(d, 1);
    const HostGeom hg(a, &d.accel);
    const SceneGeom g = hg.geom();
    std::mt19937 rng(99);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    int selfHits = 0;
    for (int i = 0; i < 20000; ++i) {
      float u = u01(rng), v = u01(rng);
      if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
      glm::vec3 p, ng;
      uint32_t prim, inst = PR_INVALID_INDEX;
      if (i % 2 == 0) {
        const size_t t = rng() % s.size();
        const glm::vec3 v0 = s.vertex(t, 0), e1 = s.vertex(t, 1) - v0, e2 = s.vertex(t, 2) - v0;
        p = v0 + u * e1 + v * e2;
        ng = glm::cross(e1, e2);
        prim = uint32_t(t);
      } else {
        const auto& recs = d.accel.instances();
        const dev::BvhInstance& rec = recs[rng() % recs.size()];
        const BvhTriangle& tri =
            d.accel.meshTriangles()[rec.first_triangle + rng() % (d.meshes[rec.mesh].size())];
        const glm::vec3 v0(tri.v0x, tri.v0y, tri.v0z), e1(tri.e1x, tri.e1y, tri.e1z),
            e2(tri.e2x, tri.e2y, tri.e2z);
        const glm::mat4 m = d.instances[rec.instance_id].objectToWorld;
        p = glm::vec3(m * glm::vec4(v0 + u * e1 + v * e2, 1.0f));
        ng = glm::transpose(glm::inverse(glm::mat3(m))) * glm::cross(e1, e2);
        prim = tri.prim;
        inst = rec.instance_id;
      }
      if (!(glm::length(ng) > 0.0f)) continue;
      ng = glm::normalize(ng);
      // Hemisphere on either side, including grazing directions.
      glm::vec3 dir = randomDir(rng);
      if (i % 4 == 1) dir = glm::normalize(dir - glm::dot(dir, ng) * ng * 0.9999f);
      if (!(glm::length(dir) > 0.0f)) continue;
      const Ray r =
          dev::spawn_ray(dev::make_float3(p.x, p.y, p.z), dev::make_float3(ng.x, ng.y, ng.z),
                         dev::make_float3(dir.x, dir.y, dir.z), PR_INF_F);
      Hit h;
      dev::intersect_scene(&g, r, &h);
      if (h.prim == prim && h.inst == inst && ++selfHits <= 5)
        ADD_FAILURE() << "ray " << i << " hit its own triangle at t = " << h.t;
    }
    EXPECT_EQ(selfHits, 0);
  }
}

TEST(SelfIntersection, ShadowSegmentsBetweenFacingSurfaces) {
  // Two facing quads and nothing between: no segment between them is ever occluded.
  Soup s;
  s.positions = {{-1, -1, 0},    {1, -1, 0},    {1, 1, 0},    {-1, 1, 0},
                 {-1, -1, 1.3f}, {1, -1, 1.7f}, {1, 1, 1.3f}, {-1, 1, 1.1f}};
  s.indices = {0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6};
  StaticAccel a;
  a.build(s.positions, s.indices);
  const HostGeom hg(a, nullptr);
  const SceneGeom g = hg.geom();
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  auto point = [&](size_t t, glm::vec3* n) {
    float u = u01(rng), v = u01(rng);
    if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
    const glm::vec3 v0 = s.vertex(t, 0), e1 = s.vertex(t, 1) - v0, e2 = s.vertex(t, 2) - v0;
    *n = glm::cross(e1, e2);
    return v0 + u * e1 + v * e2;
  };
  int blocked = 0;
  for (int i = 0; i < 20000; ++i) {
    glm::vec3 np, nq;
    const glm::vec3 p = point(rng() % 2, &np), q = point(2 + rng() % 2, &nq);
    const Ray r =
        dev::spawn_ray_to(dev::make_float3(p.x, p.y, p.z), dev::make_float3(np.x, np.y, np.z),
                          dev::make_float3(q.x, q.y, q.z), dev::make_float3(nq.x, nq.y, nq.z));
    blocked += dev::occluded_scene(&g, r);
  }
  EXPECT_EQ(blocked, 0);
}

// ---------------------------------------------------------------------------------------------
// The device runs the same code

// A hit this close to a triangle's edge may fall on either side with another rounding.
bool nearEdge(const Hit& h) {
  return h.prim != PR_INVALID_INDEX && (h.u < 1e-4f || h.v < 1e-4f || 1.0f - h.u - h.v < 1e-4f);
}

void compareDevice(const SceneGeom& g, DeviceAccel& dacc, const std::vector<Ray>& rays,
                   cl_uint mode, const std::string& what) {
  const test::TracedRays dt = test::traceRays(dacc, rays, mode);
  HitChecker c;
  int edgeCases = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    Hit want;
    int occ;
    if (mode == 1) {
      dev::intersect_static(&g, rays[i], &want);
      occ = dev::occluded_static(&g, rays[i]);
    } else if (mode == 2) {
      dev::intersect_dynamic(&g, rays[i], &want);
      occ = dev::occluded_dynamic(&g, rays[i]);
    } else {
      dev::intersect_scene(&g, rays[i], &want);
      occ = dev::occluded_scene(&g, rays[i]);
    }
    const Hit& got = dt.hits[i];
    if ((got.prim != want.prim || got.inst != want.inst) && (nearEdge(want) || nearEdge(got))) {
      ++edgeCases;
      continue;
    }
    c.check(got, want, i, what);
    EXPECT_EQ(int(dt.occluded[i]), occ) << what << " ray " << i;
  }
  EXPECT_LE(edgeCases, int(rays.size() / 1000) + 1) << what;
  EXPECT_GT(c.hits, int(rays.size() / 5)) << what;
}

// Every layout a device may get: the same nearest hits (t within 1e-5, same triangle away from
// edges) and the same occlusion answers as the CPU reference (PR_BVH_WIDTH wide), over frames
// of a two-level scene with a singular instance, with and without the DSG.
TEST(DeviceTraversal, EveryWidthMatchesCpuReference) {
  Context& ctx = test::testContext();
  const Soup s = randomSoup(8000, 0.05f, 123);
  StaticAccel ref;
  ref.build(s.positions, s.indices);
  DynamicScene dref;
  makeDynamic(dref, 200);
  for (int width : {2, 4, 8}) {
    SCOPED_TRACE("width " + std::to_string(width));
    BuildOptions o;
    o.width = width;
    StaticAccel a;
    a.build(s.positions, s.indices, o);
    DynamicScene d(width);
    makeDynamic(d, 200);
    DeviceAccel dacc(width);
    dacc.uploadStatic(ctx, a);
    {
      // No DSG at all: placeholders, instance count 0.
      const HostGeom hg(ref, nullptr);
      compareDevice(hg.geom(), dacc, randomRays(3000, triangleCentres(s), 1), 1, "static only");
    }
    dacc.uploadMeshes(ctx, d.accel);
    for (int frame = 0; frame < 3; ++frame) {
      SCOPED_TRACE("frame " + std::to_string(frame));
      setFrame(d, frame);
      setFrame(dref, frame);
      dacc.uploadFrame(ctx, d.accel);
      const HostGeom hg(ref, &dref.accel);
      auto aim = instanceCentres(d);
      const auto sc = triangleCentres(s);
      aim.insert(aim.end(), sc.begin(), sc.begin() + 2000);
      const auto rays = randomRays(3000, aim, 300 + uint32_t(frame));
      for (cl_uint mode : {0u, 1u, 2u})
        compareDevice(hg.geom(), dacc, rays, mode, "mode " + std::to_string(mode));
    }
  }
  // A device compiled for one width refuses BVHs of another.
  DeviceAccel four(4);
  EXPECT_THROW(four.uploadStatic(ctx, ref), RuntimeError);
}

// The steps' packets reach the device in their runs, each where its mesh's words say.
TEST(DeviceTraversal, DeformingMeshesMatchCpuReference) {
  Context& ctx = test::testContext();
  DeformingScene s;
  makeDeforming(&s);
  StaticAccel empty;
  empty.build({}, {});
  DeviceAccel dacc(PR_BVH_WIDTH);
  dacc.uploadStatic(ctx, empty);
  dacc.uploadMeshes(ctx, s.d.accel);
  dacc.uploadFrame(ctx, s.d.accel);
  const HostGeom hg(empty, &s.d.accel);  // the frame's time, as the device's arguments
  const auto rays = randomRays(3000, centresOf(trianglesAt(s, 0.5f)), 81);
  for (cl_uint mode : {0u, 2u})
    compareDevice(hg.geom(), dacc, rays, mode, "mode " + std::to_string(mode));
}

}  // namespace
}  // namespace pr
