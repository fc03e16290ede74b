// Options of `pathreuse render`, their defaults and their validation.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace pr {

enum class RenderMode { Reuse, Retrace, PathTrace };

// How a shaded point chooses the light it samples: through the light BVH, by weighing every
// light from the point (exhaustive), by power alone, or (auto) the light BVH where the scene
// has more lights than kAutoLightBvhMin, exhaustive where it has at most kAutoExhaustiveMax and
// power between (measured: docs/experiments/exhaustive-light-sampler.md).
enum class LightSampler { Auto, Bvh, Exhaustive, Power };
constexpr int kAutoLightBvhMin = 16;
constexpr int kAutoExhaustiveMax = 4;
// The least share of the environment's power by which light sampling chooses it where its
// uniform floor is all of it (GpuScene::envChoiceShare_; docs/experiments/env-light-choice.md).
constexpr float kEnvChoiceFloor = 1.0f / 32.0f;

// Children per BVH node for a device (0: auto): CPUs 8 (float8 slab tests), GPUs 4. Measured in
// docs/ray-benchmark.md (CPU) and docs/experiments/bvh-width.md (an H200).
int defaultBvhWidth(bool gpu);
// Resampled connections per eye vertex where --connections is auto; 0: every candidate.
int defaultConnections(bool gpu);

const char* renderModeName(RenderMode m);

// The BSDF model (kernels/shared/bsdf.h): energy-conserving (multiple-scattering GGX, layers by
// albedo scaling; the default) or the glTF specification's single-scattering one.
enum class MaterialModel { Energy, Gltf };
const char* materialModelName(MaterialModel m);

// Path resampling across pixels and frames (--resample; docs/design.md section 5): the path
// tracer's paths beyond x_1, and its direct light at x_1, resampled with those of `neighbors`
// pixels within `radius` pixels and with the previous frame's.
struct ResampleSettings {
  // --resample / --no-resample as given; unset: resolveResample's default for the mode.
  std::optional<bool> asked;
  bool enabled = false;  // resolved: what the integrator does
  // -1: the mode's default. With --mode pathtrace 1: with the previous frame's paths it reached a
  // given error sooner than 3 on both animations measured. With reuse/retrace 0: the connections
  // already share the light paths between pixels, and a neighbour cost more time than it saved
  // on all three animations of bench_temporal.
  int neighbors = -1;
  float radius = 10.0f;    // pixels
  float roughness = 0.2f;  // GGX roughness below which a vertex is not reconnected
  float distance = 0.0f;   // shortest reconnected segment; 0: 1% of the scene's radius
  // Temporal reuse: the confidence the previous frame's reservoir counts at most (ReSTIR's M
  // cap); 0: none, each frame alone.
  int history = 20;
  // --mode reuse: the samples a resampled eye path counts as in its MIS weights against the
  // connections to stored light paths (which count as C, --paths-per-pixel). 4: the least error
  // on both animations of bench_temporal among 1, 4, 16 and 64 (experiments/path-resampling.md).
  float misCount = 4.0f;
};

// Path reuse's connections to the stored light paths (--mode reuse/retrace; docs/design.md
// section 5), as the options give them; the session resolves `resample` and `lightTracing` for
// the device and the mode before PathReuse takes them.
struct ConnectionSettings {
  int arenaSlots = 0;     // --light-paths: N_L; 0: one per pixel, at most 2^21 (defaultLightPaths)
  int pathsPerPixel = 4;  // --paths-per-pixel: C, light paths each pixel sample connects to
  float clamp = 0.0f;     // --clamp on the geometry term; 0 = off
  float mis = 4.0f;       // --connection-mis: threshold on p_E / p_L (reuse/connect.cl); 0 = off
  // --connections: RIS-chosen connections per eye vertex (1-4); 0: every candidate; -1:
  // defaultConnections of the device.
  int resample = -1;
  int historyCap = 0;  // --connection-history: a pixel sample's carried reservoir, per C; 0 = off
  int historyPeriod = 1;  // frames between moves of the history's light-path offset (>= 1)
  bool eyePaths = true;   // full eye paths, weighted against the connections over whole paths
  // Strategy T: the stored light paths' vertices joined to the camera (light tracing), weighted
  // against the eye paths and the connections (kernels/shared/eye_paths.h). Needs eye paths.
  // --light-tracing / --no-light-tracing where given (resolveLightTracing).
  std::optional<bool> lightTracing;
};

// The largest frame number: one more still fits, as does the count of frames from 0 to it.
constexpr int64_t kMaxFrame = INT64_MAX - 1;

struct FrameRange {
  int64_t first = 0;
  int64_t last = -1;  // -1: up to the end of the animation
};

// The default band of a pass's paths (render/path_tracer.h): 720p in one band, 4K in eight.
constexpr uint32_t kWavefrontPixels = uint32_t(1) << 20;

// --motion-tolerance's default, in pixels: 2 let the city's fast camera at 2 fps move 16x16
// blocks by 2% (docs/experiments/motion-blur.md).
constexpr double kDefaultMotionTolerance = 0.5;

