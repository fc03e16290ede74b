// The renderer's own BVHs of real scenes against a brute-force loop over every triangle: the
// SSG of cornell-nvpro and the SSG + DSG of animated scenes at several frames.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "accel/scene_accel.h"
#include "render/gpu_scene.h"
#include "scene/gltf_loader.h"
#include "shared/bvh.h"
#include "support/test_env.h"

namespace pr {
namespace {

using dev::BvhTriangle;
using dev::Hit;
using dev::Ray;

bool zeroArea(const BvhTriangle& t) {
  const glm::vec3 e1(t.e1x, t.e1y, t.e1z), e2(t.e2x, t.e2y, t.e2z);
  return glm::cross(e1, e2) == glm::vec3(0.0f);
}

// Closest hit over every triangle (strictly nearer wins), as the traversal must find it.
void bruteForce(const std::vector<BvhTriangle>& tris, dev::float3 o, dev::float3 d, float tmin,
                uint32_t inst, Hit* best) {
  for (const BvhTriangle& tri : tris) {
    float t, u, v;
    if (dev::intersect_triangle(&tri, o, d, tmin, best->t, &t, &u, &v))
      best->t = t, best->u = u, best->v = v, best->prim = tri.prim, best->inst = inst;
  }
}

void expectSceneMatchesBruteForce(const std::string& path, const std::vector<double>& times, size_t rays) {
  const Scene scene = loadScene(path);
  Context& ctx = test::testContext();
  GpuScene gpu(ctx, scene);
  // SSG triangles, numbered as the renderer numbers them.
  std::vector<BvhTriangle> ssg;
  const TriangleMesh& sm = scene.staticMesh;
  for (uint32_t i = 0; i < sm.triangleCount(); ++i) {
    const auto t = accel::packTriangle(sm.positions[sm.indices[3 * i]], sm.positions[sm.indices[3 * i + 1]],
                                       sm.positions[sm.indices[3 * i + 2]], i);
    if (!zeroArea(t)) ssg.push_back(t);
  }
  // Each dynamic mesh in object space; DSG prims follow the SSG's.
  std::vector<std::vector<BvhTriangle>> meshes;
  uint32_t next = static_cast<uint32_t>(sm.triangleCount());
  for (const TriangleMesh& m : scene.dynamicMeshes) {
    meshes.emplace_back();
    for (uint32_t i = 0; i < m.triangleCount(); ++i) {
      const auto t = accel::packTriangle(m.positions[m.indices[3 * i]], m.positions[m.indices[3 * i + 1]],
                                         m.positions[m.indices[3 * i + 2]], next + i);
      if (!zeroArea(t)) meshes.back().push_back(t);
    }
    next += static_cast<uint32_t>(m.triangleCount());
  }
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  const Bounds b = scene.bounds;
  int hits = 0, failures = 0, dynamicHits = 0;
  for (double t : times) {
    gpu.setTime(t);
    const accel::StaticAccel& sa = gpu.staticAccel();
    const accel::DynamicAccel& da = gpu.dynamicAccel();
    dev::SceneGeom g{};
    g.static_nodes = sa.nodes().data();
    g.static_tris = sa.triangles().data();
    g.tlas_nodes = da.tlasNodes().data();
    g.instances = da.instances().data();
    g.mesh_nodes = da.meshNodes().data();
    g.mesh_tris = da.meshTriangles().data();
    g.instance_count = static_cast<uint32_t>(da.instances().size());
    const CameraPose cam = scene.cameraAt(0, t);
    for (size_t r = 0; r < rays; ++r) {
      // Half from the camera through the view, half between random points of the bounds.
      glm::vec3 o, d;
      if (r % 2 == 0) {
        o = cam.position;
        const glm::vec3 right = glm::normalize(glm::cross(cam.forward, cam.up));
        d = glm::normalize(cam.forward + right * (u01(rng) - 0.5f) + cam.up * (u01(rng) - 0.5f));
      } else {
        o = b.min + (b.max - b.min) * glm::vec3(u01(rng), u01(rng), u01(rng));
        const glm::vec3 q = b.min + (b.max - b.min) * glm::vec3(u01(rng), u01(rng), u01(rng));
        d = glm::normalize(q - o);
        if (!std::isfinite(d.x)) continue;
      }
      Ray ray{o.x, o.y, o.z, 0.0f, d.x, d.y, d.z, PR_INF_F};
      Hit got;
      dev::intersect_scene(&g, ray, &got);
      Hit want = dev::hit_none();
      const dev::float3 wo = dev::make_float3(o.x, o.y, o.z), wd = dev::make_float3(d.x, d.y, d.z);
      bruteForce(ssg, wo, wd, 0.0f, PR_INVALID_INDEX, &want);
      const dev::BvhRay world = dev::bvh_ray_from(ray);
      for (const dev::BvhInstance& rec : da.instances()) {
        const dev::BvhRay local = dev::instance_ray(&rec, &world);
        bruteForce(meshes[rec.mesh], local.o, local.d, 0.0f, rec.instance_id, &want);
      }
      const bool same = got.prim == want.prim && got.inst == want.inst &&
                        (want.prim == PR_INVALID_INDEX || std::fabs(got.t - want.t) <= 1e-5f * want.t);
      // Two triangles at the very same distance (coincident faces) may legitimately swap.
      const bool tie = !same && got.prim != PR_INVALID_INDEX && want.prim != PR_INVALID_INDEX &&
                       std::fabs(got.t - want.t) <= 1e-6f * want.t;
      hits += want.prim != PR_INVALID_INDEX;
      dynamicHits += want.inst != PR_INVALID_INDEX;
      if (!same && !tie && ++failures <= 5)
        ADD_FAILURE() << path << " t=" << t << " ray " << r << ": got prim " << got.prim << " inst " << got.inst
                      << " t " << got.t << ", want prim " << want.prim << " inst " << want.inst << " t "
                      << want.t;
    }
  }
  EXPECT_EQ(failures, 0);
  EXPECT_GT(hits, static_cast<int>(rays * times.size() / 4)) << "too few rays hit anything to test";
  if (!scene.instances.empty()) {
    EXPECT_GT(dynamicHits, 0) << "no ray reached the moving objects";
  }
}

TEST(SceneAccel, CornellNvproMatchesBruteForce) {
  const std::string path = test::sharedScene("cornell-nvpro/cornellBox.gltf");
  if (path.empty()) GTEST_SKIP() << "../shared/scenes/cornell-nvpro is absent";
  expectSceneMatchesBruteForce(path, {0.0}, 1500);
}

TEST(SceneAccel, AnimatedDemoMatchesBruteForceAtSeveralFrames) {
  expectSceneMatchesBruteForce(test::sourcePath("scenes/cornell-dynamic.gltf"), {0.0, 1.3, 2.6, 4.9}, 2000);
}

TEST(SceneAccel, BoxAnimatedMatchesBruteForceAtSeveralFrames) {
  const std::string path = test::sharedScene("BoxAnimated/BoxAnimated.gltf");
  if (path.empty()) GTEST_SKIP() << "../shared/scenes/BoxAnimated is absent";
  expectSceneMatchesBruteForce(path, {0.0, 0.7, 1.5, 3.0}, 2000);
}

}  // namespace
}  // namespace pr
