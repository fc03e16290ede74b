#include "app/render_cli.h"

#include <algorithm>
#include <cstdint>
#include <memory>
#include <set>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/cli_checks.h"
#include "util/error.h"

namespace pr {
namespace {

// Where an option's value lands: a function from the arguments to the field.
using BoolField = bool& (*)(RenderArgs&);
using IntField = int& (*)(RenderArgs&);
using U32Field = uint32_t& (*)(RenderArgs&);
using FloatField = float& (*)(RenderArgs&);
using DoubleField = double& (*)(RenderArgs&);
using TextField = std::string& (*)(RenderArgs&);
using TextsField = std::vector<std::string>& (*)(RenderArgs&);
using TriField = std::optional<bool>& (*)(RenderArgs&);  // --x / --no-x where given, else unset
using Field = std::variant<BoolField, IntField, U32Field, FloatField, DoubleField, TextField,
                           TextsField, TriField>;

#define PR_FIELD(member) +[](RenderArgs& a) -> decltype(auto) { return (a.member); }

constexpr OptionAudience kEveryday = OptionAudience::Everyday;
constexpr OptionAudience kResearch = OptionAudience::Research;
constexpr OptionEffect kEstimator = OptionEffect::Estimator;
constexpr OptionEffect kRunOnly = OptionEffect::RunOnly;

// One option of `render`. Flags (bool, tri-state) take no value; the others take one, checked
// against `lo`..`hi` (numbers, where lo <= hi) or `choices` (texts).
struct Row {
  Row(const char* n, const char* g, OptionAudience a, OptionEffect e, Field f, const char* h)
      : names(n), group(g), audience(a), effect(e), field(f), help(h) {}

  const char* names;  // CLI11 names: "--spp", "-q,--quiet", "--eye-paths,!--no-eye-paths"
  const char* group;
  OptionAudience audience;
  OptionEffect effect;
  Field field;
  const char* help;
  double lo = 1.0, hi = 0.0;
  std::vector<std::string> choices;
  bool showDefault = false;  // --help and the tables show the field's initial value
  const char* env = nullptr;