struct RenderOptions {
  std::string scene;
  bool allowOutsideUris = false;  // LoadOptions::allowOutsideUris
  std::string animation;          // LoadOptions::animation: "" = every animation
  std::string emitBaseColor;      // LoadOptions::emitBaseColor: "" = none
  float emitStrength = 1.0f;      // LoadOptions::emitStrength
  FrameRange frames;
  bool framesGiven = false;
  double fps = 24.0;
  // --shutter: frames the shutter stays open, centred on each frame's time (motion blur,
  // kernels/shared/motion.h); 0 = none.
  double shutter = 0.0;
  // --motion-tolerance: how far, in pixels, a blend of two motion steps may stray from the
  // animation midway between them (GpuScene::motionTimes).
  double motionTolerance = kDefaultMotionTolerance;
  int width = 0;  // 0: the camera's aspect with height, else 640x480
  int height = 0;
  int spp = 4;
  double timeLimit =
      0.0;  // --time-limit: seconds of sampling per frame (render/integrator.h); 0 = none
  // --noise-threshold: each pixel's target relative error (render/film.h); 0 = every pixel spp.
  float noiseThreshold = 0.0f;
  int adaptiveMinSpp = 0;  // --adaptive-min-spp: the pilot's passes; 0 = max(4, spp / 16)
  int maxDepth = 8;
  uint32_t seed = 1;
  // --device SPECs, repeatable; "all" for every device; none: the default device.
  std::vector<std::string> devices;
  RenderMode mode = RenderMode::Reuse;
  int camera = -1;  // -1: the scene's first camera
  std::string outPattern = "out/frame_%04d.exr";
  bool exrFloat = false;
  bool png = false;
  std::string video;     // --video: the frames' PNGs encoded by ffmpeg (io/video.h); "" = none
  std::string aov;       // --aov: auxiliary images as extra EXR channels (render/aov.h); "" = none
  bool denoise = false;  // --denoise: Open Image Denoise (render/denoise.h)
  float exposure = 0.0f;
  bool quiet = false;
  bool forceDiffuse = false;
  MaterialModel materialModel = MaterialModel::Energy;
  bool shadowTerminator = true;  // the terminator offset (kernels/shared/transport.h)
  LightSampler lightSampler = LightSampler::Auto;
  bool envChoiceByPower = false;  // --env-light-choice power (GpuSceneOptions)
  int bvhWidth = 0;               // 0: defaultBvhWidth of the device
  std::string statsFile;
  bool resume = false;  // skip frames whose complete EXR exists; append to the stats file
  // With path resampling: frames rendered, not written, before a frame whose previous frame the
  // run neither rendered nor read the history of (host/render/renderer.cpp).
  int warmUp = 0;
  // Camera samples keyed by frame 0 on every frame (the scene still moves with the frame):
  // the same noise pattern each frame, to measure how much flicker fresh noise adds.
  bool fixedNoise = false;
  ConnectionSettings connect;  // path reuse's (--mode reuse/retrace)
  ResampleSettings resample;
  // The pixels whose paths a pass traces at once (PathTracerSettings::wavefrontPixels). Not a
  // command-line option: frames are the same floats whatever it is; the tests make it small.
  uint32_t wavefrontPixels = kWavefrontPixels;
  // The environment light (scene/environment_map.h): a map file, "none", or "" (a uniform one of
  // envColor where --env-color is given, else white where the scene has no lights, else none).
  std::string env;
  std::string envColor;  // "R,G,B"; "" = white
  float envStrength = 1.0f;
  float envRotate = 0.0f;  // degrees about +Y
  // Every option that can change a frame's pixels, as given (the command line's, less those
  // that cannot: host/main.cpp). The resume history is used only by a run of the same.
  std::string estimatorKey;
};

// o.resample with `enabled` and `neighbors` resolved: --resample / --no-resample where given; else
// on in --mode reuse/retrace with eye paths (it reached each animation's error at least as
// soon, with a third or less of the flicker: docs/experiments/path-resampling.md) and off in
// pathtrace mode, which stays the plain path tracer, and with --no-eye-paths, which it needs.
ResampleSettings resolveResample(const RenderOptions& o);

// Strategy T: --light-tracing / --no-light-tracing where given; else on in --mode reuse/retrace
// with eye paths (it lowered the Cornell boxes' error per sample by 4-19%, the atrium's neither
// way, for splats of 2-3 ms in frames of 0.15-0.3 s: docs/experiments/light-tracing.md) and off in
// pathtrace mode.
bool resolveLightTracing(const RenderOptions& o);

// "R,G,B": three finite non-negative numbers. Throws InputError naming --env-color.
void parseColor(const std::string& text, float rgb[3]);

// "A-B" or "A" (non-negative, A <= B). Throws InputError naming --frames.
FrameRange parseFrameRange(const std::string& text);

// Checks that `pattern` holds exactly one integer conversion (%d, %04d, %5i ...) and no other
// conversion than "%%". Throws InputError naming --out.
void validateOutPattern(const std::string& pattern);

// The pattern with the frame number substituted.
std::string formatOutPath(const std::string& pattern, int64_t frame);

// `path` with its extension replaced (".exr" -> ".png"), or the extension appended.
std::string withExtension(const std::string& path, const std::string& ext);

}  // namespace pr
