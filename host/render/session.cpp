#include "render/session.h"

#include "render/aov.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "render/path_reuse.h"
#include "render/path_tracer.h"
#include "util/error.h"

namespace pr {

namespace {

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

int checkedCamera(const Scene& scene, const RenderOptions& o) {
  const int count = static_cast<int>(scene.cameras.size());
  const int cam = o.camera < 0 ? 0 : o.camera;
  if (cam >= count)
    throw InputError("--camera " + std::to_string(o.camera) + ": " + o.scene + " has " +
                     std::to_string(count) + " camera(s)");
  if (!scene.cameras[cam].perspective)
    throw InputError(o.scene + ": camera " + std::to_string(cam) +
                     " is orthographic; only perspective cameras are supported");
  return cam;
}

}  // namespace

Environment resolveEnvironment(const RenderOptions& o, const Scene& scene) {
  if (o.env == "none") return Environment{};
  float color[3] = {1.0f, 1.0f, 1.0f};
  if (!o.envColor.empty()) parseColor(o.envColor, color);
  Environment env;
  if (!o.env.empty())
    env = loadEnvironment(o.env);
  else if (!o.envColor.empty() || sceneHasNoLights(scene))
    env = constantEnvironment(glm::vec3(1.0f));
  else
    return env;
  env.scale = glm::vec3(color[0], color[1], color[2]) * o.envStrength;
  env.rotation = o.envRotate * float(M_PI / 180.0);
  return env;
}

bool sceneHasNoLights(const Scene& scene) {
  return scene.emissiveTriangleCount() == 0 && scene.lights.empty();
}

void validateRenderOptions(const RenderOptions& o) {
  validateOutPattern(o.outPattern);
  if (o.png && withExtension(o.outPattern, ".png") == o.outPattern)
    throw InputError("--out " + o.outPattern +
                     ": with --png the EXR and its PNG would be one file (name the EXR .exr)");
  if (o.mode != RenderMode::PathTrace && o.maxDepth < 2)
    throw InputError("--max-depth " + std::to_string(o.maxDepth) + ": path reuse needs at least 2");
  if (!o.aov.empty()) parseAovs(o.aov);
  if (o.timeLimit > 0.0 && o.connect.historyCap > 0)
    throw InputError(
        "--time-limit: cannot be combined with --connection-history, whose "
        "reservoirs follow every pass of every frame");
  if (o.noiseThreshold > 0.0f) {
    if (o.spp < 2) throw InputError("--noise-threshold: needs --spp of at least 2");
    if (o.adaptiveMinSpp != 0 && (o.adaptiveMinSpp < 2 || o.adaptiveMinSpp > o.spp))
      throw InputError("--adaptive-min-spp " + std::to_string(o.adaptiveMinSpp) +
                       ": must be 2 to --spp (" + std::to_string(o.spp) + ")");
    if (o.connect.historyCap > 0)
      throw InputError(
          "--noise-threshold: cannot be combined with --connection-history, whose "
          "reservoirs follow every pass of every pixel");
  }
  // Path reuse over the shutter joins still light paths to the eye paths' samples (design.md
  // section 3, "Motion blur"); the connection history's reservoirs are not built for times.
  if (o.shutter > 0.0 && o.mode != RenderMode::PathTrace && !o.connect.eyePaths)
    throw InputError(
        "--shutter: path reuse over the shutter weighs its connections against the eye paths, "
        "which --no-eye-paths turns off");
  if (o.shutter > 0.0 && o.connect.historyCap > 0)
    throw InputError("--shutter: cannot be combined with --connection-history yet");
  if (!o.envColor.empty()) {
    float rgb[3];
    parseColor(o.envColor, rgb);
    if (o.env == "none") throw InputError("--env-color: contradicts --env none");
  }
}

RenderSession::RenderSession(const Scene& scene, const DeviceEntry& device,
                             const RenderOptions& options)
    : scene_(scene), options_(options), ctx_(device) {
  ctx_.setBuildNotice(!options.quiet);
  if (scene.staticTriangleCount() + scene.dynamicTriangleCount() == 0)
    throw InputError(options.scene + ": nothing to render (no triangles)");
  camera_ = checkedCamera(scene, options);
  frameCount_ = static_cast<int>(scene.frameCount(options.fps));
  chooseSize(options, scene.cameraAt(camera_, 0.0), &width_, &height_);
  GpuSceneOptions sceneOptions;
  sceneOptions.forceDiffuse = options.forceDiffuse;
  sceneOptions.materialModel = options.materialModel;
  sceneOptions.shadowTerminator = options.shadowTerminator;
  sceneOptions.lightSampler = options.lightSampler;
  sceneOptions.envChoiceByPower = options.envChoiceByPower;
  sceneOptions.bvhWidth = options.bvhWidth;
  sceneOptions.environment = resolveEnvironment(options, scene);
  gpu_ = std::make_unique<GpuScene>(ctx_, scene, sceneOptions);
  film_ = std::make_unique<Film>(ctx_, width_, height_);
  const RenderOptions& o = options_;
  ResampleSettings resample = resolveResample(o);
  if (resample.enabled && o.mode != RenderMode::PathTrace && !o.connect.eyePaths)
    throw InputError("--resample: resamples the eye paths, which --no-eye-paths turns off");
  if (o.connect.lightTracing.value_or(false) && o.mode != RenderMode::PathTrace &&
      !o.connect.eyePaths)
    throw InputError(
        "--light-tracing: weighs its paths against the eye paths, which --no-eye-paths "
        "turns off");
  if (o.shutter > 0.0)
    gpu_->setShutter(o.shutter / o.fps, camera_, width_, height_,
                     o.mode != RenderMode::PathTrace || resample.enabled, o.motionTolerance);
  if (!(resample.distance > 0.0f)) resample.distance = 0.01f * gpu_->sceneRadius();
  if (o.mode == RenderMode::PathTrace) {
    PathTracerSettings p;
    p.spp = o.spp;
    p.maxDepth = o.maxDepth;
    p.seed = o.seed;
    p.fixedNoise = o.fixedNoise;
    p.resample = resample;
    p.wavefrontPixels = o.wavefrontPixels;
    integrator_ = std::make_unique<PathTracer>(ctx_, *gpu_, *film_, p);
  } else {
    PathReuseSettings r;
    r.spp = o.spp;
    r.maxDepth = o.maxDepth;
    r.seed = o.seed;
    r.connect = o.connect;
    if (r.connect.resample < 0)
      r.connect.resample = defaultConnections((ctx_.device().type & CL_DEVICE_TYPE_GPU) != 0);
    r.connect.lightTracing = resolveLightTracing(o);
    r.retraceAll = o.mode == RenderMode::Retrace;
    r.fixedNoise = o.fixedNoise;
    r.resamplePaths = resample;
    r.wavefrontPixels = o.wavefrontPixels;
    integrator_ = std::make_unique<PathReuse>(ctx_, *gpu_, *film_, r);
  }
  integrator_->setTimeLimit(o.timeLimit);
  if (o.noiseThreshold > 0.0f) {
    AdaptiveSettings a;
    a.threshold = o.noiseThreshold;
    a.spp = o.spp;
    a.pilot = o.adaptiveMinSpp ? o.adaptiveMinSpp : std::min(o.spp, std::max(4, o.spp / 16));
    film_->setAdaptive(a);
  }
  const uint32_t aovs = o.aov.empty() ? 0u : parseAovs(o.aov);
  samplesAov_ = (aovs & kAovSamples) != 0;
  if ((aovs & ~kAovSamples) || o.denoise) {
    AovSampling a;
    a.seed = o.seed;
    a.jitterFromFrame0 = resample.enabled || o.fixedNoise;
    a.spp = o.spp;
    a.maxDepth = o.maxDepth;
    aov_ = std::make_unique<AovRenderer>(ctx_, scene, *gpu_, aovs & ~kAovSamples, a, o.denoise);
  }
}

RenderSession::~RenderSession() = default;

std::pair<double, double> RenderSession::renderAovs(int64_t frame, Image* image) {
  return aov_->render(frame, options_.fps, camera_, image);
}

std::string RenderSession::environmentDigest() const {
  return gpu_->environmentDigest();
}

bool RenderSession::hasHistory() const {
  const FrameHistory* h = integrator_->history();
  return h && h->hasHistory();
}

std::string RenderSession::writeHistory(const std::string& key) {
  return integrator_->history()->writeHistory(key);
}

bool RenderSession::checkHistory(const std::string& data, const std::string& key, int64_t frame) {
  FrameHistory* h = integrator_->history();
  if (!h) return false;
  // What moved between that frame and the next is measured from that frame's scene, whose light
  // table the records are checked against.
  gpu_->setTime(frame / options_.fps);
  return h->checkHistory(data, key, frame);
}

void RenderSession::applyHistory(const std::string& data) {
  integrator_->history()->applyHistory(data);
}

int RenderSession::chains() const {
  const FrameHistory* h = integrator_->history();
  return h ? h->chains() : 0;
}

std::string RenderSession::chain(int pass) {
  return integrator_->history()->chain(pass);
}

void RenderSession::setChain(int pass, const std::string& records) {
  integrator_->history()->setChain(pass, records);
}

FrameRange RenderSession::frameRange() const {
  FrameRange range = options_.frames;
  if (!options_.framesGiven) range = {0, frameCount_ - 1};
  if (range.last < 0) range.last = frameCount_ - 1;
  return range;
}

Image RenderSession::renderFrame(int64_t frame, FrameStats* stats) {
  Image img(width_, height_);
  renderRows(frame, &img, stats);
  return img;
}

void RenderSession::renderRows(int64_t frame, Image* image, FrameStats* stats) {
  FrameStats local;
  FrameStats* fs = stats ? stats : &local;
  render(frame, fs);
  takeCounts(film_->readRows(image, &fs->badSamples), fs);
  fs->deviceBytes = ctx_.bytesInUse();
  fs->deviceBuffers = ctx_.bytesByName();
}

std::vector<float> RenderSession::renderSums(int64_t frame, FrameStats* stats) {
  FrameStats local;
  FrameStats* fs = stats ? stats : &local;
  render(frame, fs);
  std::vector<float> sums = film_->readSums(&fs->badSamples);
  takeCounts(sums, fs);
  fs->deviceBytes = ctx_.bytesInUse();
  fs->deviceBuffers = ctx_.bytesByName();
  return sums;
}

void RenderSession::takeCounts(const std::vector<float>& sums, FrameStats* fs) {
  const size_t n = sums.size() / 4;
  if (samplesAov_) {
    counts_.assign(size_t(width_) * height_, 0.0f);
    for (size_t k = 0; k < n; ++k) counts_[film_->first() + k] = sums[k * 4 + 3];
  }
  if (!film_->adaptive() || n == 0) return;
  double total = 0.0;
  float most = 0.0f;
  for (size_t k = 0; k < n; ++k) {
    total += sums[k * 4 + 3];
    most = std::max(most, sums[k * 4 + 3]);
  }
  fs->sppMean = total / double(n);
  fs->sppMax = int(most);
}

void RenderSession::render(int64_t frame, FrameStats* fs) {
  const double time = frame / options_.fps;
  const auto t0 = std::chrono::steady_clock::now();
  gpu_->setTime(time);
  fs->hostSeconds["scene"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  fs->hostSeconds["deform"] = gpu_->lastDeformSeconds();
  fs->motionSteps = gpu_->motionSteps();
  film_->clear();
  fs->frame = frame;
  for (const auto& [k, v] : ctx_.takeBuildSeconds()) fs->buildSeconds[k] += v;
  integrator_->renderFrame(frame, gpu_->camera(camera_, time, width_, height_), fs);
}

}  // namespace pr
