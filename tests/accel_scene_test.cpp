// The renderer's own BVHs of real scenes against a brute-force loop over every triangle: the
// SSG of cornell-nvpro and the SSG + DSG of animated scenes at several frames, traversed by the
// CPU reference and on the device in every BVH layout.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "accel/scene_accel.h"
#include "render/gpu_scene.h"
#include "scene/gltf_loader.h"
#include "shared/bvh.h"
#include "support/render_helpers.h"
#include "support/trace_rays.h"
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

// The same nearest hit: same triangle and t within 1e-5, or two triangles at the very same
// distance (coincident faces), which may legitimately swap.
bool sameHit(const Hit& got, const Hit& want) {
  const bool same = got.prim == want.prim && got.inst == want.inst &&
                    (want.prim == PR_INVALID_INDEX || std::fabs(got.t - want.t) <= 1e-5f * want.t);
  const bool tie = got.prim != PR_INVALID_INDEX && want.prim != PR_INVALID_INDEX &&
                   std::fabs(got.t - want.t) <= 1e-6f * want.t;
  return same || tie;
}

void expectSceneMatchesBruteForce(const std::string& path, const std::vector<double>& times,
                                  size_t rays) {
  const Scene scene = loadScene(path);
  Context& ctx = test::testContext();
  // Built as wide as the host's CPU reference traverses, whatever the device's default.
  GpuSceneOptions referenceLayout;
  referenceLayout.bvhWidth = PR_BVH_WIDTH;
  GpuScene gpu(ctx, scene, referenceLayout);
  // The same scene in every layout a device may get, traced on the test device.
  std::vector<std::unique_ptr<GpuScene>> layouts;
  for (int width : {2, 4, 8}) {
    GpuSceneOptions o;
    o.bvhWidth = width;
    layouts.push_back(std::make_unique<GpuScene>(ctx, scene, o));
  }
  // SSG triangles, numbered as the renderer numbers them.
  std::vector<BvhTriangle> ssg;
  const TriangleMesh& sm = scene.staticMesh;
  for (uint32_t i = 0; i < sm.triangleCount(); ++i) {
    const auto t =
        accel::packTriangle(sm.positions[sm.indices[3 * i]], sm.positions[sm.indices[3 * i + 1]],
                            sm.positions[sm.indices[3 * i + 2]], i);
    if (!zeroArea(t)) ssg.push_back(t);
  }
  // Each dynamic mesh in object space; DSG prims follow the SSG's.
  std::vector<std::vector<BvhTriangle>> meshes;
  uint32_t next = static_cast<uint32_t>(sm.triangleCount());
  for (const TriangleMesh& m : scene.dynamicMeshes) {
    meshes.emplace_back();
    for (uint32_t i = 0; i < m.triangleCount(); ++i) {
      const auto t =
          accel::packTriangle(m.positions[m.indices[3 * i]], m.positions[m.indices[3 * i + 1]],
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
    for (auto& l : layouts) l->setTime(t);
    std::vector<Ray> traced;
    std::vector<Hit> wanted;
    const accel::StaticAccel& sa = gpu.staticAccel();
    const accel::DynamicAccel& da = gpu.dynamicAccel();
    const accel::HostGeom hg(sa, &da);
    const dev::SceneGeom g = hg.geom();
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
        const dev::BvhRay local = dev::instance_ray(&g, &rec, &world);
        bruteForce(meshes[rec.mesh], local.o, local.d, 0.0f, rec.instance_id, &want);
      }
      hits += want.prim != PR_INVALID_INDEX;
      dynamicHits += want.inst != PR_INVALID_INDEX;
      if (!sameHit(got, want) && ++failures <= 5)
        ADD_FAILURE() << path << " t=" << t << " ray " << r << ": got prim " << got.prim << " inst "
                      << got.inst << " t " << got.t << ", want prim " << want.prim << " inst "
                      << want.inst << " t " << want.t;
      traced.push_back(ray);
      wanted.push_back(want);
    }
    for (auto& l : layouts) {
      const std::vector<Hit> got = test::traceRays(l->deviceAccel(), traced, 0).hits;
      int wrong = 0;
      for (size_t i = 0; i < got.size(); ++i) {
        if (sameHit(got[i], wanted[i]) || ++wrong > 5) continue;
        ADD_FAILURE() << path << " t=" << t << " width " << l->bvhWidth() << " ray " << i
                      << ": got prim " << got[i].prim << " inst " << got[i].inst << " t "
                      << got[i].t << ", want prim " << wanted[i].prim << " inst " << wanted[i].inst
                      << " t " << wanted[i].t;
      }
      EXPECT_EQ(wrong, 0) << "width " << l->bvhWidth();
    }
  }
  EXPECT_EQ(failures, 0);
  EXPECT_GT(hits, static_cast<int>(rays * times.size() / 4)) << "too few rays hit anything to test";
  if (!scene.instances.empty()) {
    EXPECT_GT(dynamicHits, 0) << "no ray reached the moving objects";
  }
}

TEST(SceneAccel, CornellNvproMatchesBruteForce) {
  PR_SHARED_SCENE(path, "cornell-nvpro/cornellBox.gltf");
  expectSceneMatchesBruteForce(path, {0.0}, 1500);
}

TEST(SceneAccel, AnimatedDemoMatchesBruteForceAtSeveralFrames) {
  expectSceneMatchesBruteForce(test::sourcePath("scenes/cornell-dynamic.gltf"),
                               {0.0, 1.3, 2.6, 4.9}, 2000);
}

TEST(SceneAccel, OrbitDemoMatchesBruteForceAtSeveralFrames) {
  expectSceneMatchesBruteForce(test::sourcePath("scenes/cornell-orbit.gltf"), {0.0, 2.1, 4.0},
                               2000);
}

// Every layout renders the demo's frames bit for bit the same (its rays never fall exactly
// between two triangles at the same distance). The path tracer's closest-hit and shadow rays
// use the traversal every mode uses; reuse's kernels would add minutes of compilation per
// width on a GPU whose compiler cache is cold.
TEST(SceneAccel, EveryBvhWidthRendersTheDemoAlike) {
  const std::string scene = test::sourcePath("scenes/cornell-dynamic.gltf");
  const std::string args = "--mode pathtrace --width 48 --height 36 --spp 2";
  const std::string ref = test::renderFrames(scene, "0-1", args + " --bvh-width 8", "bvh8");
  for (const char* width : {"2", "4"}) {
    const std::string dir = test::renderFrames(scene, "0-1", args + " --bvh-width " + width,
                                               std::string("bvh") + width);
    for (int f = 0; f <= 1; ++f)
      EXPECT_TRUE(test::frameImage(dir, f).rgba == test::frameImage(ref, f).rgba)
          << "width " << width << " frame " << f;
  }
}

TEST(SceneAccel, BoxAnimatedMatchesBruteForceAtSeveralFrames) {
  PR_SHARED_SCENE(path, "BoxAnimated/BoxAnimated.gltf");
  expectSceneMatchesBruteForce(path, {0.0, 0.7, 1.5, 3.0}, 2000);
}

}  // namespace
}  // namespace pr
