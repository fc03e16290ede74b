// pathreuse: command-line entry. Parses arguments with CLI11, runs one subcommand, and turns
// every exception into one line on stderr and an exit code (docs/design.md section 1).
#include <algorithm>
#include <cmath>
#include <iterator>
#include <cstdio>
#include <exception>
#include <iostream>
#include <new>
#include <string>

#include <CLI/CLI.hpp>

#include "cl/device.h"
#include "portability/portability.h"
#include "render/options.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"
#include "scene/scene_info.h"
#include "util/error.h"

namespace {

int runDevices(bool json) {
  const auto devices = pr::enumerateDevices();
  if (devices.empty()) throw pr::NoDeviceError();
  if (json) {
    std::cout << pr::devicesJson(devices) << "\n";
  } else {
    for (const auto& d : devices) std::cout << pr::describeDevice(d) << "\n";
  }
  return pr::kExitOk;
}

int runInfo(const std::string& path, bool json, double fps, bool allowOutsideUris) {
  if (!(fps > 0.0) || fps > 1000.0) throw pr::InputError("--fps: must be in (0, 1000]");
  pr::LoadOptions options;
  options.allowOutsideUris = allowOutsideUris;
  options.printWarnings = json;  // the text summary lists them itself
  const pr::Scene scene = pr::loadScene(path, options);
  if (json)
    std::cout << pr::sceneInfoJson(scene, fps).dump(2) << "\n";
  else
    std::cout << pr::sceneInfoText(scene, fps);
  return pr::kExitOk;
}

// Numbers a user types: finite (CLI::Range lets NaN through), within bounds that --help shows.
CLI::Validator finiteIn(double lo, double hi) {
  const std::string range =
      "[" + CLI::detail::to_string(lo) + " - " + CLI::detail::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v) || !std::isfinite(v) || v < lo || v > hi)
          return "Value " + text + " not in range " + range;
        return "";
      },
      "in " + range);
}

const char* const kOutsideHelp =
    "Let the scene's buffer and image URIs name files outside its folder (by default a scene "
    "reads files in its own folder and below only)";

// Options declared after this are listed under `group` in the subcommand's --help. A heading
// only: unlike add_option_group, parsing and error messages stay as they are.
void listUnder(CLI::App* command, const char* group) {
  command->option_defaults()->group(group);
}

// --- devices and info ---

struct InfoArgs {
  std::string scene;
  bool json = false;
  double fps = 24.0;
  bool allowOutsideUris = false;
};

CLI::App* addDevicesCommand(CLI::App& app, bool& json) {
  auto* devices = app.add_subcommand("devices", "List every OpenCL platform and device");
  devices->add_flag("--json", json, "Print the list as JSON");
  return devices;
}

CLI::App* addInfoCommand(CLI::App& app, InfoArgs& a) {
  auto* info =
      app.add_subcommand("info", "What a scene holds: static/dynamic split, lights, animation");
  info->add_option("SCENE", a.scene, "glTF file (.gltf or .glb)")->required();
  info->add_flag("--json", a.json, "Print as JSON");
  info->add_option("--fps", a.fps, "Frames per second of the animation (default 24)")
      ->check(finiteIn(0.001, 1000));
  info->add_flag("--allow-outside-uris", a.allowOutsideUris, kOutsideHelp);
  return info;
}

// --- render ---

// The render options as typed; toRenderOptions turns the texts into RenderOptions' enums.
struct RenderArgs {
  pr::RenderOptions ro;
  std::string frames;
  std::string mode = "reuse", lightSampler = "auto", materialModel = "energy";
  std::string terminator = "on", bvhWidth = "auto", connections = "auto";
  CLI::Option* connectionMis = nullptr;  // to tell whether it was given
  bool resample = false, noResample = false;
};

void addSceneOptions(CLI::App* render, RenderArgs& a) {
  listUnder(render, "Scene and frames");
  render->add_flag("--allow-outside-uris", a.ro.allowOutsideUris, kOutsideHelp);
  render->add_option("--animation", a.ro.animation,
                     "The one animation that plays, by index or name (default: all of them; "
                     "where two animate the same node, the first)");
  render->add_option("--frames", a.frames,
                     "Frame range A-B or one frame A (default: the whole animation)");
  render->add_option("--fps", a.ro.fps, "Frames per second: frame f is at time f / fps")
      ->check(finiteIn(0.001, 1000))
      ->capture_default_str();
  render->add_option("--camera", a.ro.camera, "Camera index (default: the scene's first)")
      ->check(CLI::Range(0, 1 << 20));
}

