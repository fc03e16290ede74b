// ray_bench: ray throughput of the SSG + DSG traversal (kernels/shared/bvh.h) on an OpenCL
// device, with BVH build times and device memory.
//
//   ray_bench SCENE.gltf [--frame-time T] [--width W --height H] [--repeats N] [--device SPEC]
//             [--json FILE]
//   ray_bench            (no scene: a synthetic sphere flake, ~236k triangles, 16 instances)
//
// Three ray sets come from the scene's first camera at time T, deterministically (counter-based
// RNG keyed by pixel): camera rays through pixel centres; shadow rays from each camera hit to a
// random point on a random emissive triangle (else a point light, else straight up); diffuse
// bounce rays, cosine-weighted about the geometric normal facing the camera. Camera rays that
// miss are dropped from all three sets. Closest hit is timed for camera and bounce rays, any
// hit for shadow rays: kernel time from profiling events, median/min/max over --repeats
// launches after one warm-up.
//
// Optional reference: Intel Embree 3 traces the same rays on 2 std::threads, alternating with
// ours, and reports the ratio and the hit/miss agreement. Install it to get the comparison
// (it is no dependency of the renderer):  apt-get install -y libembree-dev  then re-run cmake.
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "accel/device_accel.h"
#include "accel/scene_accel.h"
#include "cl/context.h"
#include "cl/device.h"
#include "cl/cl_check.h"
#include "scene/gltf_loader.h"
#include "scene/scene.h"
#include "shared/bvh.h"
#include "shared/rng.h"
#include "shared/sampling.h"
#include "util/error.h"

#ifdef PATHREUSE_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

namespace {

using namespace pr;
using dev::Hit;
using dev::Ray;
using json = nlohmann::json;

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

glm::vec3 toGlm(dev::float3 v) {
  return glm::vec3(v.x, v.y, v.z);
}
dev::float3 toDev(glm::vec3 v) {
  return dev::make_float3(v.x, v.y, v.z);
}

// What the benchmark needs of a scene, in the renderer's numbering: DSG prims follow the SSG's.
struct DynMesh {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  uint32_t primBase = 0;
};
struct BenchScene {
  std::string name;
  std::vector<glm::vec3> positions;  // SSG, world space
  std::vector<uint32_t> indices;
  std::vector<DynMesh> meshes;
  std::vector<accel::InstanceInput> instances;  // at the frame time
  CameraPose camera;
  std::vector<std::array<glm::vec3, 3>> emitters;  // world space
  std::vector<glm::vec3> pointLights;
};

BenchScene fromGltf(const std::string& path, double t) {
  Scene s = loadScene(path);
  BenchScene b;
  b.name = path;
  b.positions = s.staticMesh.positions;
  b.indices = s.staticMesh.indices;
  uint32_t next = uint32_t(s.staticMesh.triangleCount());
  for (const TriangleMesh& m : s.dynamicMeshes) {
    b.meshes.push_back({m.positions, m.indices, next});
    next += uint32_t(m.triangleCount());
  }
  for (size_t i = 0; i < s.instances.size(); ++i)
    b.instances.push_back({s.instances[i].mesh, s.instanceTransform(i, t)});
  b.camera = s.cameraAt(0, t);
  auto emissive = [&](uint32_t mat) {
    return mat < s.materials.size() && s.materials[mat].isEmissive();
  };
  const TriangleMesh& sm = s.staticMesh;
  for (size_t k = 0; k < sm.triangleCount(); ++k)
    if (emissive(sm.materials[k]))
      b.emitters.push_back({sm.positions[sm.indices[3 * k]], sm.positions[sm.indices[3 * k + 1]],
                            sm.positions[sm.indices[3 * k + 2]]});
  for (const accel::InstanceInput& in : b.instances) {
    const TriangleMesh& m = s.dynamicMeshes[in.mesh];
    auto w = [&](uint32_t v) {
      return glm::vec3(in.objectToWorld * glm::vec4(m.positions[v], 1.0f));
    };
    for (size_t k = 0; k < m.triangleCount(); ++k)
      if (emissive(m.materials[k]))
        b.emitters.push_back(
            {w(m.indices[3 * k]), w(m.indices[3 * k + 1]), w(m.indices[3 * k + 2])});
  }
  for (size_t i = 0; i < s.lights.size(); ++i) {
    const PunctualLight l = s.lightAt(i, t);
    if (l.type != LightType::Directional) b.pointLights.push_back(l.position);
  }
  return b;
}

// --- the synthetic scene: a sphere flake over a ground quad, an emissive quad above ---

void addSphere(std::vector<glm::vec3>& p, std::vector<uint32_t>& idx, glm::vec3 c, float r,
               int rings, int segments) {
  const uint32_t base = uint32_t(p.size());
  for (int i = 0; i <= rings; ++i) {
    const float th = PR_PI * float(i) / float(rings);
    for (int j = 0; j < segments; ++j) {
      const float ph = 2.0f * PR_PI * float(j) / float(segments);
      p.push_back(c + r * glm::vec3(std::sin(th) * std::cos(ph), std::cos(th),
                                    std::sin(th) * std::sin(ph)));
    }
  }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = base + uint32_t(i * segments + j),
                     b = base + uint32_t(i * segments + (j + 1) % segments);
      const uint32_t c2 = a + uint32_t(segments), d = b + uint32_t(segments);
      if (i > 0) idx.insert(idx.end(), {a, c2, b});
      if (i < rings - 1) idx.insert(idx.end(), {b, c2, d});
    }
}

