#include "render/aov.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "cl/kernel_binding.h"
#include "render/integrator.h"
#include "util/error.h"

namespace pr {

namespace {

constexpr int kAovFloats = 12;  // per pixel, kernels/aov.cl's PR_AOV_FLOATS

}  // namespace

uint32_t parseAovs(const std::string& list) {
  static const std::pair<const char*, uint32_t> kNames[] = {
      {"albedo", kAovAlbedo},   {"normal", kAovNormal}, {"depth", kAovDepth},
      {"motion", kAovMotion},   {"object", kAovObject}, {"material", kAovMaterial},
      {"samples", kAovSamples}, {"all", 127u}};
  uint32_t bits = 0;
  std::stringstream in(list);
  std::string name;
  while (std::getline(in, name, ',')) {
    uint32_t bit = 0;
    for (const auto& [n, b] : kNames)
      if (name == n) bit = b;
    if (!bit)
      throw InputError("--aov " + list + ": unknown image '" + name +
                       "' (albedo, normal, depth, motion, object, material, samples, all)");
    bits |= bit;
  }
  if (!bits) throw InputError("--aov: names no image");
  return bits;
}

AovRenderer::AovRenderer(Context& ctx, const Scene& scene, GpuScene& gpu, uint32_t aovs,
                         const AovSampling& sampling, bool denoise)
    : ctx_(ctx), scene_(scene), gpu_(gpu), aovs_(aovs), sampling_(sampling) {
  if (denoise) denoiser_ = std::make_unique<Denoiser>();  // a missing library: an error now
}

void AovRenderer::setUp() {
  kernel_ = kargs::kernel<kargs::AovArgs>(ctx_, "aov.cl", gpu_.buildOptions());
  // Objects are glTF nodes: the SSG's triangles keep theirs, an instance is its node's.
  std::vector<uint32_t> tri(scene_.staticTriangleNodes.begin(), scene_.staticTriangleNodes.end());
  if (tri.empty()) tri.push_back(0u);
  triObject_ = ctx_.allocate("aov triangle objects", tri.size() * 4, CL_MEM_READ_ONLY);
  CL_CHECK(ctx_.queue().enqueueWriteBuffer(triObject_, CL_TRUE, 0, tri.size() * 4, tri.data()));
  std::vector<uint32_t> inst;
  for (const Instance& i : scene_.instances) inst.push_back(uint32_t(i.node));
  if (inst.empty()) inst.push_back(0u);
  instObject_ = ctx_.allocate("aov instance objects", inst.size() * 4, CL_MEM_READ_ONLY);
  CL_CHECK(ctx_.queue().enqueueWriteBuffer(instObject_, CL_TRUE, 0, inst.size() * 4, inst.data()));
  size_t verts = 0;
  for (size_t m = 0; m < scene_.dynamicMeshes.size(); ++m) {
    verts += scene_.dynamicMeshes[m].vertexCount();
    anyDeforms_ = anyDeforms_ || scene_.meshDeforms(m);
  }
  prevPos_ = ctx_.allocate("aov previous vertices", std::max<size_t>(verts, 1) * 16);
  ctx_.zero(prevPos_, std::max<size_t>(verts, 1) * 16);
  prevInst_ =
      ctx_.allocate("aov previous transforms", std::max<size_t>(scene_.instances.size(), 1) * 48);
  ctx_.zero(prevInst_, std::max<size_t>(scene_.instances.size(), 1) * 48);
}

void AovRenderer::uploadPrevious(double t) {
  if (restUploaded_ && !anyDeforms_) return;
  std::vector<float> pos;
  TriangleMesh shape;
  for (size_t m = 0; m < scene_.dynamicMeshes.size(); ++m) {
    const TriangleMesh* mesh = &scene_.dynamicMeshes[m];
    if (scene_.meshDeforms(m)) {
      scene_.deformMesh(m, t, &shape);
      mesh = &shape;
    }
    for (const glm::vec3& p : mesh->positions) pos.insert(pos.end(), {p.x, p.y, p.z, 1.0f});
  }
  if (!pos.empty())
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(prevPos_, CL_TRUE, 0, pos.size() * 4, pos.data()));
  restUploaded_ = true;
}