  Row range(double l, double h) const {
    Row r = *this;
    r.lo = l;
    r.hi = h;
    return r;
  }
  Row oneOf(std::vector<std::string> c) const {
    Row r = *this;
    r.choices = std::move(c);
    return r;
  }
  Row withDefault() const {
    Row r = *this;
    r.showDefault = true;
    return r;
  }
  Row fromEnv(const char* name) const {
    Row r = *this;
    r.env = name;
    return r;
  }
};

const char* const kScene = "Scene and frames";
const char* const kOutput = "Output";
const char* const kLongRuns = "Long runs";
const char* const kSampling = "Sampling";
const char* const kSamplingResearch = "Sampling: research";
const char* const kResampling = "Path resampling";
const char* const kConnections = "Light paths and connections";
const char* const kMaterials = "Materials";
const char* const kEnvironment = "Environment";
const char* const kDevices = "Devices";

std::vector<Row> sceneAndOutputRows() {
  return {
      Row{"--allow-outside-uris", kScene, kEveryday, kEstimator, PR_FIELD(ro.allowOutsideUris),
          kOutsideUrisHelp},
      Row{"--animation", kScene, kEveryday, kEstimator, PR_FIELD(ro.animation),
          "The one animation that plays, by index or name (default: all of them; where two "
          "animate the same node, the first)"},
      Row{"--frames", kScene, kEveryday, kRunOnly, PR_FIELD(frames),
          "Frame range A-B or one frame A (default: the whole animation)"},
      Row{"--fps", kScene, kEveryday, kEstimator, PR_FIELD(ro.fps),
          "Frames per second: frame f is at time f / fps"}
          .range(0.001, 1000)
          .withDefault(),
      Row{"--shutter", kScene, kEveryday, kEstimator, PR_FIELD(ro.shutter),
          "Motion blur: the shutter stays open this many frames, centred on each frame's time "
          "(0: none; not with --connection-history)"}
          .range(0, 2)
          .withDefault(),
      Row{"--motion-tolerance", kScene, kEveryday, kEstimator, PR_FIELD(ro.motionTolerance),
          "With --shutter: how far, in pixels, the motion steps' blend of a moving object or "
          "skin may stray from its animation (larger: fewer steps, faster frames)"}
          .range(0.01, 100)
          .withDefault(),
      Row{"--camera", kScene, kEveryday, kEstimator, PR_FIELD(ro.camera),
          "Camera index (default: the scene's first)"}
          .range(0, 1 << 20),
      Row{"--width", kOutput, kEveryday, kEstimator, PR_FIELD(ro.width),
          "Image width (default: from the camera's aspect, else 640)"}
          .range(1, 16384),
      Row{"--height", kOutput, kEveryday, kEstimator, PR_FIELD(ro.height),
          "Image height (default 480)"}
          .range(1, 16384),
      Row{"--out", kOutput, kEveryday, kRunOnly, PR_FIELD(ro.outPattern),
          "Output EXR path with a frame number conversion"}
          .withDefault(),
      Row{"--exr-float", kOutput, kEveryday, kRunOnly, PR_FIELD(ro.exrFloat),
          "Write 32-bit float EXR (default: half)"},
      Row{"--png", kOutput, kEveryday, kRunOnly, PR_FIELD(ro.png),
          "Also write an sRGB PNG beside each EXR"},
      Row{"--video", kOutput, kEveryday, kRunOnly, PR_FIELD(ro.video),
          "Also encode the frames as one H.264 video (.mp4, .mov or .mkv) at --fps, through "
          "ffmpeg, from their PNGs (--video writes them)"},
      Row{"--time-limit", kSampling, kEveryday, kEstimator, PR_FIELD(ro.timeLimit),
          "Seconds per frame: no sample pass starts once they have run out (at least one; at "
          "most --spp); the stats line gives each frame's spp"}
          .range(0, 1e9),
      Row{"--noise-threshold", kSampling, kEveryday, kEstimator, PR_FIELD(ro.noiseThreshold),
          "Adaptive sampling: each pixel takes samples until its estimated relative error (from "
          "its neighbours' variance) is below this, at least --adaptive-min-spp and at most "
          "--spp (e.g. 0.02; default 0: off)"}
          .range(0, 1e9),
      Row{"--adaptive-min-spp", kSamplingResearch, kResearch, kEstimator,
          PR_FIELD(ro.adaptiveMinSpp),
          "Adaptive sampling's pilot: the samples every pixel takes before the noise is "
          "estimated (default: max(4, spp/16))"}
          .range(0, 1 << 20),
      Row{"--aov", kOutput, kEveryday, kRunOnly, PR_FIELD(ro.aov),
          "Auxiliary images as extra channels of each EXR, a comma-separated list of albedo, "
          "normal, depth, motion, object, material, samples, or all"},
      Row{"--denoise", kOutput, kEveryday, kRunOnly, PR_FIELD(ro.denoise),
          "Denoise each frame with Intel Open Image Denoise (installed by tools/setup/oidn.sh), "
          "guided by the albedo and normals; the noisy image stays in the EXR as noisy.R/G/B"},
      Row{"--exposure", kOutput, kEveryday, kRunOnly, PR_FIELD(ro.exposure),
          "Exposure in stops for the PNG"}
          .range(-64, 64)
          .withDefault(),
      Row{"--stats", kLongRuns, kEveryday, kRunOnly, PR_FIELD(ro.statsFile),
          "Write one JSON line per frame to this file"},
      Row{"--resume", kLongRuns, kEveryday, kRunOnly, PR_FIELD(ro.resume),
          "Skip frames whose complete EXR already exists (a truncated one is rendered again); "
          "append to the stats file"},
      Row{"--warm-up", kLongRuns, kEveryday, kRunOnly, PR_FIELD(ro.warmUp),
          "With path resampling: before a run's first frame f (or one after a gap), render "
          "frames f - N .. f - 1 without writing them, so that its paths have the history an "
          "uninterrupted run gives them (where the previous frame's history is not read with "
          "--resume); from frame 0 on, the very same frames"}
          .range(0, 1000)
          .withDefault(),
      Row{"-q,--quiet", kLongRuns, kEveryday, kRunOnly, PR_FIELD(ro.quiet),
          "No progress line or summary"},
  };
}

std::vector<Row> samplingRows() {
  return {
      Row{"--mode", kSampling, kEveryday, kEstimator, PR_FIELD(mode),
          "reuse: light paths kept across frames, re-traced only where moving objects disturb "
          "them; retrace: the same with every path re-traced each frame; pathtrace: "
          "unidirectional path tracing (the baseline)"}
          .oneOf({"reuse", "retrace", "pathtrace"})
          .withDefault(),
      Row{"--spp", kSampling, kEveryday, kEstimator, PR_FIELD(ro.spp),
          "Samples per pixel per frame"}
          .range(1, 1 << 20)
          .withDefault(),
      Row{"--max-depth", kSampling, kEveryday, kEstimator, PR_FIELD(ro.maxDepth),
          "Longest path, in surface vertices with the light's (direct light only: 2)"}
          .range(1, 64)
          .withDefault(),
      Row{"--seed", kSampling, kEveryday, kEstimator, PR_FIELD(ro.seed),
          "Random seed; the same seed reproduces a frame on one device"}
          .range(0, 4294967295.0)
          .withDefault(),
      Row{"--fixed-noise", kSamplingResearch, kResearch, kEstimator, PR_FIELD(ro.fixedNoise),
          "Key the camera samples' random numbers by frame 0 on every frame (the same noise "
          "pattern each frame; the scene still animates)"},
      Row{"--light-sampler", kSamplingResearch, kResearch, kEstimator, PR_FIELD(lightSampler),
          "How a shaded point chooses the light it samples: bvh (by the light it can get from "
          "each, through a light BVH), exhaustive (by the light it can get from each, every "
          "light weighed: for few lights), power (by power alone) or auto (bvh where the scene "
          "has more than 16 lights, exhaustive where it has at most 4, power between)"}
          .oneOf({"auto", "bvh", "exhaustive", "power"})
          .withDefault(),
      Row{"--env-light-choice", kSamplingResearch, kResearch, kEstimator, PR_FIELD(envLightChoice),
          "How light sampling weighs the environment against the other lights: auto (by the "
          "power above its darkest texel's: the uniform part, which BSDF sampling draws as well, "
          "leaves its samples to the other lights) or power (by its whole power)"}
          .oneOf({"auto", "power"})
          .withDefault(),
      Row{"--resample", kResampling, kResearch, kEstimator, PR_FIELD(resample),
          "Resample the paths beyond each first surface with those of neighbouring pixels and "
          "of the previous frame, reconnected there and weighed by pairwise MIS (unbiased; with "
          "--mode reuse/retrace the eye paths, weighted against the connections, which are "
          "added as without it). On by default in reuse/retrace, off in pathtrace"},
      Row{"--no-resample", kResampling, kResearch, kEstimator, PR_FIELD(noResample),
          "Reuse/retrace without path resampling (the estimator before it)"},
      Row{"--resample-neighbors", kResampling, kResearch, kEstimator,
          PR_FIELD(ro.resample.neighbors),
          "Pixels whose paths each pixel takes (--resample; 0: its own alone; default: 1 in "
          "pathtrace mode, 0 in reuse/retrace)"}
          .range(0, 16),
      Row{"--resample-radius", kResampling, kResearch, kEstimator, PR_FIELD(ro.resample.radius),
          "Radius in pixels within which the neighbours are drawn (--resample)"}
          .range(1, 256)
          .withDefault(),
      Row{"--resample-roughness", kResampling, kResearch, kEstimator,
          PR_FIELD(ro.resample.roughness),
          "GGX roughness below which a surface is too smooth to reconnect at (--resample)"}
          .range(0, 1)
          .withDefault(),
      Row{"--resample-distance", kResampling, kResearch, kEstimator, PR_FIELD(ro.resample.distance),
          "Shortest segment reconnected, in scene units (--resample; 0: 1% of the scene's "
          "radius)"}
          .range(0, 1e30)
          .withDefault(),
      Row{"--resample-history", kResampling, kResearch, kEstimator, PR_FIELD(ro.resample.history),
          "Confidence the previous frame's paths count at most, in samples (--resample; 0: no "
          "reuse between frames)"}
          .range(0, 1000)
          .withDefault(),
      Row{"--resample-mis-count", kResampling, kResearch, kEstimator,
          PR_FIELD(ro.resample.misCount),
          "Samples a resampled eye path counts as in its MIS weights against the connections to "
          "stored light paths, which count as --paths-per-pixel (--mode reuse/retrace with "
          "--resample)"}
          .range(0.01, 1e6)
          .withDefault(),
  };
}

std::vector<Row> connectionRows() {
  return {
      Row{"--light-paths", kConnections, kResearch, kEstimator, PR_FIELD(ro.connect.arenaSlots),
          "Light-path slots kept in the arena (reuse/retrace; default: one per pixel, at most "
          "2097152)"}
          .range(1, 1 << 26),
      Row{"--paths-per-pixel", kConnections, kResearch, kEstimator,
          PR_FIELD(ro.connect.pathsPerPixel),
          "Light paths each pixel sample connects to (reuse/retrace)"}
          .range(1, 64)
          .withDefault(),
      Row{"--clamp", kConnections, kResearch, kEstimator, PR_FIELD(ro.connect.clamp),
          "Upper bound on the connection geometry term (reuse/retrace; 0 = off, unbiased)"}
          .range(0, 1e30)
          .withDefault(),
      Row{"--connection-mis", kConnections, kResearch, kEstimator, PR_FIELD(ro.connect.mis),
          "Connection MIS threshold R (reuse/retrace): where the eye's BSDF sample finds a "
          "connected light vertex R or more times likelier than the light tracer did, the path "
          "is shared with a connection from that sample (fewer fireflies near corners; 0 = "
          "off). With --no-eye-paths only: eye paths weigh whole paths instead"}
          .range(0, 1e30)
          .withDefault(),
      Row{"--connections", kConnections, kResearch, kEstimator, PR_FIELD(connections),
          "Connections to the stored light vertices per eye vertex (reuse/retrace): 1 to 4 "
          "shadow rays, each to a candidate chosen in proportion to its unshadowed "
          "contribution, all (one shadow ray per candidate), or auto (all on CPUs, 2 on GPUs)"}
          .oneOf({"1", "2", "3", "4", "all", "auto"})
          .withDefault(),
      Row{"--connection-history", kConnections, kResearch, kEstimator,
          PR_FIELD(ro.connect.historyCap),
          "Carry each pixel sample's reservoir of connections at its first eye vertex from "
          "frame to frame (reuse/retrace; generalized RIS), standing for at most this many "
          "times C candidates; 0 = off"}
          .range(0, 1000)
          .withDefault(),
      Row{"--connection-history-period", kConnections, kResearch, kEstimator,
          PR_FIELD(ro.connect.historyPeriod),
          "With a connection history, the light paths each pixel sample connects to shift "
          "every this many frames: 1 gives the least error per frame, more keeps the noise "
          "steady for longer (less flicker)"}
          .range(1, 1000)
          .withDefault(),
      Row{"--eye-paths,!--no-eye-paths", kConnections, kResearch, kEstimator,
          PR_FIELD(ro.connect.eyePaths),
          "Reuse/retrace: trace whole eye paths as the path tracer does and weigh them against "
          "the connections to stored light paths over whole paths (MIS), so that connections "
          "count where they sample a path better, and eye paths elsewhere (dark corners, "
          "occluded rooms). On by default; --no-eye-paths: the connections alone at the first "
          "eye vertex, with next-event estimation, strategy E and the delta-chain extension "
          "there"},
      Row{"--light-tracing,!--no-light-tracing", kConnections, kResearch, kEstimator,
          PR_FIELD(ro.connect.lightTracing),
          "Reuse/retrace with eye paths: also join every stored light vertex to the camera "
          "(light tracing, strategy T), weighted against the eye paths and the connections over "
          "whole paths: the technique for caustics seen on diffuse surfaces. On by default "
          "there"},
  };
}

std::vector<Row> sceneLookRows() {
  return {
      Row{"--material-model", kMaterials, kResearch, kEstimator, PR_FIELD(materialModel),
          "The BSDF: energy (multiple-scattering GGX, layers by albedo scaling; as Blender's "
          "Cycles and OpenPBR) or gltf-reference (the glTF specification's single-scattering "
          "model, for conformance comparisons)"}
          .oneOf({"energy", "gltf-reference"})
          .withDefault(),
      Row{"--shadow-terminator", kMaterials, kResearch, kEstimator, PR_FIELD(terminator),
          "Coarse smooth-shaded facets: on (rays leave from the smooth surface the vertex "
          "normals describe, facets seen edge-on keep their light) or off (the flat facets' "
          "shadows, as renders before the correction)"}
          .oneOf({"on", "off"})
          .withDefault(),
      Row{"--force-diffuse", kMaterials, kResearch, kEstimator, PR_FIELD(ro.forceDiffuse),
          "Shade every non-delta material as pure Lambert with its base colour (a diagnostic)"},
      Row{"--env", kEnvironment, kEveryday, kEstimator, PR_FIELD(ro.env),
          "Environment light: an equirectangular map (.exr or .hdr; +Y up, its centre looking "
          "along -Z), or none (default: a uniform one of --env-color where that is given, else "
          "white where the scene has no lights, else none)"},
      Row{"--env-color", kEnvironment, kEveryday, kEstimator, PR_FIELD(ro.envColor),
          "R,G,B: a uniform environment of this radiance, or the map's tint"},
      Row{"--env-strength", kEnvironment, kEveryday, kEstimator, PR_FIELD(ro.envStrength),
          "Scales the environment's radiance"}
          .range(0, 1e30)
          .withDefault(),
      Row{"--env-rotate", kEnvironment, kEveryday, kEstimator, PR_FIELD(ro.envRotate),
          "Turns the environment about +Y by this many degrees (counter-clockwise seen from "
          "above)"}
          .range(-1e6, 1e6)
          .withDefault(),
      Row{"--emit-base-color", kEnvironment, kEveryday, kEstimator, PR_FIELD(ro.emitBaseColor),
          "Materials, by name or index (comma-separated; A-B a range of indices), that emit "
          "their base colour (factor and texture) as light: lights a sky dome or backdrop "
          "meant to be drawn unlit"},
      Row{"--emit-strength", kEnvironment, kEveryday, kEstimator, PR_FIELD(ro.emitStrength),
          "Scales what --emit-base-color's materials emit"}
          .range(0, 1e20)
          .withDefault(),
      Row{"--device", kDevices, kEveryday, kRunOnly, PR_FIELD(ro.devices),
          "OpenCL device: index, P:D, cpu, gpu or part of its name (default: $PATHREUSE_DEVICE, "
          "else the first GPU, else the first CPU); repeatable, each device renders a share of "
          "every frame's rows; 'all': every device"}
          .fromEnv("PATHREUSE_DEVICE"),
      Row{"--bvh-width", kDevices, kResearch, kEstimator, PR_FIELD(bvhWidth),
          "Children per BVH node: 8 (float8 slab tests, for CPUs), 4 (for GPUs), 2, or auto (8 "
          "on CPUs, 4 on GPUs)"}
          .oneOf({"auto", "2", "4", "8"})
          .withDefault(),
  };
}

#undef PR_FIELD

// The table, in the order the estimator key lists its options (a new option goes at the end of
// its group; moving one only makes earlier resume histories unusable, never wrong).
const std::vector<Row>& table() {
  static const std::vector<Row> rows = [] {
    std::vector<Row> all;
    for (auto part : {sceneAndOutputRows, samplingRows, connectionRows, sceneLookRows}) {
      std::vector<Row> p = part();
      all.insert(all.end(), p.begin(), p.end());
    }
    return all;
  }();
  return rows;
}

bool isFlag(const Row& r) {
  return std::holds_alternative<BoolField>(r.field) || std::holds_alternative<TriField>(r.field);
}

// The first long name: "--eye-paths,!--no-eye-paths" -> "--eye-paths", "-q,--quiet" -> "--quiet".
std::string longName(const char* names) {
  std::stringstream in(names);
  std::string part;
  while (std::getline(in, part, ','))
    if (part.rfind("--", 0) == 0) return part;
  return names;
}

// The numeric check of a row, typed as its field so that --help shows INT or UINT ranges.
CLI::Validator numberCheck(const Row& r) {
  if (std::holds_alternative<IntField>(r.field))
    return CLI::Range(static_cast<int>(r.lo), static_cast<int>(r.hi));
  if (std::holds_alternative<U32Field>(r.field))
    return CLI::Range(static_cast<uint32_t>(r.lo), static_cast<uint32_t>(r.hi));
  return finiteIn(r.lo, r.hi);
}

CLI::Option* addRow(CLI::App* render, const Row& r, RenderArgs& a) {
  CLI::Option* opt = std::visit(
      [&](auto field) -> CLI::Option* {
        auto& value = field(a);
        using T = std::decay_t<decltype(value)>;
        if constexpr (std::is_same_v<T, bool>) {
          return render->add_flag(r.names, value, r.help);
        } else if constexpr (std::is_same_v<T, std::optional<bool>>) {
          return render->add_flag_function(
              r.names, [&value](int64_t n) { value = n > 0; }, r.help);
        } else {
          return render->add_option(r.names, value, r.help);
        }
      },
      r.field);
  if (r.lo <= r.hi) opt->check(numberCheck(r));
  if (!r.choices.empty()) opt->check(CLI::IsMember(r.choices));
  if (r.showDefault) opt->capture_default_str();
  if (r.env) opt->envname(r.env);
  if (std::holds_alternative<TextsField>(r.field)) opt->allow_extra_args(false);
  return opt;
}

// A number as the range errors print it.
std::string numberText(double x) {
  std::ostringstream out;
  out << x;
  return out.str();
}

}  // namespace

void checkOptionRanges(const RenderOptions& o) {
  RenderArgs given, defaults;
  given.ro = o;
  for (const Row& r : table()) {
    if (!(r.lo <= r.hi)) continue;
    std::visit(
        [&](auto field) {
          using T = std::decay_t<decltype(field(given))>;
          if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
            const T value = field(given);
            if (value == field(defaults)) return;  // not given: the default (0 or -1: automatic)
            const double x = static_cast<double>(value);
            if (!(x >= r.lo && x <= r.hi))
              throw InputError(longName(r.names) + " " + numberText(x) + ": must be in [" +
                               numberText(r.lo) + ", " + numberText(r.hi) + "]");
          }
        },
        r.field);
  }
}