// Nine children per sphere at a third of its radius, on the side away from the parent.
void addFlake(std::vector<glm::vec3>& p, std::vector<uint32_t>& idx, glm::vec3 c, float r,
              glm::vec3 up, int levels) {
  addSphere(p, idx, c, r, 10, 16);
  if (levels == 0) return;
  dev::float3 t3, b3;
  dev::orthonormal_basis(toDev(up), &t3, &b3);
  const glm::vec3 t = toGlm(t3), b = toGlm(b3);
  for (int k = 0; k < 9; ++k) {
    const float elev = k < 6 ? 0.0f : 1.0f;  // six around the equator, three above
    const float az = 2.0f * PR_PI * (k < 6 ? float(k) / 6.0f : (float(k - 6) + 0.5f) / 3.0f);
    const glm::vec3 dir = glm::normalize(std::cos(elev) * (std::cos(az) * t + std::sin(az) * b) +
                                         std::sin(elev) * up);
    addFlake(p, idx, c + dir * (r * 4.0f / 3.0f), r / 3.0f, dir, levels - 1);
  }
}

BenchScene synthetic(int levels, int instances) {
  BenchScene b;
  b.name = "synthetic sphere flake";
  addFlake(b.positions, b.indices, glm::vec3(0.0f), 1.0f, glm::vec3(0, 1, 0), levels);
  auto quad = [&](glm::vec3 a, glm::vec3 bb, glm::vec3 c, glm::vec3 d) {
    const uint32_t base = uint32_t(b.positions.size());
    b.positions.insert(b.positions.end(), {a, bb, c, d});
    b.indices.insert(b.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
  };
  quad({-8, -1.5f, -8}, {8, -1.5f, -8}, {8, -1.5f, 8}, {-8, -1.5f, 8});
  const glm::vec3 l[4] = {{-1, 4, -1}, {1, 4, -1}, {1, 4, 1}, {-1, 4, 1}};
  quad(l[0], l[1], l[2], l[3]);
  b.emitters.push_back({l[0], l[2], l[1]});
  b.emitters.push_back({l[0], l[3], l[2]});
  DynMesh ball;
  addSphere(ball.positions, ball.indices, glm::vec3(0.0f), 0.3f, 32, 32);
  ball.primBase = uint32_t(b.indices.size() / 3);
  b.meshes.push_back(ball);
  for (int i = 0; i < instances; ++i) {
    const float a = 2.0f * PR_PI * float(i) / float(std::max(instances, 1));
    b.instances.push_back(
        {0, glm::scale(
                glm::translate(glm::mat4(1.0f), glm::vec3(2.2f * std::cos(a), 0.3f * float(i % 3),
                                                          2.2f * std::sin(a))),
                glm::vec3(1.0f, 0.6f + 0.1f * float(i % 4), 1.0f))});
  }
  b.camera.position = glm::vec3(0.5f, 1.5f, 5.0f);
  b.camera.forward = glm::normalize(glm::vec3(0.0f, 0.2f, 0.0f) - b.camera.position);
  b.camera.up = glm::normalize(
      glm::cross(glm::cross(b.camera.forward, glm::vec3(0, 1, 0)), b.camera.forward));
  b.camera.yfov = 50.0f * PR_PI / 180.0f;
  return b;
}

// --- BVH statistics ---

float halfArea(const accel::BinaryNode& n) {
  const float x = n.hi_x - n.lo_x, y = n.hi_y - n.lo_y, z = n.hi_z - n.lo_z;
  return x * y + y * z + z * x;
}

// SAH cost of the tree below `root` with the builder's costs (traversal 1, triangle 1), in
// units of one triangle test per ray that hits the root box.
double sahCost(const std::vector<accel::BinaryNode>& nodes, uint32_t root) {
  const double rootArea = halfArea(nodes[root]);
  if (!(rootArea > 0.0)) return 0.0;
  double cost = 0.0;
  std::vector<uint32_t> stack{root};
  while (!stack.empty()) {
    const uint32_t i = stack.back();
    stack.pop_back();
    const accel::BinaryNode& n = nodes[i];
    const double a = halfArea(n) / rootArea;
    if (n.meta & PR_BVH_LEAF_BIT) {
      cost += a * double(n.meta & ~PR_BVH_LEAF_BIT);
    } else {
      cost += a;
      stack.push_back(i + 1);
      stack.push_back(n.index);
    }
  }
  return cost;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n == 0 ? 0.0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

struct Rates {
  std::vector<double> mrays;  // one per repeat
  double med() const { return median(mrays); }
  double min() const { return mrays.empty() ? 0.0 : *std::min_element(mrays.begin(), mrays.end()); }
  double max() const { return mrays.empty() ? 0.0 : *std::max_element(mrays.begin(), mrays.end()); }
  json toJson() const {
    return {{"median", med()}, {"min", min()}, {"max", max()}, {"runs", mrays}};
  }
};

// --- our tracer on the OpenCL device ---

class DeviceTracer {
 public:
  DeviceTracer(Context& ctx, accel::DeviceAccel& acc) : ctx_(ctx) {
    ProgramBuild pb =
        ctx.buildProgram("test/trace.cl", "-DPR_BVH_WIDTH=" + std::to_string(acc.width()));
    cl_int err = CL_SUCCESS;
    closest_ = cl::Kernel(pb.program, "trace_closest", &err);
    CL_CHECK(err);
    any_ = cl::Kernel(pb.program, "trace_any", &err);
    CL_CHECK(err);
    acc.setKernelArgs(ctx, closest_, 3);
    acc.setKernelArgs(ctx, any_, 3);
  }

  // Uploads the rays (not timed) and binds them to both kernels.
  void setRays(const std::vector<Ray>& rays) {
    n_ = rays.size();
    rays_ = ctx_.allocate("bench rays", std::max<size_t>(n_, 1) * sizeof(Ray), CL_MEM_READ_ONLY);
    hits_ = ctx_.allocate("bench hits", std::max<size_t>(n_, 1) * sizeof(Hit));
    occ_ = ctx_.allocate("bench occluded", std::max<size_t>(n_, 1) * sizeof(cl_uint));
    if (n_ > 0)
      CL_CHECK(ctx_.queue().enqueueWriteBuffer(rays_, CL_TRUE, 0, n_ * sizeof(Ray), rays.data()));
    const cl_uint n = cl_uint(n_);
    CL_CHECK(closest_.setArg(0, rays_));
    CL_CHECK(closest_.setArg(1, hits_));
    CL_CHECK(closest_.setArg(2, n));
    CL_CHECK(any_.setArg(0, rays_));
    CL_CHECK(any_.setArg(1, occ_));
    CL_CHECK(any_.setArg(2, n));
  }

  // One launch; returns Mrays/s from the kernel's profiled duration.
  double run(bool anyHit) {
    if (n_ == 0) return 0.0;
    StageTimer timer;
    ctx_.finish();
    ctx_.launch1D(anyHit ? any_ : closest_, n_, "ray_bench", &timer);
    const double seconds = timer.collect()["ray_bench"];
    return seconds > 0.0 ? double(n_) / seconds * 1e-6 : 0.0;
  }

  std::vector<Hit> hits() {
    std::vector<Hit> h(n_);
    if (n_ > 0)
      CL_CHECK(ctx_.queue().enqueueReadBuffer(hits_, CL_TRUE, 0, n_ * sizeof(Hit), h.data()));
    return h;
  }
  std::vector<cl_uint> occluded() {
    std::vector<cl_uint> o(n_);
    if (n_ > 0)
      CL_CHECK(ctx_.queue().enqueueReadBuffer(occ_, CL_TRUE, 0, n_ * sizeof(cl_uint), o.data()));
    return o;
  }

 private:
  Context& ctx_;
  cl::Kernel closest_, any_;
  cl::Buffer rays_, hits_, occ_;
  size_t n_ = 0;
};

// --- the reference: Embree 3 on 2 threads ---

#ifdef PATHREUSE_HAVE_EMBREE
std::atomic<int64_t> g_embreeBytes{0};

bool countEmbreeBytes(void*, ssize_t bytes, bool) {
  g_embreeBytes += bytes;
  return true;
}

class EmbreeTracer {
 public:
  EmbreeTracer(const BenchScene& s, int threads) : threads_(threads) {
    const std::string config = "threads=" + std::to_string(threads);
    device_ = rtcNewDevice(config.c_str());
    if (!device_) throw RuntimeError("Embree: rtcNewDevice failed");
    rtcSetDeviceMemoryMonitorFunction(device_, countEmbreeBytes, nullptr);
    const double t0 = now();
    scene_ = rtcNewScene(device_);
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
    addTriangles(scene_, s.positions, s.indices);  // geomID 0
    for (const DynMesh& m : s.meshes) {
      RTCScene ms = rtcNewScene(device_);
      rtcSetSceneBuildQuality(ms, RTC_BUILD_QUALITY_HIGH);
      if (!m.indices.empty()) addTriangles(ms, m.positions, m.indices);
      rtcCommitScene(ms);
      meshScenes_.push_back(ms);
      primBase_.push_back(m.primBase);
    }
    meshSeconds_ = now() - t0;
    for (size_t i = 0; i < s.instances.size(); ++i) {
      const DynMesh& m = s.meshes[s.instances[i].mesh];
      if (m.indices.empty()) continue;
      RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(g, meshScenes_[s.instances[i].mesh]);
      rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR,
                              &s.instances[i].objectToWorld[0][0]);
      rtcCommitGeometry(g);
      const unsigned id = rtcAttachGeometry(scene_, g);
      rtcReleaseGeometry(g);
      if (instanceOf_.size() <= id) instanceOf_.resize(id + 1, PR_INVALID_INDEX);
      instanceOf_[id] = uint32_t(i);
      instanceMesh_.resize(id + 1, 0);
      instanceMesh_[id] = s.instances[i].mesh;
    }
    rtcCommitScene(scene_);
    buildSeconds_ = now() - t0;
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE)
      throw RuntimeError("Embree: scene build failed");
  }
  ~EmbreeTracer() {
    rtcReleaseScene(scene_);
    for (RTCScene m : meshScenes_) rtcReleaseScene(m);
    rtcReleaseDevice(device_);
  }
  EmbreeTracer(const EmbreeTracer&) = delete;
  EmbreeTracer& operator=(const EmbreeTracer&) = delete;

  double buildSeconds() const { return buildSeconds_; }
  double meshSeconds() const { return meshSeconds_; }

  // Traces all rays, `packet` = 1 (rtcIntersect1/rtcOccluded1) or 8 (8-wide packets), on the
  // threads; writes prim/inst per ray (closest) or occluded flags. Returns Mrays/s (wall time).
  double run(const std::vector<Ray>& rays, bool anyHit, int packet, std::vector<Hit>* hits,
             std::vector<cl_uint>* occ) {
    const size_t n = rays.size();
    hits->resize(n);
    occ->resize(n);
    std::atomic<size_t> next{0};
    const size_t chunk = 512;  // multiple of 8
    auto work = [&] {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      for (size_t begin; (begin = next.fetch_add(chunk)) < n;) {
        const size_t end = std::min(n, begin + chunk);
        if (packet == 8)
          for (size_t i = begin; i < end; i += 8)
            trace8(rays, i, std::min(end, i + 8), anyHit, &ctx, hits, occ);
        else
          for (size_t i = begin; i < end; ++i)
            trace1(rays[i], anyHit, &ctx, &(*hits)[i], &(*occ)[i]);
      }
    };
    const double t0 = now();
    std::vector<std::thread> pool;
    for (int t = 1; t < threads_; ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
    return double(n) / (now() - t0) * 1e-6;
  }

 private:
  void addTriangles(RTCScene scene, const std::vector<glm::vec3>& p,
                    const std::vector<uint32_t>& idx) {
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
    float* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0,
                                                           RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                           std::max<size_t>(p.size(), 1)));
    for (size_t i = 0; i < p.size(); ++i)
      v[3 * i] = p[i].x, v[3 * i + 1] = p[i].y, v[3 * i + 2] = p[i].z;
    unsigned* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), idx.size() / 3));
    std::copy(idx.begin(), idx.end(), t);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
  }

  void toHit(unsigned geomID, unsigned primID, unsigned instID, float t, Hit* h) const {
    *h = dev::hit_none();
    if (geomID == RTC_INVALID_GEOMETRY_ID) return;
    h->t = t;
    if (instID == RTC_INVALID_GEOMETRY_ID) {
      h->prim = primID;
    } else {
      h->inst = instanceOf_[instID];
      h->prim = primBase_[instanceMesh_[instID]] + primID;
    }
  }

  void trace1(const Ray& r, bool anyHit, RTCIntersectContext* ctx, Hit* hit, cl_uint* occ) const {
    RTCRayHit rh;
    rh.ray.org_x = r.ox, rh.ray.org_y = r.oy, rh.ray.org_z = r.oz, rh.ray.tnear = r.tmin;
    rh.ray.dir_x = r.dx, rh.ray.dir_y = r.dy, rh.ray.dir_z = r.dz, rh.ray.tfar = r.tmax;
    rh.ray.time = 0.0f, rh.ray.mask = 0xffffffffu, rh.ray.id = 0, rh.ray.flags = 0;
    if (anyHit) {
      rtcOccluded1(scene_, ctx, &rh.ray);
      *occ = rh.ray.tfar < 0.0f ? 1u : 0u;
      return;
    }
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, ctx, &rh);
    toHit(rh.hit.geomID, rh.hit.primID, rh.hit.instID[0], rh.ray.tfar, hit);
  }

  void trace8(const std::vector<Ray>& rays, size_t begin, size_t end, bool anyHit,
              RTCIntersectContext* ctx, std::vector<Hit>* hits, std::vector<cl_uint>* occ) const {
    RTCRayHit8 p;
    int valid[8];
    for (size_t k = 0; k < 8; ++k) {
      const Ray& r = rays[std::min(begin + k, end - 1)];
      valid[k] = begin + k < end ? -1 : 0;
      p.ray.org_x[k] = r.ox, p.ray.org_y[k] = r.oy, p.ray.org_z[k] = r.oz, p.ray.tnear[k] = r.tmin;
      p.ray.dir_x[k] = r.dx, p.ray.dir_y[k] = r.dy, p.ray.dir_z[k] = r.dz, p.ray.tfar[k] = r.tmax;
      p.ray.time[k] = 0.0f, p.ray.mask[k] = 0xffffffffu, p.ray.id[k] = 0, p.ray.flags[k] = 0;
      p.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      p.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    if (anyHit) {
      rtcOccluded8(valid, scene_, ctx, &p.ray);
      for (size_t k = 0; begin + k < end; ++k) (*occ)[begin + k] = p.ray.tfar[k] < 0.0f ? 1u : 0u;
      return;
    }
    rtcIntersect8(valid, scene_, ctx, &p);
    for (size_t k = 0; begin + k < end; ++k)
      toHit(p.hit.geomID[k], p.hit.primID[k], p.hit.instID[0][k], p.ray.tfar[k],
            &(*hits)[begin + k]);
  }

  int threads_;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::vector<RTCScene> meshScenes_;
  std::vector<uint32_t> primBase_, instanceOf_, instanceMesh_;
  double buildSeconds_ = 0.0, meshSeconds_ = 0.0;
};
#endif

