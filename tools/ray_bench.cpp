// ray_bench: BVH build time, buffer sizes and traversal speed (Mrays/s) of the SSG + DSG on an
// OpenCL device, for coherent camera rays and incoherent diffuse-bounce rays, on a sphere-flake
// scene of about 250k static triangles plus a few animated instances.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <random>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/vec3.hpp>

#include "accel/device_accel.h"
#include "accel/scene_accel.h"
#include "cl/context.h"
#include "cl/device.h"
#include "cl/error.h"
#include "shared/bvh.h"

namespace {

using namespace pr;
using dev::Hit;
using dev::Ray;

struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  size_t triangles() const { return indices.size() / 3; }
};

void addSphere(Mesh& m, glm::vec3 c, float r, int rings, int segments) {
  const uint32_t base = uint32_t(m.positions.size());
  for (int i = 0; i <= rings; ++i) {
    const float th = PR_PI * float(i) / float(rings);
    for (int j = 0; j < segments; ++j) {
      const float ph = 2.0f * PR_PI * float(j) / float(segments);
      m.positions.push_back(c + r * glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)));
    }
  }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = base + uint32_t(i * segments + j), b = base + uint32_t(i * segments + (j + 1) % segments);
      const uint32_t c2 = a + uint32_t(segments), d = b + uint32_t(segments);
      if (i > 0) m.indices.insert(m.indices.end(), {a, c2, b});
      if (i < rings - 1) m.indices.insert(m.indices.end(), {b, c2, d});
    }
}

// Nine children per sphere at a third of its radius, on the side away from the parent.
void addFlake(Mesh& m, glm::vec3 c, float r, glm::vec3 up, int levels) {
  addSphere(m, c, r, 10, 16);
  if (levels == 0) return;
  dev::float3 t3, b3;
  dev::orthonormal_basis(dev::make_float3(up.x, up.y, up.z), &t3, &b3);
  const glm::vec3 t(t3.x, t3.y, t3.z), b(b3.x, b3.y, b3.z);
  for (int k = 0; k < 9; ++k) {
    const float elev = k < 6 ? 0.0f : 1.0f;  // six around the equator, three above
    const float az = 2.0f * PR_PI * (k < 6 ? float(k) / 6.0f : (float(k - 6) + 0.5f) / 3.0f);
    const glm::vec3 dir = glm::normalize(std::cos(elev) * (std::cos(az) * t + std::sin(az) * b) + std::sin(elev) * up);
    addFlake(m, c + dir * (r * 4.0f / 3.0f), r / 3.0f, dir, levels - 1);
  }
}