namespace {

// Each estimator option with what was given for it ("" where nothing, the default), after the
// scene: two runs with the same key render the same frames from the same inputs.
std::string estimatorKey(const CLI::App& render) {
  std::string key;
  auto append = [&key](const CLI::Option* opt) {
    key += opt->get_name();
    for (const std::string& v : opt->results()) key += " " + std::to_string(v.size()) + ":" + v;
    key += "\n";
  };
  append(render.get_option("SCENE"));
  for (const Row& r : table())
    if (r.effect == OptionEffect::Estimator) append(render.get_option(longName(r.names)));
  return key;
}

// "--a,!--no-a" as "`--a`, `--no-a`".
std::string markdownNames(const char* names) {
  std::stringstream in(names);
  std::string part, out;
  while (std::getline(in, part, ',')) {
    if (!part.empty() && part[0] == '!') part.erase(0, 1);
    out += (out.empty() ? "`" : ", `") + part + "`";
  }
  return out;
}

std::string markdownValues(const Row& r) {
  if (isFlag(r)) return "flag";
  if (!r.choices.empty()) {
    std::string s;
    for (const std::string& c : r.choices) s += (s.empty() ? "" : ", ") + c;
    return s;
  }
  if (r.lo <= r.hi) {
    if (std::holds_alternative<IntField>(r.field) || std::holds_alternative<U32Field>(r.field))
      return std::to_string(static_cast<int64_t>(r.lo)) + " to " +
             std::to_string(static_cast<int64_t>(r.hi));
    return CLI::detail::to_string(r.lo) + " to " + CLI::detail::to_string(r.hi);
  }
  return std::holds_alternative<TextsField>(r.field) ? "text, repeatable" : "text";
}

std::string markdownDefault(const Row& r) {
  if (!r.showDefault) return "";
  RenderArgs fresh;
  return std::visit(
      [&](auto field) -> std::string {
        const auto& value = field(fresh);
        using T = std::decay_t<decltype(value)>;
        if constexpr (std::is_same_v<T, std::string>) {
          return "`" + value + "`";
        } else if constexpr (std::is_arithmetic_v<T>) {
          return CLI::detail::to_string(value);
        } else {
          return "";
        }
      },
      r.field);
}

// Lists the research knobs only where asked: a hidden option (empty group) would lose its name
// in CLI11's error messages, so they keep their groups and help leaves them out.
class RenderHelpFormatter : public CLI::Formatter {
 public:
  explicit RenderHelpFormatter(bool listResearch) : listResearch_(listResearch) {
    for (const Row& r : table())
      if (r.audience == OptionAudience::Research) research_.insert(longName(r.names));
  }