// --- ray sets ---

struct RaySets {
  std::vector<Ray> camera, shadow, bounce;
  size_t pixels = 0;
};

// World-space corners of the hit triangle, in the renderer's prim numbering.
std::array<glm::vec3, 3> hitTriangle(const BenchScene& s, const Hit& h) {
  if (h.inst == PR_INVALID_INDEX) {
    const uint32_t* t = &s.indices[3 * size_t(h.prim)];
    return {s.positions[t[0]], s.positions[t[1]], s.positions[t[2]]};
  }
  const accel::InstanceInput& in = s.instances[h.inst];
  const DynMesh& m = s.meshes[in.mesh];
  const uint32_t* t = &m.indices[3 * size_t(h.prim - m.primBase)];
  auto w = [&](uint32_t v) {
    return glm::vec3(in.objectToWorld * glm::vec4(m.positions[v], 1.0f));
  };
  return {w(t[0]), w(t[1]), w(t[2])};
}

// Camera rays through pixel centres; the device finds their hits, which seed the other sets.
RaySets makeRays(const BenchScene& s, DeviceTracer& tracer, int width, int height) {
  RaySets sets;
  const glm::vec3 f = glm::normalize(s.camera.forward);
  const glm::vec3 r = glm::normalize(glm::cross(f, s.camera.up)), u = glm::cross(r, f);
  const float tanHalf = std::tan(0.5f * s.camera.yfov);
  const float aspect = float(width) / float(height);
  std::vector<Ray> all;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float sx = (2.0f * (float(x) + 0.5f) / float(width) - 1.0f) * tanHalf * aspect;
      const float sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(height)) * tanHalf;
      const glm::vec3 d = glm::normalize(f + sx * r + sy * u);
      const glm::vec3& o = s.camera.position;
      all.push_back(Ray{o.x, o.y, o.z, 0.0f, d.x, d.y, d.z, PR_INF_F});
    }
  sets.pixels = all.size();
  tracer.setRays(all);
  tracer.run(false);
  const std::vector<Hit> hits = tracer.hits();
  for (size_t i = 0; i < all.size(); ++i) {
    const Hit& h = hits[i];
    if (h.prim == PR_INVALID_INDEX) continue;
    const Ray& cr = all[i];
    sets.camera.push_back(cr);
    const auto tri = hitTriangle(s, h);
    const glm::vec3 p = (1.0f - h.u - h.v) * tri[0] + h.u * tri[1] + h.v * tri[2];
    glm::vec3 ng = glm::normalize(glm::cross(tri[1] - tri[0], tri[2] - tri[0]));
    if (glm::dot(ng, glm::vec3(cr.dx, cr.dy, cr.dz)) > 0.0f) ng = -ng;  // facing the camera
    dev::Rng rng = dev::rng_make(7u, PR_RNG_TEST, 0u, uint32_t(i), 0u);
    const float u1 = dev::rng_next(&rng), u2 = dev::rng_next(&rng), u3 = dev::rng_next(&rng);
    // Shadow ray: toward an emitter, a point light, or straight up.
    if (!s.emitters.empty()) {
      const auto& e =
          s.emitters[std::min(s.emitters.size() - 1, size_t(u1 * float(s.emitters.size())))];
      const dev::float2 b = dev::sample_triangle(u2, u3);
      const glm::vec3 q = (1.0f - b.x - b.y) * e[0] + b.x * e[1] + b.y * e[2];
      const glm::vec3 nq = glm::cross(e[1] - e[0], e[2] - e[0]);
      sets.shadow.push_back(dev::spawn_ray_to(toDev(p), toDev(ng), toDev(q), toDev(nq)));
    } else if (!s.pointLights.empty()) {
      const glm::vec3 q = s.pointLights[std::min(s.pointLights.size() - 1,
                                                 size_t(u1 * float(s.pointLights.size())))];
      sets.shadow.push_back(dev::spawn_ray(toDev(p), toDev(ng), toDev(q - p), 1.0f));
    } else {
      sets.shadow.push_back(
          dev::spawn_ray(toDev(p), toDev(ng), dev::make_float3(0.0f, 1.0f, 0.0f), PR_INF_F));
    }
    // Bounce ray: cosine-weighted about ng.
    dev::float3 t3, b3;
    dev::orthonormal_basis(toDev(ng), &t3, &b3);
    const dev::float3 l = dev::sample_cosine_hemisphere(dev::rng_next(&rng), dev::rng_next(&rng));
    const dev::float3 d = dev::to_world(l, t3, b3, toDev(ng));
    sets.bounce.push_back(dev::spawn_ray(toDev(p), toDev(ng), d, PR_INF_F));
  }
  return sets;
}