void addOutputOptions(CLI::App* render, RenderArgs& a) {
  pr::RenderOptions& ro = a.ro;
  listUnder(render, "Output");
  render
      ->add_option("--width", ro.width, "Image width (default: from the camera's aspect, else 640)")
      ->check(CLI::Range(1, 16384));
  render->add_option("--height", ro.height, "Image height (default 480)")
      ->check(CLI::Range(1, 16384));
  render->add_option("--out", ro.outPattern, "Output EXR path with a frame number conversion")
      ->capture_default_str();
  render->add_flag("--exr-float", ro.exrFloat, "Write 32-bit float EXR (default: half)");
  render->add_flag("--png", ro.png, "Also write an sRGB PNG beside each EXR");
  render->add_option("--video", ro.video,
                     "Also encode the frames as one H.264 video (.mp4, .mov or .mkv) at --fps, "
                     "through ffmpeg, from their PNGs (--video writes them)");
  render
      ->add_option("--time-limit", ro.timeLimit,
                   "Seconds per frame: no sample pass starts once they have run out (at least "
                   "one; at most --spp); the stats line gives each frame's spp")
      ->check(finiteIn(0, 1e9));
  render
      ->add_option("--noise-threshold", ro.noiseThreshold,
                   "Adaptive sampling: each pixel takes samples until its estimated relative "
                   "error (from its neighbours' variance) is below this, at least "
                   "--adaptive-min-spp and at most --spp (e.g. 0.02; default 0: off)")
      ->check(finiteIn(0, 1e9));
  render
      ->add_option("--adaptive-min-spp", ro.adaptiveMinSpp,
                   "Adaptive sampling's pilot: the samples every pixel takes before the noise "
                   "is estimated (default: max(4, spp/16))")
      ->check(CLI::Range(0, 1 << 20));
  render->add_option("--aov", ro.aov,
                     "Auxiliary images as extra channels of each EXR, a comma-separated list of "
                     "albedo, normal, depth, motion, object, material, or all");
  render->add_flag("--denoise", ro.denoise,
                   "Denoise each frame with Intel Open Image Denoise (installed by "
                   "tools/setup/oidn.sh), guided by the albedo and normals; the noisy image "
                   "stays in the EXR as noisy.R/G/B");
  render->add_option("--exposure", ro.exposure, "Exposure in stops for the PNG")
      ->check(finiteIn(-64, 64))
      ->capture_default_str();
  render->add_option("--stats", ro.statsFile, "Write one JSON line per frame to this file");
  render->add_flag(
      "--resume", ro.resume,
      "Skip frames whose complete EXR already exists (a truncated one is rendered again); "
      "append to the stats file");
  render
      ->add_option("--warm-up", ro.warmUp,
                   "With path resampling: before a run's first frame f (or one after a gap), "
                   "render frames f - N .. f - 1 without writing them, so that its paths have "
                   "the history an uninterrupted run gives them (where the previous frame's "
                   "history is not read with --resume); from frame 0 on, the very same frames")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  render->add_flag("-q,--quiet", ro.quiet, "No progress line or summary");
}