  std::string make_group(std::string group, bool isPositional,
                         std::vector<const CLI::Option*> opts) const override {
    if (!listResearch_) {
      opts.erase(std::remove_if(
                     opts.begin(), opts.end(),
                     [this](const CLI::Option* o) { return research_.count(o->get_name()) > 0; }),
                 opts.end());
      if (opts.empty()) return "";
    }
    return CLI::Formatter::make_group(group, isPositional, opts);
  }

  // Groups left empty above leave their separators: at most two blank lines in a row.
  std::string make_help(const CLI::App* app, std::string name,
                        CLI::AppFormatMode mode) const override {
    std::string text = CLI::Formatter::make_help(app, std::move(name), mode);
    for (size_t at; (at = text.find("\n\n\n\n")) != std::string::npos;) text.erase(at, 1);
    return text;
  }

 private:
  bool listResearch_;
  std::set<std::string> research_;
};

}  // namespace

CLI::App* addRenderCommand(CLI::App& app, RenderArgs& a, bool listResearch) {
  auto* render = app.add_subcommand("render", "Render a range of frames of the scene's animation");
  render->add_option("SCENE", a.ro.scene, "glTF file (.gltf or .glb)")->required();
  for (const Row& r : table()) addRow(render, r, a)->group(r.group);
  render->formatter(std::make_shared<RenderHelpFormatter>(listResearch));
  render->footer("Research knobs (strategies' parameters, diagnostics): render --help-all");
  render->get_option("--resample")->excludes(render->get_option("--no-resample"));
  return render;
}