struct SetResult {
  SetResult(const char* n, bool any) : name(n), anyHit(any) {}
  const char* name;
  bool anyHit;
  size_t rays = 0;
  double hitFraction = 0.0;
  Rates ours, embree1, embree8;
  double agreeHit = -1.0, agreePrim = -1.0;  // fractions; -1: no reference
};

#ifndef PATHREUSE_HAVE_EMBREE
class EmbreeTracer;  // no reference: always null
#endif

struct BenchArgs {
  std::string scenePath, deviceSpec, jsonPath;
  double frameTime = 0.0;
  int width = 640, height = 480, repeats = 5, levels = 3, instances = 16, embreeThreads = 2;
  bool noEmbree = false;
  accel::BuildOptions build;
};

void addOptions(CLI::App& app, BenchArgs& a) {
  app.add_option("scene", a.scenePath, "glTF scene (none: the synthetic sphere flake)");
  app.add_option("--frame-time", a.frameTime, "Animation time of the DSG instances and camera (s)");
  app.add_option("--width", a.width, "Camera ray image width")->check(CLI::PositiveNumber);
  app.add_option("--height", a.height, "Camera ray image height")->check(CLI::PositiveNumber);
  app.add_option("--repeats", a.repeats, "Timed launches per set, after one warm-up")
      ->check(CLI::PositiveNumber);
  app.add_option("--device", a.deviceSpec,
                 "OpenCL device (index, platform:device, cpu, gpu or name)");
  app.add_option("--json", a.jsonPath, "Also write the results as JSON");
  app.add_option("--levels", a.levels,
                 "Synthetic scene: sphere-flake levels (3: about 236k triangles)");
  app.add_option("--instances", a.instances,
                 "Synthetic scene: dynamic instances of a 2k-triangle sphere");
  app.add_option("--embree-threads", a.embreeThreads, "Threads of the Embree reference")
      ->check(CLI::PositiveNumber);
  app.add_option("--bvh-width", a.build.width, "Children per BVH node (2, 4 or 8)")
      ->check(CLI::IsMember({2, 4, 8}));
  app.add_option("--leaf-size", a.build.maxLeafSize,
                 "BVH builder: largest leaf (tuning experiments)");
  app.add_option("--traversal-cost", a.build.traversalCost,
                 "BVH builder: SAH node cost per triangle test");
  app.add_flag("--no-embree", a.noEmbree, "Skip the Embree reference");
}