std::pair<double, double> AovRenderer::render(int64_t frame, double fps, int camera, Image* image) {
  const auto t0 = std::chrono::steady_clock::now();
  const int w = image->width, h = image->height;
  const uint32_t n = uint32_t(w) * uint32_t(h);
  const double then = (frame - 1) / fps;
  if (!kernel_()) setUp();  // on the one device that renders them, at its first frame
  uploadPrevious(then);
  std::vector<float> inst(std::max<size_t>(scene_.instances.size(), 1) * 12, 0.0f);
  for (size_t i = 0; i < scene_.instances.size(); ++i)
    toRows(scene_.instanceTransform(i, then), &inst[i * 12]);
  CL_CHECK(ctx_.queue().enqueueWriteBuffer(prevInst_, CL_TRUE, 0, inst.size() * 4, inst.data()));
  if (n > outPixels_) {
    if (out_()) ctx_.release("aov images", uint64_t(outPixels_) * kAovFloats * 4);
    out_ = ctx_.allocate("aov images", uint64_t(n) * kAovFloats * 4);
    outPixels_ = n;
  }

  kargs::AovArgs a;
  kargs::setScene(&a, gpu_.kernelArgs());
  a.cam = gpu_.camera(camera, frame / fps, w, h);
  a.cam_steps = gpu_.cameraSteps();
  a.cam_step_count = gpu_.motionSteps();
  a.prev_cam = toCameraParams(scene_.cameraAt(camera, then), w, h);
  a.prev_inst = prevInst_;
  a.prev_pos = prevPos_;
  a.tri_object = triObject_;
  a.inst_object = instObject_;
  a.aov = out_;
  a.static_vertices = uint32_t(scene_.staticMesh.vertexCount());
  a.static_triangles = uint32_t(scene_.staticTriangleNodes.size());
  a.seed = sampling_.seed;
  a.jitter_frame = sampling_.jitterFromFrame0 ? 0u : rngFrameKey(frame);
  a.spp = uint32_t(sampling_.spp);
  a.max_depth = uint32_t(sampling_.maxDepth);
  a.end = n;
  a.set(kernel_);
  ctx_.launch1D(kernel_, n, "aov");
  std::vector<float> v(size_t(n) * kAovFloats);
  CL_CHECK(ctx_.queue().enqueueReadBuffer(out_, CL_TRUE, 0, v.size() * 4, v.data()));

  auto channel = [&](const char* name, int at, bool mean, bool fullFloat) {
    ImageChannel c{name, std::vector<float>(n), fullFloat};
    for (uint32_t p = 0; p < n; ++p) {
      const float* px = &v[size_t(p) * kAovFloats];
      c.values[p] = mean ? px[at] / px[11] : px[at];
    }
    image->channels.push_back(std::move(c));
  };
  if (aovs_ & kAovAlbedo)
    for (int k = 0; k < 3; ++k)
      channel(k == 0 ? "albedo.R" : k == 1 ? "albedo.G" : "albedo.B", k, true, false);
  if (aovs_ & kAovNormal)
    for (int k = 0; k < 3; ++k)
      channel(k == 0 ? "normal.X" : k == 1 ? "normal.Y" : "normal.Z", 3 + k, true, false);
  if (aovs_ & kAovDepth) channel("Z", 6, false, true);
  if (aovs_ & kAovMotion) {
    channel("motion.X", 7, true, false);
    channel("motion.Y", 8, true, false);
  }
  if (aovs_ & kAovObject) channel("object.ID", 9, false, true);
  if (aovs_ & kAovMaterial) channel("material.ID", 10, false, true);
  const auto t1 = std::chrono::steady_clock::now();
  if (denoiser_) denoise(v, image);
  return {std::chrono::duration<double>(t1 - t0).count(),
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count()};
}

void AovRenderer::denoise(const std::vector<float>& v, Image* image) {
  const size_t n = size_t(image->width) * image->height;
  std::vector<float> color(n * 3), albedo(n * 3), normal(n * 3);
  for (size_t p = 0; p < n; ++p) {
    const float* px = &v[p * kAovFloats];
    for (int k = 0; k < 3; ++k) {
      color[p * 3 + k] = image->rgba[p * 4 + k];
      albedo[p * 3 + k] = px[k] / px[11];
      normal[p * 3 + k] = px[3 + k] / px[11];
    }
  }
  denoiser_->denoise(image->width, image->height, color.data(), albedo.data(), normal.data());
  for (int k = 0; k < 3; ++k) {
    ImageChannel c{k == 0   ? "noisy.R"
                   : k == 1 ? "noisy.G"
                            : "noisy.B",
                   std::vector<float>(n), false};
    for (size_t p = 0; p < n; ++p) {
      c.values[p] = image->rgba[p * 4 + k];
      image->rgba[p * 4 + k] = color[p * 3 + k];
    }
    image->channels.push_back(std::move(c));
  }
}

}  // namespace pr
