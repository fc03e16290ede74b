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
#include "render/session.h"
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

}  // namespace

int runRender(const RenderOptions& o) {
  validateRenderOptions(o);
  const Scene scene = loadScene(o.scene);
  if (scene.emissiveTriangleCount() == 0 && scene.lights.empty() && !o.quiet)
    std::cerr << "warning: " << o.scene << ": no lights; frames will be black\n";
  const auto devices = enumerateDevices();
  const DeviceEntry& device = selectDevice(devices, o.device);
  RenderSession session(scene, device, o);
  const FrameRange range = session.frameRange();
  if (!o.quiet) {
    std::cerr << "rendering " << o.scene << " frames " << range.first << "-" << range.last << " at "
              << session.width() << "x" << session.height() << ", " << o.spp << " spp, mode "
              << renderModeName(o.mode) << ", on " << device.name;
    if (auto* reuse = dynamic_cast<PathReuse*>(&session.integrator()))
      std::cerr << "; arena " << reuse->slots() << " slots x " << reuse->stride() << " vertices = "
                << (reuse->arenaBytes() >> 20) << " MiB";
    std::cerr << "\n";
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
    FrameStats fs;
    const Image img = session.renderFrame(f, &fs);
    const std::string exr = formatOutPath(o.outPattern, f);
    writeExr(exr, img, o.exrFloat ? ExrPixels::Float : ExrPixels::Half);
    if (o.png) writePng(withExtension(exr, ".png"), img, o.exposure);
    fs.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
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