// The scene's BVHs, built as the renderer builds them (render/gpu_scene.cpp): SSG, each mesh,
// TLAS at the frame time; then uploaded.
struct Accels {
  explicit Accels(int width) : dsg(width), dacc(width) {}
  accel::StaticAccel ssg;
  accel::DynamicAccel dsg;
  accel::DeviceAccel dacc;
  double ssgSeconds = 0.0, meshSeconds = 0.0, tlasSeconds = 0.0;  // build times
  uint32_t meshNodes = 0;
};

void buildAccels(Context& ctx, const BenchScene& s, const accel::BuildOptions& build, Accels& acc) {
  double t0 = now();
  acc.ssg.build(s.positions, s.indices, build);
  acc.ssgSeconds = now() - t0;
  t0 = now();
  for (const DynMesh& m : s.meshes) acc.dsg.addMesh(m.positions, m.indices, m.primBase, build);
  acc.meshSeconds = now() - t0;
  std::vector<double> tlasTimes;
  for (int i = 0; i < 51; ++i) {
    t0 = now();
    acc.dsg.setInstances(s.instances);
    tlasTimes.push_back(now() - t0);
  }
  acc.tlasSeconds = median(tlasTimes);
  acc.meshNodes = acc.dsg.meshNodeCount();

  acc.dacc.uploadStatic(ctx, acc.ssg);
  acc.dacc.uploadMeshes(ctx, acc.dsg);
  acc.dacc.uploadFrame(ctx, acc.dsg);
  ctx.finish();
}