glm::vec3 cosineDir(glm::vec3 n, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float r = std::sqrt(u(rng)), ph = 2.0f * PR_PI * u(rng);
  dev::float3 t3, b3;
  dev::orthonormal_basis(dev::make_float3(n.x, n.y, n.z), &t3, &b3);
  const glm::vec3 t(t3.x, t3.y, t3.z), b(b3.x, b3.y, b3.z);
  return r * std::cos(ph) * t + r * std::sin(ph) * b + std::sqrt(std::max(0.0f, 1.0f - r * r)) * n;
}

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// Best of `reps` launches, in Mrays/s.
double timeKernel(Context& ctx, cl::Kernel& k, size_t n, int reps) {
  double best = 1e30;
  for (int r = 0; r < reps; ++r) {
    ctx.finish();
    const double t0 = now();
    ctx.launch1D(k, n, "ray_bench");
    ctx.finish();
    best = std::min(best, now() - t0);
  }
  return double(n) / best * 1e-6;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"ray_bench: BVH build and traversal speed"};
  std::string deviceSpec;
  int width = 512, levels = 3, reps = 3, instances = 16;
  app.add_option("--device", deviceSpec, "OpenCL device (index, platform:device, cpu, gpu or name)");
  app.add_option("--width", width, "Image width and height of the camera rays");
  app.add_option("--levels", levels, "Sphere-flake recursion levels (3: about 236k triangles)");
  app.add_option("--instances", instances, "Dynamic instances of a 2k-triangle sphere");
  app.add_option("--reps", reps, "Launches per measurement (the best counts)");
  CLI11_PARSE(app, argc, argv);
  try {
    const auto devices = enumerateDevices();
    Context ctx(selectDevice(devices, deviceSpec));
    std::printf("device: %s\n", describeDevice(ctx.device()).c_str());

    Mesh flake;
    addFlake(flake, glm::vec3(0.0f), 1.0f, glm::vec3(0, 1, 0), levels);
    const glm::vec3 g[4] = {{-8, -1.5f, -8}, {8, -1.5f, -8}, {8, -1.5f, 8}, {-8, -1.5f, 8}};
    const uint32_t gb = uint32_t(flake.positions.size());
    flake.positions.insert(flake.positions.end(), g, g + 4);
    flake.indices.insert(flake.indices.end(), {gb, gb + 2, gb + 1, gb, gb + 3, gb + 2});
    Mesh ball;
    addSphere(ball, glm::vec3(0.0f), 0.3f, 32, 32);

    accel::StaticAccel ssg;
    ssg.build(flake.positions, flake.indices);
    accel::DynamicAccel dsg;
    double t0 = now();
    dsg.addMesh(ball.positions, ball.indices);
    const double meshBuild = now() - t0;
    std::vector<accel::InstanceInput> inst;
    for (int i = 0; i < instances; ++i) {
      const float a = 2.0f * PR_PI * float(i) / float(std::max(instances, 1));
      inst.push_back({0, glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(2.2f * std::cos(a), 0.3f * float(i % 3), 2.2f * std::sin(a))),
                                    glm::vec3(1.0f, 0.6f + 0.1f * float(i % 4), 1.0f))});
    }
    t0 = now();
    const int tlasReps = 100;
    for (int i = 0; i < tlasReps; ++i) dsg.setInstances(inst);
    const double tlasBuild = (now() - t0) / tlasReps;

    const auto& st = ssg.stats();
    std::printf("SSG: %zu triangles, BVH build %.1f ms, %u nodes, %u leaves, depth %d\n", flake.triangles(),
                st.seconds * 1e3, st.nodes, st.leaves, st.depth);
    std::printf("DSG: %zu-triangle mesh BVH %.2f ms; %d instances: world bounds + TLAS %.3f ms/frame\n",
                ball.triangles(), meshBuild * 1e3, instances, tlasBuild * 1e3);

    accel::DeviceAccel dacc;
    t0 = now();
    dacc.uploadStatic(ctx, ssg);
    dacc.uploadMeshes(ctx, dsg);
    dacc.uploadFrame(ctx, dsg);
    ctx.finish();
    std::printf("buffers: static %.2f MiB, meshes %.2f MiB, per frame %.1f KiB (upload %.1f ms)\n",
                double(dacc.staticBytes()) / (1 << 20), double(dacc.meshBytes()) / (1 << 20),
                double(dacc.frameBytes()) / 1024.0, (now() - t0) * 1e3);

    t0 = now();
    ProgramBuild pb = ctx.buildProgram("test/trace.cl");
    std::printf("kernel build %.2f s%s\n", now() - t0, pb.fromCache ? " (cached)" : "");
    cl_int err = CL_SUCCESS;
    cl::Kernel closest(pb.program, "trace_closest", &err);
    CL_CHECK(err);
    cl::Kernel any(pb.program, "trace_any", &err);
    CL_CHECK(err);

    // Coherent: a pinhole camera looking at the flake.
    const size_t n = size_t(width) * size_t(width);
    std::vector<Ray> rays(n);
    const glm::vec3 eye(0.5f, 1.5f, 5.0f), at(0.0f, 0.2f, 0.0f);
    const glm::vec3 fw = glm::normalize(at - eye), right = glm::normalize(glm::cross(fw, glm::vec3(0, 1, 0)));
    const glm::vec3 up = glm::cross(right, fw);
    const float tanHalf = std::tan(0.5f * 50.0f * PR_PI / 180.0f);
    for (int y = 0; y < width; ++y)
      for (int x = 0; x < width; ++x) {
        const float sx = (2.0f * (float(x) + 0.5f) / float(width) - 1.0f) * tanHalf;
        const float sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(width)) * tanHalf;
        const glm::vec3 d = glm::normalize(fw + sx * right + sy * up);
        rays[size_t(y) * size_t(width) + size_t(x)] = Ray{eye.x, eye.y, eye.z, 0.0f, d.x, d.y, d.z, PR_INF_F};
      }
    const cl_uint cn = cl_uint(n);
    cl::Buffer rb = ctx.allocate("rays", n * sizeof(Ray)), hb = ctx.allocate("hits", n * sizeof(Hit)),
               ob = ctx.allocate("occluded", n * sizeof(cl_uint));
    CL_CHECK(closest.setArg(0, rb));
    CL_CHECK(closest.setArg(1, hb));
    CL_CHECK(closest.setArg(2, cn));
    dacc.setKernelArgs(ctx, closest, 3);
    CL_CHECK(any.setArg(0, rb));
    CL_CHECK(any.setArg(1, ob));
    CL_CHECK(any.setArg(2, cn));
    dacc.setKernelArgs(ctx, any, 3);

    CL_CHECK(ctx.queue().enqueueWriteBuffer(rb, CL_TRUE, 0, n * sizeof(Ray), rays.data()));
    const double camClosest = timeKernel(ctx, closest, n, reps);
    const double camAny = timeKernel(ctx, any, n, reps);
    std::vector<Hit> hits(n);
    CL_CHECK(ctx.queue().enqueueReadBuffer(hb, CL_TRUE, 0, n * sizeof(Hit), hits.data()));
    size_t hitCount = 0;

    // Incoherent: a cosine-distributed bounce from each camera hit (random rays where it missed).
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-3.0f, 3.0f);
    const auto& meshTris = dsg.meshTriangles();
    for (size_t i = 0; i < n; ++i) {
      const Hit& h = hits[i];
      if (h.prim == PR_INVALID_INDEX) {
        const glm::vec3 o(u(rng), u(rng) * 0.5f, u(rng)), d = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + 1e-3f);
        rays[i] = Ray{o.x, o.y, o.z, 0.0f, d.x, d.y, d.z, PR_INF_F};
        continue;
      }
      ++hitCount;
      const Ray& r = rays[i];
      const glm::vec3 p = glm::vec3(r.ox, r.oy, r.oz) + h.t * glm::vec3(r.dx, r.dy, r.dz);
      glm::vec3 ng;
      if (h.inst == PR_INVALID_INDEX) {
        const uint32_t* tri = &flake.indices[3 * size_t(h.prim)];
        ng = glm::cross(flake.positions[tri[1]] - flake.positions[tri[0]], flake.positions[tri[2]] - flake.positions[tri[0]]);
      } else {
        const dev::BvhTriangle* t = nullptr;
        for (const auto& mt : meshTris)
          if (mt.prim == h.prim) t = &mt;
        const glm::mat3 m(inst[h.inst].objectToWorld);
        ng = glm::transpose(glm::inverse(m)) * glm::cross(glm::vec3(t->e1x, t->e1y, t->e1z), glm::vec3(t->e2x, t->e2y, t->e2z));
      }
      ng = glm::normalize(ng);
      if (glm::dot(ng, glm::vec3(r.dx, r.dy, r.dz)) > 0.0f) ng = -ng;
      const glm::vec3 d = cosineDir(ng, rng);
      rays[i] = dev::spawn_ray(dev::make_float3(p.x, p.y, p.z), dev::make_float3(ng.x, ng.y, ng.z),
                               dev::make_float3(d.x, d.y, d.z), PR_INF_F);
    }
    CL_CHECK(ctx.queue().enqueueWriteBuffer(rb, CL_TRUE, 0, n * sizeof(Ray), rays.data()));
    const double incClosest = timeKernel(ctx, closest, n, reps);
    const double incAny = timeKernel(ctx, any, n, reps);

    // The CPU reference (one thread) on the first incoherent rays, for scale.
    const dev::SceneGeom cg{ssg.nodes().data(), ssg.triangles().data(), dsg.tlasNodes().data(),
                            dsg.instances().data(), dsg.meshNodes().data(), dsg.meshTriangles().data(),
                            uint32_t(dsg.instances().size())};
    const size_t cpuN = std::min<size_t>(n, 50000);
    t0 = now();
    size_t cpuHits = 0;
    for (size_t i = 0; i < cpuN; ++i) {
      Hit h;
      cpuHits += size_t(dev::intersect_scene(&cg, rays[i], &h));
    }
    const double cpuRate = double(cpuN) / (now() - t0) * 1e-6;

    std::printf("rays: %zu per launch (%d x %d), camera hit %.0f%%\n", n, width, width, 100.0 * double(hitCount) / double(n));
    std::printf("coherent   (camera):  closest %7.2f Mrays/s, any %7.2f Mrays/s\n", camClosest, camAny);
    std::printf("incoherent (bounce):  closest %7.2f Mrays/s, any %7.2f Mrays/s\n", incClosest, incAny);
    std::printf("CPU reference, 1 thread, incoherent closest: %.2f Mrays/s (%zu hits)\n", cpuRate, cpuHits);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ray_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