bool asksForHelpAll(int argc, const char* const* argv) {
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--help-all") return true;
  return false;
}

std::vector<OptionSummary> renderOptionSummaries() {
  std::vector<OptionSummary> out;
  for (const Row& r : table()) out.push_back({longName(r.names), r.audience, r.effect, isFlag(r)});
  return out;
}

std::string renderOptionsMarkdown(bool research) {
  auto line = [research](const Row& r) {
    std::string cells = "| " + markdownNames(r.names) + " | " + markdownValues(r) + " | " +
                        markdownDefault(r) + " | " + r.help + " |";
    if (research) cells += r.effect == OptionEffect::Estimator ? " yes |" : " no |";
    return cells + "\n";
  };
  const std::string head =
      research ? "| option | values | default | what it does | in the key |\n"
                 "|---|---|---|---|---|\n"
               : "| option | values | default | what it does |\n|---|---|---|---|\n";
  if (!research) {
    std::string md = head;
    for (const Row& r : table())
      if (r.audience == OptionAudience::Everyday) md += line(r);
    return md;
  }
  // By group, the groups in the order they first appear (as --help-all lists them).
  std::vector<std::string> groups;
  for (const Row& r : table())
    if (std::find(groups.begin(), groups.end(), r.group) == groups.end()) groups.push_back(r.group);
  std::string md;
  for (const std::string& g : groups) {
    md += (md.empty() ? "" : "\n") + std::string("## ") + g + "\n\n" + head;
    for (const Row& r : table())
      if (r.group == g) md += line(r);
  }
  return md;
}