void addSamplingOptions(CLI::App* render, RenderArgs& a) {
  pr::RenderOptions& ro = a.ro;
  listUnder(render, "Sampling");
  render
      ->add_option("--mode", a.mode,
                   "reuse: light paths kept across frames, re-traced only where moving objects "
                   "disturb them; retrace: the same with every path re-traced each frame; "
                   "pathtrace: unidirectional path tracing (the baseline)")
      ->check(CLI::IsMember({"reuse", "retrace", "pathtrace"}))
      ->capture_default_str();
  render->add_option("--spp", ro.spp, "Samples per pixel per frame")
      ->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  render
      ->add_option("--max-depth", ro.maxDepth,
                   "Longest path, in surface vertices with the light's (direct light only: 2)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  render
      ->add_option("--seed", ro.seed, "Random seed; the same seed reproduces a frame on one device")
      ->check(CLI::Range(0u, 4294967295u))
      ->capture_default_str();
  render->add_flag("--fixed-noise", ro.fixedNoise,
                   "Key the camera samples' random numbers by frame 0 on every frame (the same "
                   "noise pattern each frame; the scene still animates)");
  render
      ->add_option("--light-sampler", a.lightSampler,
                   "How a shaded point chooses the light it samples: bvh (by the light it can "
                   "get from each, through a light BVH), exhaustive (by the light it can get "
                   "from each, every light weighed: for few lights), power (by power alone) or "
                   "auto (bvh where the scene has more than 16 lights, exhaustive where it has "
                   "at most 4, power between)")
      ->check(CLI::IsMember({"auto", "bvh", "exhaustive", "power"}))
      ->capture_default_str();
  auto* on = render->add_flag(
      "--resample", a.resample,
      "Resample the paths beyond each first surface with those of neighbouring pixels and of the "
      "previous frame, reconnected there and weighed by pairwise MIS (unbiased; with --mode "
      "reuse/retrace the eye paths, weighted against the connections, which are added as "
      "without it). On by default in reuse/retrace, off in pathtrace");
  auto* off = render->add_flag("--no-resample", a.noResample,
                               "Reuse/retrace without path resampling (the estimator before it)");
  on->excludes(off);
  render
      ->add_option("--resample-neighbors", ro.resample.neighbors,
                   "Pixels whose paths each pixel takes (--resample; 0: its own alone; default: "
                   "1 in pathtrace mode, 0 in reuse/retrace)")
      ->check(CLI::Range(0, 16));
  render
      ->add_option("--resample-radius", ro.resample.radius,
                   "Radius in pixels within which the neighbours are drawn (--resample)")
      ->check(finiteIn(1, 256))
      ->capture_default_str();
  render
      ->add_option("--resample-roughness", ro.resample.roughness,
                   "GGX roughness below which a surface is too smooth to reconnect at (--resample)")
      ->check(finiteIn(0, 1))
      ->capture_default_str();
  render
      ->add_option("--resample-distance", ro.resample.distance,
                   "Shortest segment reconnected, in scene units (--resample; 0: 1% of the "
                   "scene's radius)")
      ->check(finiteIn(0, 1e30))
      ->capture_default_str();
  render
      ->add_option("--resample-history", ro.resample.history,
                   "Confidence the previous frame's paths count at most, in samples (--resample; "
                   "0: no reuse between frames)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  render
      ->add_option("--resample-mis-count", ro.resample.misCount,
                   "Samples a resampled eye path counts as in its MIS weights against the "
                   "connections to stored light paths, which count as --paths-per-pixel "
                   "(--mode reuse/retrace with --resample)")
      ->check(finiteIn(0.01, 1e6))
      ->capture_default_str();
}

// Connections between eye and stored light paths: the reuse and retrace modes only.
void addReuseOptions(CLI::App* render, RenderArgs& a) {
  pr::RenderOptions& ro = a.ro;
  listUnder(render, "Reuse and retrace");
  render
      ->add_option(
          "--light-paths", ro.lightPaths,
          "Light-path slots kept in the arena (reuse/retrace; default: one per pixel, at most "
          "2097152)")
      ->check(CLI::Range(1, 1 << 26));
  render
      ->add_option("--paths-per-pixel", ro.pathsPerPixel,
                   "Light paths each pixel sample connects to (reuse/retrace)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  render
      ->add_option("--clamp", ro.clamp,
                   "Upper bound on the connection geometry term (reuse/retrace; 0 = off, unbiased)")
      ->check(finiteIn(0, 1e30))
      ->capture_default_str();
  a.connectionMis =
      render
          ->add_option(
              "--connection-mis", ro.connectionMis,
              "Connection MIS threshold R (reuse/retrace): where the eye's BSDF sample finds a "
              "connected light vertex R or more times likelier than the light tracer did, the "
              "path is shared with a connection from that sample (fewer fireflies near "
              "corners; 0 = off). With --no-eye-paths only: eye paths weigh whole paths instead")
          ->check(finiteIn(0, 1e30))
          ->capture_default_str();
  render
      ->add_option("--connections", a.connections,
                   "Connections to the stored light vertices per eye vertex (reuse/retrace): "
                   "1 to 4 shadow rays, each to a candidate chosen in proportion to its "
                   "unshadowed contribution, all (one shadow ray per candidate), or auto (all "
                   "on CPUs, 2 on GPUs)")
      ->check(CLI::IsMember({"1", "2", "3", "4", "all", "auto"}))
      ->capture_default_str();
  render
      ->add_option("--connection-history", ro.connectionHistory,
                   "Carry each pixel sample's reservoir of connections at its first eye vertex "
                   "from frame to frame (reuse/retrace; generalized RIS), standing for at most "
                   "this many times C candidates; 0 = off")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  render
      ->add_option("--connection-history-period", ro.connectionHistoryPeriod,
                   "With a connection history, the light paths each pixel sample connects to "
                   "shift every this many frames: 1 gives the least error per frame, more keeps "
                   "the noise steady for longer (less flicker)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  render->add_flag(
      "--eye-paths,!--no-eye-paths", ro.eyePaths,
      "Reuse/retrace: trace whole eye paths as the path tracer does and weigh them against the "
      "connections to stored light paths over whole paths (MIS), so that connections count "
      "where they sample a path better, and eye paths elsewhere (dark corners, occluded rooms). "
      "On by default; --no-eye-paths: the connections alone at the first eye vertex, with "
      "next-event estimation, strategy E and the delta-chain extension there");
  render->add_flag_function(
      "--light-tracing,!--no-light-tracing", [&ro](int64_t n) { ro.lightTracing = n > 0; },
      "Reuse/retrace with eye paths: also join every stored light vertex to the camera (light "
      "tracing, strategy T), weighted against the eye paths and the connections over whole "
      "paths: the technique for caustics seen on diffuse surfaces. On by default there");
}

void addMaterialOptions(CLI::App* render, RenderArgs& a) {
  listUnder(render, "Materials");
  render
      ->add_option("--material-model", a.materialModel,
                   "The BSDF: energy (multiple-scattering GGX, layers by albedo scaling; as "
                   "Blender's Cycles and OpenPBR) or gltf-reference (the glTF specification's "
                   "single-scattering model, for conformance comparisons)")
      ->check(CLI::IsMember({"energy", "gltf-reference"}))
      ->capture_default_str();
  render
      ->add_option("--shadow-terminator", a.terminator,
                   "Coarse smooth-shaded facets: on (rays leave from the smooth surface the "
                   "vertex normals describe, facets seen edge-on keep their light) or off (the "
                   "flat facets' shadows, as renders before the correction)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  render->add_flag(
      "--force-diffuse", a.ro.forceDiffuse,
      "Shade every non-delta material as pure Lambert with its base colour (a diagnostic)");
}

void addEnvironmentOptions(CLI::App* render, RenderArgs& a) {
  pr::RenderOptions& ro = a.ro;
  listUnder(render, "Environment");
  render->add_option(
      "--env", ro.env,
      "Environment light: an equirectangular map (.exr or .hdr; +Y up, its centre looking along "
      "-Z), or none (default: a uniform one of --env-color where that is given, else white "
      "where the scene has no lights, else none)");
  render->add_option("--env-color", ro.envColor,
                     "R,G,B: a uniform environment of this radiance, or the map's tint");
  render->add_option("--env-strength", ro.envStrength, "Scales the environment's radiance")
      ->check(finiteIn(0, 1e30))
      ->capture_default_str();
  render
      ->add_option("--env-rotate", ro.envRotate,
                   "Turns the environment about +Y by this many degrees (counter-clockwise seen "
                   "from above)")
      ->check(finiteIn(-1e6, 1e6))
      ->capture_default_str();
}

void addRenderDeviceOptions(CLI::App* render, RenderArgs& a) {
  listUnder(render, "Devices");
  render
      ->add_option("--device", a.ro.devices,
                   "OpenCL device: index, P:D, cpu, gpu or part of its name (default: "
                   "$PATHREUSE_DEVICE, else the first GPU, else the first CPU); repeatable, "
                   "each device renders a share of every frame's rows; 'all': every device")
      ->allow_extra_args(false)
      ->envname("PATHREUSE_DEVICE");
  render
      ->add_option("--bvh-width", a.bvhWidth,
                   "Children per BVH node: 8 (float8 slab tests, for CPUs), 4 (for GPUs), 2, or "
                   "auto (8 on CPUs, 4 on GPUs)")
      ->check(CLI::IsMember({"auto", "2", "4", "8"}))
      ->capture_default_str();
}

CLI::App* addRenderCommand(CLI::App& app, RenderArgs& a) {
  auto* render = app.add_subcommand("render", "Render a range of frames of the scene's animation");
  render->add_option("SCENE", a.ro.scene, "glTF file (.gltf or .glb)")->required();
  addSceneOptions(render, a);
  addOutputOptions(render, a);
  addSamplingOptions(render, a);
  addReuseOptions(render, a);
  addMaterialOptions(render, a);
  addEnvironmentOptions(render, a);
  addRenderDeviceOptions(render, a);
  return render;
}

// The render options that cannot change a frame's pixels: where its files go and what else is
// written, which frames, how the run reports, and the devices (named in the history's key by
// what they are). Every other option, present or added later, is part of the estimator's key.
const char* const kRunOnlyOptions[] = {
    "--out",    "--exr-float", "--png",   "--exposure", "--aov",    "--denoise", "--stats",
    "--resume", "--warm-up",   "--quiet", "--frames",   "--device", "--help",    "--video"};

// Each option of `render` but the run-only ones, with what was given for it ("" where nothing,
// the default): two runs with the same key render the same frames from the same inputs.
std::string estimatorKey(const CLI::App& render) {
  std::string key;
  for (const CLI::Option* opt : render.get_options()) {
    const std::string name = opt->get_name();
    if (std::find(std::begin(kRunOnlyOptions), std::end(kRunOnlyOptions), name) !=
        std::end(kRunOnlyOptions))
      continue;
    key += name;
    for (const std::string& r : opt->results()) key += " " + std::to_string(r.size()) + ":" + r;
    key += "\n";
  }
  return key;
}

pr::RenderOptions toRenderOptions(const RenderArgs& a, const CLI::App& render) {
  pr::RenderOptions ro = a.ro;
  ro.estimatorKey = estimatorKey(render);
  if (!ro.video.empty()) ro.png = true;  // the video is encoded from the PNGs
  if (!a.frames.empty()) {
    ro.frames = pr::parseFrameRange(a.frames);
    ro.framesGiven = true;
  }
  ro.mode = a.mode == "pathtrace" ? pr::RenderMode::PathTrace
            : a.mode == "retrace" ? pr::RenderMode::Retrace
                                  : pr::RenderMode::Reuse;
  ro.materialModel =
      a.materialModel == "gltf-reference" ? pr::MaterialModel::Gltf : pr::MaterialModel::Energy;
  ro.shadowTerminator = a.terminator == "on";
  ro.lightSampler = a.lightSampler == "bvh"          ? pr::LightSampler::Bvh
                    : a.lightSampler == "exhaustive" ? pr::LightSampler::Exhaustive
                    : a.lightSampler == "power"      ? pr::LightSampler::Power
                                                     : pr::LightSampler::Auto;
  ro.bvhWidth = a.bvhWidth == "auto" ? 0 : std::stoi(a.bvhWidth);
  if (a.resample || a.noResample) ro.resample.asked = a.resample;
  if (ro.eyePaths && a.connectionMis->count() > 0 && !ro.quiet)
    std::cerr << "note: --connection-mis is used with --no-eye-paths only; eye paths weigh "
                 "whole paths by MIS instead\n";
  if (ro.lightTracing.value_or(false) && ro.mode == pr::RenderMode::PathTrace && !ro.quiet)
    std::cerr << "note: --light-tracing joins stored light paths to the camera in --mode reuse or "
                 "retrace; the path tracer has none\n";
  ro.connections = a.connections == "auto"  ? -1
                   : a.connections == "all" ? 0
                                            : std::stoi(a.connections);
  return ro;
}

// --- portability ---

struct PortabilityArgs {
  pr::PortabilityOptions po;
  bool noDemo = false;
};

const char* const kPortabilityFooter =
    "Renders a fixed suite on every OpenCL device and compares each device's frames with the\n"
    "first's. Round-off may send paths another way on another device, so the check is\n"
    "statistical: the first device renders the suite again with seeds seed+1 and seed+2, and\n"
    "these independent estimates give each frame's noise floor. A device whose paths diverge\n"
    "is at worst another seed; a fault adds a systematic error. Leaving out the 1% most\n"
    "extreme pixels (fireflies), a device disagrees when its relMSE > TOLERANCE x the floor's,\n"
    "when its mean luminance is more than SIGMAS standard errors off, or on any NaN/Inf.\n"
    "Exit 0: all agree (or only one device: nothing to compare); 1: a device disagrees;\n"
    "2: bad input.";

// What is rendered: scenes, frames, size, samples and modes.
void addSuiteOptions(CLI::App* portability, PortabilityArgs& a) {
  pr::PortabilityOptions& po = a.po;
  listUnder(portability, "Suite");
  portability->add_flag("--no-demo", a.noDemo, "Test only the given scenes, not the demo scenes");
  portability->add_flag("--allow-outside-uris", po.allowOutsideUris, kOutsideHelp);
  portability->add_option("--frames", po.frames, "Frames: A, A-B or a list (A,B-C)")
      ->capture_default_str();
  portability->add_option("--width", po.width, "Image width")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  portability->add_option("--height", po.height, "Image height (default: from the camera's aspect)")
      ->check(CLI::Range(1, 16384));
  portability->add_option("--spp", po.spp, "Samples per pixel per frame")
      ->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  portability->add_option("--seed", po.seed, "Random seed (the noise floor uses seed+1 and seed+2)")
      ->check(CLI::Range(0u, 4294967293u))
      ->capture_default_str();
  portability
      ->add_option("--mode", po.modes,
                   "reuse, retrace or pathtrace; repeatable (default: all three)")
      ->check(CLI::IsMember({"reuse", "retrace", "pathtrace"}));
}

// Which devices, what they are compared with, and how closely.
void addComparisonOptions(CLI::App* portability, PortabilityArgs& a) {
  pr::PortabilityOptions& po = a.po;
  listUnder(portability, "Devices and comparison");
  portability->add_option(
      "--device", po.devices,
      "Device (index, P:D, cpu, gpu or part of its name); repeatable, the first is the "
      "reference (default: every device found)");
  portability
      ->add_option("--tolerance", po.tolerance.relMseFactor,
                   "A device disagrees when its relMSE exceeds this multiple of the noise floor")
      ->check(finiteIn(0.001, 1e6))
      ->capture_default_str();
  portability
      ->add_option("--sigmas", po.tolerance.lumSigmas,
                   "... or when its mean luminance is this many standard errors off")
      ->check(finiteIn(0.001, 1e6))
      ->capture_default_str();
  portability->add_option("--save-reference", po.saveReferenceDir,
                          "Also write the reference device's frames (and noise-floor seeds) to "
                          "this folder, to compare a device on another machine with");
  portability->add_option("--reference", po.referenceDir,
                          "Compare every device with the frames saved in this folder by "
                          "--save-reference, instead of with the first device");
}

void addReportOptions(CLI::App* portability, PortabilityArgs& a) {
  pr::PortabilityOptions& po = a.po;
  listUnder(portability, "Output");
  portability->add_flag("--json", po.json, "Print one JSON document instead of the table");
  portability->add_option("--out", po.outDir, "Folder for the PNG of the worst difference")
      ->capture_default_str();
  portability->add_flag("-q,--quiet", po.quiet, "No progress lines on stderr");
}

CLI::App* addPortabilityCommand(CLI::App& app, PortabilityArgs& a) {
  auto* portability = app.add_subcommand(
      "portability", "Render a fixed suite on every OpenCL device and compare the images");
  portability->footer(kPortabilityFooter);
  portability->add_option("SCENES", a.po.scenes, "glTF files tested besides the demo scenes");
  addSuiteOptions(portability, a);
  addComparisonOptions(portability, a);
  addReportOptions(portability, a);
  return portability;
}

// --- running ---

// Runs `command`, turning its exceptions into one line on stderr and an exit code.
template <typename Command>
int runReportingErrors(Command command) {
  try {
    return command();
  } catch (const pr::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return pr::kExitBadInput;
  } catch (const pr::RuntimeError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return pr::kExitRuntime;
  } catch (const std::bad_alloc&) {
    std::cerr << "error: out of host memory\n";
    return pr::kExitRuntime;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return pr::kExitRuntime;
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pathreuse: global illumination of animated glTF scenes by reusing light paths"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "pathreuse 0.1.0");
  bool devicesJson = false;
  InfoArgs infoArgs;
  RenderArgs renderArgs;
  PortabilityArgs portabilityArgs;
  const CLI::App* devices = addDevicesCommand(app, devicesJson);
  const CLI::App* info = addInfoCommand(app, infoArgs);
  const CLI::App* render = addRenderCommand(app, renderArgs);
  const CLI::App* portability = addPortabilityCommand(app, portabilityArgs);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "error: " << e.what() << " (see pathreuse --help)\n";
    return pr::kExitBadInput;
  }

  return runReportingErrors([&]() -> int {
    if (*devices) return runDevices(devicesJson);
    if (*info)
      return runInfo(infoArgs.scene, infoArgs.json, infoArgs.fps, infoArgs.allowOutsideUris);
    if (*render) return pr::runRender(toRenderOptions(renderArgs, *render));
    if (*portability) {
      portabilityArgs.po.demoScenes = !portabilityArgs.noDemo;
      return pr::runPortability(portabilityArgs.po);
    }
    return pr::kExitOk;
  });
}