// Triangles of the DSG's meshes, and of its instances (a mesh once per instance).
std::pair<size_t, size_t> dynamicTriangles(const BenchScene& s) {
  size_t dynTris = 0, instTris = 0;
  for (const DynMesh& m : s.meshes) dynTris += m.indices.size() / 3;
  for (const auto& in : s.instances) instTris += s.meshes[in.mesh].indices.size() / 3;
  return {dynTris, instTris};
}

void printAccels(const BenchScene& s, const Accels& acc, double loadSeconds) {
  const auto [dynTris, instTris] = dynamicTriangles(s);
  const auto& st = acc.ssg.stats();
  std::printf("scene: %s (loaded in %.2f s)\n", s.name.c_str(), loadSeconds);
  std::printf(
      "SSG:  %zu triangles, build %.1f ms, binary tree of %u nodes, %u leaves, depth %d, SAH "
      "cost %.1f; "
      "%u nodes %d wide, stack need %d\n",
      s.indices.size() / 3, acc.ssgSeconds * 1e3, st.nodes, st.leaves, st.depth,
      sahCost(acc.ssg.nodes(), 0), acc.ssg.wide().nodeCount(), acc.ssg.wide().width,
      acc.ssg.wide().stackNeed);
  std::printf(
      "DSG:  %zu meshes (%zu triangles), mesh BVHs %.2f ms, %u nodes; %zu instances (%zu "
      "triangles), "
      "TLAS %.3f ms, %u nodes, depth %d\n",
      s.meshes.size(), dynTris, acc.meshSeconds * 1e3, acc.meshNodes, s.instances.size(), instTris,
      acc.tlasSeconds * 1e3, acc.dsg.tlasStats().nodes, acc.dsg.tlasStats().depth);
  std::printf("device memory: SSG %.2f MiB, DSG meshes %.2f MiB, per frame %.1f KiB\n",
              double(acc.dacc.staticBytes()) / (1 << 20), double(acc.dacc.meshBytes()) / (1 << 20),
              double(acc.dacc.frameBytes()) / 1024.0);
  std::printf("emitters: %zu triangles, %zu point lights\n", s.emitters.size(),
              s.pointLights.size());
}