RenderOptions toRenderOptions(const RenderArgs& a, const CLI::App& render) {
  RenderOptions ro = a.ro;
  ro.estimatorKey = estimatorKey(render);
  if (!ro.video.empty()) ro.png = true;  // the video is encoded from the PNGs
  if (!a.frames.empty()) {
    ro.frames = parseFrameRange(a.frames);
    ro.framesGiven = true;
  }
  ro.mode = a.mode == "pathtrace" ? RenderMode::PathTrace
            : a.mode == "retrace" ? RenderMode::Retrace
                                  : RenderMode::Reuse;
  ro.materialModel =
      a.materialModel == "gltf-reference" ? MaterialModel::Gltf : MaterialModel::Energy;
  ro.shadowTerminator = a.terminator == "on";
  ro.lightSampler = a.lightSampler == "bvh"          ? LightSampler::Bvh
                    : a.lightSampler == "exhaustive" ? LightSampler::Exhaustive
                    : a.lightSampler == "power"      ? LightSampler::Power
                                                     : LightSampler::Auto;
  ro.envChoiceByPower = a.envLightChoice == "power";
  ro.bvhWidth = a.bvhWidth == "auto" ? 0 : std::stoi(a.bvhWidth);
  if (a.resample || a.noResample) ro.resample.asked = a.resample;
  if (ro.connect.eyePaths && render.get_option("--connection-mis")->count() > 0 && !ro.quiet)
    std::cerr << "note: --connection-mis is used with --no-eye-paths only; eye paths weigh "
                 "whole paths by MIS instead\n";
  if (ro.connect.lightTracing.value_or(false) && ro.mode == RenderMode::PathTrace && !ro.quiet)
    std::cerr << "note: --light-tracing joins stored light paths to the camera in --mode reuse or "
                 "retrace; the path tracer has none\n";
  ro.connect.resample = a.connections == "auto"  ? -1
                        : a.connections == "all" ? 0
                                                 : std::stoi(a.connections);
  return ro;
}

}  // namespace pr
