#include "render/renderer.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "cl/context.h"
#include "cl/device.h"
#include "io/image.h"
#include "render/film.h"
#include "render/gpu_scene.h"
#include "render/path_reuse.h"
#include "render/path_tracer.h"
#include "scene/gltf_loader.h"
#include "util/error.h"

namespace pr {

namespace {

std::string clock(double seconds) {
  const long s = std::lround(seconds);
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%02ld:%02ld", s / 60, s % 60);
  return buf;
}

void chooseSize(const RenderOptions& o, const CameraPose& pose, int* w, int* h) {
  const double aspect = pose.aspect > 0.0f ? pose.aspect : 4.0 / 3.0;
  *w = o.width;
  *h = o.height;
  if (*w == 0 && *h == 0) {
    *h = 480;
    *w = pose.aspect > 0.0f ? std::max(1, int(std::lround(480 * aspect))) : 640;
  } else if (*w == 0) {
    *w = std::max(1, int(std::lround(*h * aspect)));
  } else if (*h == 0) {
    *h = std::max(1, int(std::lround(*w / aspect)));
  }
}

}  // namespace

int runRender(const RenderOptions& o) {
  validateOutPattern(o.outPattern);
  if (o.spp < 1) throw InputError("--spp " + std::to_string(o.spp) + ": must be at least 1");
  if (o.maxDepth < 1 || o.maxDepth > 64)
    throw InputError("--max-depth " + std::to_string(o.maxDepth) + ": must be 1 to 64");
  if (!(o.fps > 0.0) || !std::isfinite(o.fps)) throw InputError("--fps: must be positive");
  if (o.width < 0 || o.height < 0 || o.width > 16384 || o.height > 16384)
    throw InputError("--width/--height: must be 1 to 16384");

  const Scene scene = loadScene(o.scene);
  if (scene.staticTriangleCount() + scene.dynamicTriangleCount() == 0)
    throw InputError(o.scene + ": nothing to render (no triangles)");
  if (scene.emissiveTriangleCount() == 0 && scene.lights.empty())
    std::cerr << "warning: " << o.scene << ": no lights; frames will be black\n";
  const int cameraCount = static_cast<int>(scene.cameras.size());
  const int cam = o.camera < 0 ? 0 : o.camera;
  if (cam >= cameraCount)
    throw InputError("--camera " + std::to_string(o.camera) + ": " + o.scene + " has " +
                     std::to_string(cameraCount) + " camera(s)");
  if (!scene.cameras[cam].perspective)
    throw InputError(o.scene + ": camera " + std::to_string(cam) +
                     " is orthographic; only perspective cameras are supported");

  const int frameCount = static_cast<int>(scene.frameCount(o.fps));
  FrameRange range = o.frames;
  if (!o.framesGiven) range = {0, frameCount - 1};
  if (range.last < 0) range.last = frameCount - 1;

  int width = 0, height = 0;
  chooseSize(o, scene.cameraAt(cam, 0.0), &width, &height);

  const auto devices = enumerateDevices();
  const DeviceEntry& device = selectDevice(devices, o.device);
  Context ctx(device);
  GpuSceneOptions sceneOptions;
  sceneOptions.forceDiffuse = o.forceDiffuse;
  GpuScene gpu(ctx, scene, sceneOptions);
  Film film(ctx, width, height);
  std::unique_ptr<Integrator> integrator;
  switch (o.mode) {
    case RenderMode::PathTrace:
      integrator = std::make_unique<PathTracer>(ctx, gpu, film,
                                                PathTracerSettings{o.spp, o.maxDepth, o.seed});
      break;
    case RenderMode::Reuse:
    case RenderMode::Retrace: {
      PathReuseSettings r;
      r.spp = o.spp;
      r.maxDepth = o.maxDepth;
      r.seed = o.seed;
      r.lightPaths = static_cast<uint32_t>(o.lightPaths);
      r.pathsPerPixel = static_cast<uint32_t>(o.pathsPerPixel);
      r.clamp = o.clamp;
      r.retraceAll = o.mode == RenderMode::Retrace;
      integrator = std::make_unique<PathReuse>(ctx, gpu, film, r);
      break;
    }
  }

  std::unique_ptr<std::ofstream> stats;
  if (!o.statsFile.empty()) {
    const auto parent = std::filesystem::path(o.statsFile).parent_path();
    std::error_code ec;
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
    stats = std::make_unique<std::ofstream>(o.statsFile, std::ios::trunc);
    if (!*stats) throw RuntimeError(o.statsFile + ": cannot write the stats file");
  }
  const bool progress = !o.quiet && isatty(STDERR_FILENO);
  const int total = range.last - range.first + 1;
  const auto start = std::chrono::steady_clock::now();
  uint64_t raysSoFar = 0;
  for (int f = range.first; f <= range.last; ++f) {
    const auto t0 = std::chrono::steady_clock::now();
    const double time = f / o.fps;
    gpu.setTime(time);
    film.clear();
    FrameStats fs;
    fs.frame = f;
    integrator->renderFrame(f, gpu.camera(cam, time, width, height), &fs);
    Image img = film.read(&fs.badSamples);
    const std::string exr = formatOutPath(o.outPattern, f);
    writeExr(exr, img, o.exrFloat ? ExrPixels::Float : ExrPixels::Half);
    if (o.png) writePng(withExtension(exr, ".png"), img, o.exposure);
    fs.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    fs.deviceBytes = ctx.bytesInUse();
    uint64_t frameRays = 0;
    for (const auto& [k, v] : fs.rays) frameRays += v;
    raysSoFar += frameRays;
    if (stats) {
      nlohmann::ordered_json j;
      j["frame"] = f;
      j["mode"] = renderModeName(o.mode);
      j["wall_s"] = fs.wallSeconds;
      j["stages_s"] = fs.stageSeconds;
      j["rays"] = fs.rays;
      if (!fs.counters.empty()) j["counters"] = fs.counters;
      j["device_bytes"] = fs.deviceBytes;
      j["bad_samples"] = fs.badSamples;
      *stats << j.dump() << "\n" << std::flush;
    }
    if (fs.badSamples > 0 && !o.quiet)
      std::cerr << "warning: frame " << f << ": " << fs.badSamples
                << " non-finite samples were dropped\n";
    if (progress) {
      const int done = f - range.first + 1;
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double eta = elapsed / done * (total - done);
      std::fprintf(stderr, "\rframe %d of %d (#%d)  %.2f Mrays/s  elapsed %s  ETA %s   ", done, total, f,
                   elapsed > 0 ? raysSoFar / elapsed * 1e-6 : 0.0, clock(elapsed).c_str(),
                   clock(eta).c_str());
      std::fflush(stderr);
    }
  }
  if (progress) std::fprintf(stderr, "\n");
  if (!o.quiet)
    std::cerr << "rendered " << total << " frame(s) to " << formatOutPath(o.outPattern, range.first)
              << (total > 1 ? " ... " + formatOutPath(o.outPattern, range.last) : "") << "\n";
  return kExitOk;
}

}  // namespace pr