#ifdef PATHREUSE_HAVE_EMBREE
// Embree's answers for the same rays against ours: how many agree on hit or miss (occluded or
// not), and on the primitive hit. Leaves Embree warmed up for both of its ways to trace, and
// eh and eo sized for the timed runs.
void compareWithEmbree(EmbreeTracer& embree, const std::vector<Ray>& rays,
                       const std::vector<Hit>& hits, const std::vector<cl_uint>& occ,
                       SetResult& res, std::vector<Hit>& eh, std::vector<cl_uint>& eo) {
  embree.run(rays, res.anyHit, 1, &eh, &eo);  // warm-up, and the answers to compare
  size_t sameHit = 0, samePrim = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    if (res.anyHit) {
      sameHit += size_t((occ[i] != 0) == (eo[i] != 0));
      continue;
    }
    sameHit += size_t((hits[i].prim == PR_INVALID_INDEX) == (eh[i].prim == PR_INVALID_INDEX));
    samePrim += size_t(hits[i].prim == eh[i].prim && hits[i].inst == eh[i].inst);
  }
  const double n = double(std::max<size_t>(rays.size(), 1));
  res.agreeHit = double(sameHit) / n;
  res.agreePrim = res.anyHit ? res.agreeHit : double(samePrim) / n;
  embree.run(rays, res.anyHit, 8, &eh, &eo);
}
#endif

// Times one ray set: a warm-up launch (whose answers give the hit fraction), then `repeats`
// timed launches of ours, each followed by Embree's where there is a reference.
void measureSet(DeviceTracer& ours, EmbreeTracer* embree, const std::vector<Ray>& rays, int repeats,
                SetResult& res) {
  res.rays = rays.size();
  ours.setRays(rays);
  ours.run(res.anyHit);  // warm-up
  const std::vector<Hit> hits = ours.hits();
  const std::vector<cl_uint> occ = ours.occluded();
  size_t hitCount = 0;
  for (size_t i = 0; i < rays.size(); ++i)
    hitCount += res.anyHit ? size_t(occ[i] != 0) : size_t(hits[i].prim != PR_INVALID_INDEX);
  res.hitFraction = double(hitCount) / double(std::max<size_t>(rays.size(), 1));
#ifdef PATHREUSE_HAVE_EMBREE
  std::vector<Hit> eh;
  std::vector<cl_uint> eo;
  if (embree) compareWithEmbree(*embree, rays, hits, occ, res, eh, eo);
#else
  (void)embree;
#endif
  // Ours and the reference alternate, so drifting load hits both alike.
  for (int r = 0; r < repeats; ++r) {
    res.ours.mrays.push_back(ours.run(res.anyHit));
#ifdef PATHREUSE_HAVE_EMBREE
    if (embree) {
      res.embree1.mrays.push_back(embree->run(rays, res.anyHit, 1, &eh, &eo));
      res.embree8.mrays.push_back(embree->run(rays, res.anyHit, 8, &eh, &eo));
    }
#endif
  }
}

void printResults(const std::vector<SetResult>& results) {
  std::printf("\n%-7s %-7s %8s %6s | %-24s", "rays", "query", "count", "hit%",
              "ours Mrays/s med [min-max]");
  const bool ref = !results[0].embree1.mrays.empty();
  if (ref)
    std::printf(" | %-9s %-9s %-6s %-9s %-9s", "Embree-1", "Embree-8", "ratio", "agree",
                "same-prim");
  std::printf("\n");
  for (const SetResult& r : results) {
    char ourCol[64];
    std::snprintf(ourCol, sizeof ourCol, "%7.2f [%.2f-%.2f]", r.ours.med(), r.ours.min(),
                  r.ours.max());
    std::printf("%-7s %-7s %8zu %5.1f%% | %-24s", r.name, r.anyHit ? "any" : "closest", r.rays,
                100.0 * r.hitFraction, ourCol);
    if (ref) {
      const double best = std::max(r.embree1.med(), r.embree8.med());
      std::printf(" | %9.2f %9.2f %6.3f %8.4f%% %8.4f%%", r.embree1.med(), r.embree8.med(),
                  best > 0.0 ? r.ours.med() / best : 0.0, 100.0 * r.agreeHit, 100.0 * r.agreePrim);
    }
    std::printf("\n");
  }
  if (ref)
    std::printf(
        "ratio = ours / the better of Embree-1 (rtcIntersect1) and Embree-8 (8-wide packets)\n");
}

json accelsJson(const BenchScene& s, const Accels& acc) {
  const auto [dynTris, instTris] = dynamicTriangles(s);
  const auto& st = acc.ssg.stats();
  json j;
  j["ssg"] = {{"triangles", s.indices.size() / 3},
              {"build_ms", acc.ssgSeconds * 1e3},
              {"nodes", st.nodes},
              {"leaves", st.leaves},
              {"depth", st.depth},
              {"sah_cost", sahCost(acc.ssg.nodes(), 0)},
              {"wide_nodes", acc.ssg.wide().nodeCount()},
              {"width", acc.ssg.wide().width},
              {"stack_need", acc.ssg.wide().stackNeed}};
  j["dsg"] = {{"meshes", s.meshes.size()},
              {"mesh_triangles", dynTris},
              {"mesh_build_ms", acc.meshSeconds * 1e3},
              {"mesh_nodes", acc.meshNodes},
              {"instances", s.instances.size()},
              {"instance_triangles", instTris},
              {"tlas_build_ms", acc.tlasSeconds * 1e3},
              {"tlas_nodes", acc.dsg.tlasStats().nodes}};
  j["device_bytes"] = {{"ssg", acc.dacc.staticBytes()},
                       {"dsg_meshes", acc.dacc.meshBytes()},
                       {"per_frame", acc.dacc.frameBytes()}};
  return j;
}

json setJson(const SetResult& r, bool ref) {
  json e = {{"query", r.anyHit ? "any" : "closest"},
            {"rays", r.rays},
            {"hit_fraction", r.hitFraction},
            {"ours_mrays", r.ours.toJson()}};
  if (ref) {
    e["embree1_mrays"] = r.embree1.toJson();
    e["embree8_mrays"] = r.embree8.toJson();
    e["agree_hit"] = r.agreeHit;
    e["agree_prim"] = r.agreePrim;
  }
  return e;
}

void writeJson(const BenchArgs& a, const std::string& deviceName, const char* cap,
               const BenchScene& s, const Accels& acc, const EmbreeTracer* embree,
               const std::vector<SetResult>& results) {
  json j;
  j["device"] = deviceName;
  j["pocl_max_pthread_count"] = cap ? cap : "";
  j["scene"] = s.name;
  j["frame_time"] = a.frameTime;
  j["image"] = {a.width, a.height};
  j.update(accelsJson(s, acc));
#ifdef PATHREUSE_HAVE_EMBREE
  if (embree)
    j["embree"] = {{"version", RTC_VERSION_STRING},
                   {"threads", a.embreeThreads},
                   {"build_ms", embree->buildSeconds() * 1e3},
                   {"bytes", g_embreeBytes.load()}};
#else
  (void)embree;
#endif
  const bool ref = !results[0].embree1.mrays.empty();
  for (const SetResult& r : results) j["sets"][r.name] = setJson(r, ref);
  std::ofstream(a.jsonPath) << j.dump(2) << "\n";
}

int runBench(const BenchArgs& a) {
  const auto devices = enumerateDevices();
  Context ctx(selectDevice(devices, a.deviceSpec));
  const std::string deviceName = describeDevice(ctx.device());
  const char* cap = std::getenv("POCL_MAX_PTHREAD_COUNT");
  std::printf("device: %s (POCL_MAX_PTHREAD_COUNT=%s)\n", deviceName.c_str(), cap ? cap : "unset");

  const double t0 = now();
  const BenchScene s =
      a.scenePath.empty() ? synthetic(a.levels, a.instances) : fromGltf(a.scenePath, a.frameTime);
  const double loadSeconds = now() - t0;
  Accels acc(a.build.width);
  buildAccels(ctx, s, a.build, acc);
  printAccels(s, acc, loadSeconds);

  DeviceTracer ours(ctx, acc.dacc);
  const RaySets sets = makeRays(s, ours, a.width, a.height);
  std::printf("rays: %zu camera (%d x %d, %.1f%% hit), %zu shadow, %zu bounce\n",
              sets.camera.size(), a.width, a.height,
              100.0 * double(sets.camera.size()) / double(std::max<size_t>(sets.pixels, 1)),
              sets.shadow.size(), sets.bounce.size());

#ifdef PATHREUSE_HAVE_EMBREE
  std::unique_ptr<EmbreeTracer> embree;
  if (!a.noEmbree) embree = std::make_unique<EmbreeTracer>(s, a.embreeThreads);
  if (embree)
    std::printf(
        "Embree %d.%d.%d, %d threads: build (quality high) %.1f ms (meshes %.1f ms), %.2f MiB\n",
        RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH, a.embreeThreads,
        embree->buildSeconds() * 1e3, embree->meshSeconds() * 1e3,
        double(g_embreeBytes.load()) / (1 << 20));
  EmbreeTracer* reference = embree.get();
#else
  EmbreeTracer* reference = nullptr;
#endif

  std::vector<SetResult> results{{"camera", false}, {"shadow", true}, {"bounce", false}};
  const std::vector<Ray>* raysOf[3] = {&sets.camera, &sets.shadow, &sets.bounce};
  for (size_t k = 0; k < results.size(); ++k)
    measureSet(ours, reference, *raysOf[k], a.repeats, results[k]);
  printResults(results);
  if (!a.jsonPath.empty()) writeJson(a, deviceName, cap, s, acc, reference, results);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"ray_bench: BVH build and ray throughput of the SSG + DSG"};
  BenchArgs args;
  addOptions(app, args);
  CLI11_PARSE(app, argc, argv);
  try {
    return runBench(args);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ray_bench: %s\n", e.what());
    return 1;
  }
}
