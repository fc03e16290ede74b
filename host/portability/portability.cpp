#include "portability/portability.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cl/device.h"
#include "io/image.h"
#include "render/options.h"
#include "render/session.h"
#include "scene/gltf_loader.h"
#include "util/error.h"
#include "util/files.h"
#include "util/input_file.h"

namespace pr {

namespace fs = std::filesystem;

namespace {

const char* const kDemoScenes[] = {"cornell-dynamic.gltf", "cornell-orbit.gltf"};

// Renders with seeds seed+1 ... seed+kFloorSeeds measure the noise floor (compare.h).
constexpr uint32_t kFloorSeeds = 2;

struct SuiteScene {
  std::string path;
  std::string label;  // file stem, made unique
  std::unique_ptr<Scene> scene;
};

// One device's frames of one (scene, mode) at one seed.
struct FrameSet {
  std::vector<Image> images;
  std::vector<uint64_t> dropped;  // non-finite samples the film dropped, per frame
};

struct Row {
  size_t scene = 0;
  RenderMode mode = RenderMode::Reuse;
  int64_t frame = 0;
  size_t device = 0;  // position in the compared devices (0 is the reference)
  ImageDiff diff;
  NoiseFloor floor;
  Verdict verdict;
  uint64_t dropped = 0, refDropped = 0;
};

RenderMode parseMode(const std::string& s) {
  if (s == "reuse") return RenderMode::Reuse;
  if (s == "retrace") return RenderMode::Retrace;
  if (s == "pathtrace") return RenderMode::PathTrace;
  throw InputError("--mode " + s + ": must be reuse, retrace or pathtrace");
}

std::string executableDir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.parent_path().string();
}

// File-name-safe form of a label.
std::string safeName(const std::string& s) {
  std::string out;
  for (char c : s)
    out += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.') ? c : '_';
  return out;
}

void validate(const PortabilityOptions& o) {
  if (o.width < 1 || o.width > 4096)
    throw InputError("--width " + std::to_string(o.width) + ": must be 1 to 4096");
  if (o.height < 0 || o.height > 4096)
    throw InputError("--height " + std::to_string(o.height) +
                     ": must be 1 to 4096 (0: from the camera)");
  if (o.spp < 1 || o.spp > 4096)
    throw InputError("--spp " + std::to_string(o.spp) + ": must be 1 to 4096");
  if (!(o.tolerance.relMseFactor >= 1.0) || !std::isfinite(o.tolerance.relMseFactor))
    throw InputError("--tolerance: must be at least 1 (a multiple of the noise floor)");
  if (!(o.tolerance.lumSigmas > 0.0) || !std::isfinite(o.tolerance.lumSigmas))
    throw InputError("--sigmas: must be positive");
  if (o.outDir.empty()) throw InputError("--out: must name a folder");
  if (!o.demoScenes && o.scenes.empty()) throw InputError("--no-demo: no scene given to test");
  if (!o.saveReferenceDir.empty() && !o.referenceDir.empty())
    throw InputError("--save-reference and --reference: give one of them");
}

FrameSet renderSet(const SuiteScene& s, const DeviceEntry& device, const RenderOptions& ro,
                   const std::vector<int64_t>& frames, bool quiet) {
  if (!quiet)
    std::cerr << "portability: " << s.label << " " << renderModeName(ro.mode) << " seed " << ro.seed
              << " on [" << device.index << "] " << device.name << "\n";
  RenderSession session(*s.scene, device, ro);
  FrameSet set;
  for (int64_t f : frames) {  // increasing, so reuse carries paths from frame to frame
    FrameStats stats;
    set.images.push_back(session.renderFrame(f, &stats));
    set.dropped.push_back(stats.badSamples);
  }
  return set;
}

// A saved reference: frames as float EXRs named by scene, mode, seed and frame, and
// reference.json with the suite's settings (checked on load) and each frame's dropped samples.
const char* const kManifest = "reference.json";
constexpr uint64_t kMaxManifestBytes = 64 << 20;

std::string referenceFile(const std::string& label, RenderMode mode, uint32_t seed, int64_t frame) {
  return safeName(label) + "_" + renderModeName(mode) + "_s" + std::to_string(seed) + "_f" +
         std::to_string(frame) + ".exr";
}

nlohmann::json suiteSettings(const std::vector<int64_t>& frames, int width, int height, int spp,
                             uint32_t seed) {
  return {{"frames", frames}, {"width", width}, {"height", height},
          {"spp", spp},       {"seed", seed},   {"noise_floor_seeds", kFloorSeeds}};
}

class StoredReference {
 public:
  explicit StoredReference(const std::string& dir) : dir_(dir) {
    const fs::path manifest = fs::path(dir) / kManifest;
    std::string text;
    try {
      text = readInputFileText(manifest.string(), kMaxManifestBytes);
    } catch (const InputError& e) {
      throw InputError(std::string(e.what()) + " (make one with --save-reference)");
    }
    try {
      json_ = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
      throw InputError(manifest.string() + ": not a reference manifest (" + e.what() + ")");
    }
    bool ok = json_.is_object() && json_.contains("settings") && json_["settings"].is_object() &&
              json_.contains("device") && json_["device"].is_object() &&
              json_.contains("frames_dropped") && json_["frames_dropped"].is_object();
    if (ok)
      for (const auto& v : json_["frames_dropped"]) ok = ok && v.is_number_unsigned();
    if (!ok) throw InputError(manifest.string() + ": not a reference manifest");
  }
  std::string device() const {
    const auto& d = json_["device"];
    return d.contains("name") && d["name"].is_string() ? d["name"].get<std::string>() : "?";
  }
  // The suite asked for must be the one saved.
  void check(const nlohmann::json& settings) const {
    if (json_["settings"] != settings)
      throw InputError((fs::path(dir_) / kManifest).string() + ": saved with " +
                       json_["settings"].dump() + ", not " + settings.dump() +
                       " (use the same --frames, --width, --height, --spp and --seed)");
  }
  // Every frame of one scene is the size of the first loaded (and --width wide): a frame of
  // another size is a damaged reference, named.
  FrameSet load(const std::string& label, RenderMode mode, uint32_t seed,
                const std::vector<int64_t>& frames) {
    FrameSet set;
    for (int64_t f : frames) {
      const std::string name = referenceFile(label, mode, seed, f);
      const fs::path path = fs::path(dir_) / name;
      if (!fs::is_regular_file(path) || !json_["frames_dropped"].contains(name))
        throw InputError(path.string() +
                         ": missing from the saved reference (saved with other "
                         "scenes or modes?)");
      set.images.push_back(readExr(path.string()));
      const Image& img = set.images.back();
      const std::string key = label + "/" + renderModeName(mode);
      if (!sizes_.count(key)) sizes_[key] = {img.width, img.height};
      const auto [w, h] = sizes_[key];
      const nlohmann::json& st = json_["settings"];
      const bool widthOk = !st.contains("width") || !st["width"].is_number_integer() ||
                           st["width"].get<int>() == img.width;
      if (img.width != w || img.height != h || !widthOk)
        throw InputError(path.string() + ": a frame of " + std::to_string(img.width) + "x" +
                         std::to_string(img.height) + " in a reference of " + std::to_string(w) +
                         "x" + std::to_string(h) + " frames (damaged or mixed reference)");
      set.dropped.push_back(json_["frames_dropped"][name].get<uint64_t>());
    }
    return set;
  }

 private:
  std::string dir_;
  nlohmann::json json_;
  std::map<std::string, std::pair<int, int>> sizes_;  // per scene and mode
};

// How far past its tolerance a comparison is (above 1: it disagrees); ranks the worst.
double badness(const Row& r, const Tolerance& tol) {
  if (r.diff.nonFinite > 0) return std::numeric_limits<double>::infinity();
  return std::max(r.verdict.relMseRatio / tol.relMseFactor, r.verdict.lumZ / tol.lumSigmas);
}

std::string fixed(double v, int prec) {
  if (std::isinf(v)) return "inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", prec, v);
  return buf;
}

std::string sci(double v) {
  if (std::isinf(v)) return "inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3e", v);
  return buf;
}

// JSON has no infinity; a zero floor with a non-zero difference is reported as null.
nlohmann::json number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

}  // namespace

std::vector<int64_t> parseFrameList(const std::string& text) {
  std::vector<int64_t> frames;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, ',')) {
    const FrameRange r = parseFrameRange(part);
    if (r.last - r.first > 1000) throw InputError("--frames " + text + ": at most 1000 frames");
    for (int64_t f = r.first; f <= r.last; ++f) frames.push_back(f);
  }
  if (frames.empty() || text.back() == ',')
    throw InputError("--frames " + text + ": expected A, A-B or a list A,B-C");
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  if (frames.size() > 1000) throw InputError("--frames " + text + ": at most 1000 frames");
  return frames;
}

std::vector<std::string> demoScenePaths() {
  std::vector<fs::path> dirs;
  const std::string exeDir = executableDir();
  if (!exeDir.empty()) dirs.push_back(fs::path(exeDir) / ".." / "scenes");
  dirs.push_back(fs::path(PATHREUSE_SOURCE_DIR) / "scenes");
  for (const auto& dir : dirs) {
    std::vector<std::string> paths;
    for (const char* name : kDemoScenes)
      if (fs::is_regular_file(dir / name))
        paths.push_back((dir / name).lexically_normal().string());
    if (paths.size() == std::size(kDemoScenes)) return paths;
  }
  std::string tried;
  for (const auto& dir : dirs)
    tried += (tried.empty() ? "" : ", ") + dir.lexically_normal().string();
  throw InputError("demo scenes cornell-dynamic.gltf and cornell-orbit.gltf not found (looked in " +
                   tried + "); pass scenes with --no-demo");
}

namespace {

// What the suite is, fixed before its first render.
struct Suite {
  explicit Suite(const PortabilityOptions& options) : o(options) {}
  const PortabilityOptions& o;
  std::vector<int64_t> frames;
  std::vector<RenderMode> modes;
  std::vector<SuiteScene> scenes;
  // --reference: the saved frames every device is compared with.
  std::unique_ptr<StoredReference> stored;
  bool save = false;        // --save-reference
  nlohmann::json settings;  // suiteSettings: saved with a reference, checked against one
  // The first renders the reference unless `stored`.
  std::vector<const DeviceEntry*> devices;
  RenderOptions base;
  // Against saved frames every device is compared; else every device but the first.
  size_t firstCompared = 1;
  bool compare = false;
};

// What the suite found.
struct Results {
  std::vector<Row> rows;
  // The comparison furthest past its tolerance gets its difference written.
  double worstBadness = -1.0;
  size_t worstIndex = 0;
  Image worstImage;
  double worstScale = 1.0;
  int width = 0, height = 0;  // of the reference frames
  // --save-reference: the manifest's dropped samples per saved frame.
  nlohmann::json savedDropped = nlohmann::json::object();
};

std::vector<RenderMode> suiteModes(const std::vector<std::string>& names) {
  std::vector<RenderMode> modes;
  for (const auto& m : names) {
    const RenderMode mode = parseMode(m);
    if (std::find(modes.begin(), modes.end(), mode) == modes.end()) modes.push_back(mode);
  }
  if (modes.empty()) modes = {RenderMode::Reuse, RenderMode::Retrace, RenderMode::PathTrace};
  return modes;
}

std::vector<SuiteScene> loadSuiteScenes(const PortabilityOptions& o) {
  std::vector<std::string> paths;
  if (o.demoScenes) paths = demoScenePaths();
  paths.insert(paths.end(), o.scenes.begin(), o.scenes.end());
  std::vector<SuiteScene> scenes;
  for (const auto& p : paths) {
    SuiteScene s;
    s.path = p;
    s.label = fs::path(p).stem().string();
    for (const auto& other : scenes)
      if (other.label == s.label) s.label += "#" + std::to_string(scenes.size());
    LoadOptions lo;
    lo.printWarnings = !o.quiet;
    lo.allowOutsideUris = o.allowOutsideUris;
    s.scene = std::make_unique<Scene>(loadScene(p, lo));
    scenes.push_back(std::move(s));
  }
  return scenes;
}

RenderOptions suiteRenderOptions(const PortabilityOptions& o) {
  RenderOptions base;
  base.width = o.width;
  base.height = o.height;
  base.spp = o.spp;
  base.seed = o.seed;
  base.quiet = true;
  // One estimator on every device (auto would resample connections on GPUs only): the suite
  // compares implementations, not per-device defaults.
  base.connect.resample = 0;
  validateRenderOptions(base);
  return base;
}

// The reference frames of one scene and mode at `seed`: the saved ones, else rendered on the
// first device (and written out with --save-reference).
FrameSet referenceFrames(const Suite& suite, const SuiteScene& s, const RenderOptions& ro,
                         uint32_t seed, Results& res) {
  if (suite.stored) return suite.stored->load(s.label, ro.mode, seed, suite.frames);
  RenderOptions r = ro;
  r.seed = seed;
  FrameSet set = renderSet(s, *suite.devices[0], r, suite.frames, suite.o.quiet);
  for (size_t fi = 0; suite.save && fi < suite.frames.size(); ++fi) {
    const std::string name = referenceFile(s.label, ro.mode, seed, suite.frames[fi]);
    writeExr((fs::path(suite.o.saveReferenceDir) / name).string(), set.images[fi],
             ExrPixels::Float);
    res.savedDropped[name] = set.dropped[fi];
  }
  return set;
}

// Renders one scene and mode on device `di` and compares every frame with the reference's.
void compareDevice(const Suite& suite, size_t si, const RenderOptions& ro, size_t di,
                   const FrameSet& ref, const std::vector<NoiseFloor>& floors, Results& res) {
  const FrameSet dev =
      renderSet(suite.scenes[si], *suite.devices[di], ro, suite.frames, suite.o.quiet);
  for (size_t fi = 0; fi < suite.frames.size(); ++fi) {
    if (dev.images[fi].width != res.width || dev.images[fi].height != res.height)
      throw InputError("the reference frames are " + std::to_string(res.width) + "x" +
                       std::to_string(res.height) + ", the device's " +
                       std::to_string(dev.images[fi].width) + "x" +
                       std::to_string(dev.images[fi].height));
    Row r;
    r.scene = si;
    r.mode = ro.mode;
    r.frame = suite.frames[fi];
    r.device = di;
    r.diff = compareImages(dev.images[fi], ref.images[fi]);
    r.floor = floors[fi];
    r.dropped = dev.dropped[fi];
    r.refDropped = ref.dropped[fi];
    r.verdict = judge(r.diff, r.floor, suite.o.tolerance, r.dropped, r.refDropped);
    const double b = badness(r, suite.o.tolerance);
    if (b > res.worstBadness) {
      res.worstBadness = b;
      res.worstIndex = res.rows.size();
      res.worstImage = differenceImage(dev.images[fi], ref.images[fi], &res.worstScale);
    }
    res.rows.push_back(r);
  }
}

void runSceneMode(const Suite& suite, size_t si, RenderMode mode, Results& res) {
  const SuiteScene& s = suite.scenes[si];
  RenderOptions ro = suite.base;
  ro.scene = s.path;
  ro.mode = mode;
  const uint32_t seed = suite.o.seed;
  const FrameSet ref = referenceFrames(suite, s, ro, seed, res);
  res.width = ref.images.front().width;
  res.height = ref.images.front().height;
  if (!suite.compare && !suite.save) return;
  // The noise floor: the reference again with other seeds.
  std::vector<std::vector<Image>> others;
  for (uint32_t k = 1; k <= kFloorSeeds; ++k)
    others.push_back(referenceFrames(suite, s, ro, seed + k, res).images);
  if (!suite.compare) return;
  const std::vector<NoiseFloor> floors = measureNoiseFloors(ref.images, others);
  for (size_t di = suite.firstCompared; di < suite.devices.size(); ++di)
    compareDevice(suite, si, ro, di, ref, floors, res);
}

void writeManifest(const Suite& suite, const nlohmann::json& savedDropped) {
  const DeviceEntry& d = *suite.devices[0];
  const nlohmann::json manifest = {
      {"settings", suite.settings},
      {"device",
       {{"name", d.name}, {"platform", d.platformName}, {"driver_version", d.driverVersion}}},
      {"frames_dropped", savedDropped}};
  writeFileAtomic((fs::path(suite.o.saveReferenceDir) / kManifest).string(),
                  manifest.dump(2) + "\n");
}

// Writes the worst comparison's difference image; returns its path ("" without comparisons).
std::string writeWorstPng(const Suite& suite, const Results& res) {
  if (res.rows.empty()) return "";
  const Row& worst = res.rows[res.worstIndex];
  const std::string png = (fs::path(suite.o.outDir) /
                           ("worst_" + safeName(suite.scenes[worst.scene].label) + "_" +
                            renderModeName(worst.mode) + "_f" + std::to_string(worst.frame) +
                            "_dev" + std::to_string(suite.devices[worst.device]->index) + ".png"))
                              .string();
  writePng(png, res.worstImage);
  return png;
}

nlohmann::ordered_json rowJson(const Suite& suite, const Row& r) {
  return {{"scene", suite.scenes[r.scene].label},
          {"mode", renderModeName(r.mode)},
          {"frame", r.frame},
          {"device", suite.devices[r.device]->index},
          {"rel_mse", r.diff.relMse},
          {"rel_mse_trimmed", r.diff.relMseTrimmed},
          {"noise_floor_rel_mse", r.floor.relMse},
          {"noise_floor_rel_mse_trimmed", r.floor.relMseTrimmed},
          {"rel_mse_ratio", number(r.verdict.relMseRatio)},
          {"mad", r.diff.mad},
          {"mean_luminance", r.diff.meanLum},
          {"reference_mean_luminance", r.diff.refMeanLum},
          {"luminance_difference_trimmed", r.diff.lumDiff},
          {"noise_floor_luminance_stderr", r.floor.lumStdErr},
          {"noise_floor_luminance_stderr_pixels", r.floor.lumStdErrPixels},
          {"noise_floor_luminance_stderr_seeds", r.floor.lumStdErrSeeds},
          {"luminance_z", number(r.verdict.lumZ)},
          {"non_finite", r.diff.nonFinite},
          {"dropped_samples", r.dropped},
          {"identical", r.diff.identical},
          {"agree", r.verdict.agree},
          {"reasons", r.verdict.reasons}};
}

void printJson(const Suite& suite, const Results& res, const std::string& worstPng,
               size_t identical, size_t disagree) {
  const PortabilityOptions& o = suite.o;
  nlohmann::ordered_json j;
  j["settings"] = {
      {"frames", suite.frames}, {"width", res.width},
      {"height", res.height},   {"spp", o.spp},
      {"seed", o.seed},         {"noise_floor_seeds", {o.seed + 1, o.seed + kFloorSeeds}}};
  j["tolerance"] = {{"relmse_factor", o.tolerance.relMseFactor},
                    {"luminance_sigmas", o.tolerance.lumSigmas},
                    {"relmse_slack", o.tolerance.relMseSlack}};
  nlohmann::ordered_json devs = nlohmann::ordered_json::array();
  for (size_t i = 0; i < suite.devices.size(); ++i)
    devs.push_back({{"index", suite.devices[i]->index},
                    {"name", suite.devices[i]->name},
                    {"platform", suite.devices[i]->platformName},
                    {"driver_version", suite.devices[i]->driverVersion},
                    {"reference", i == 0 && !suite.stored}});
  j["devices"] = devs;
  if (suite.stored)
    j["reference"] = {{"saved_in", o.referenceDir}, {"device", suite.stored->device()}};
  if (suite.save) j["saved_reference"] = o.saveReferenceDir;
  nlohmann::ordered_json sc = nlohmann::ordered_json::array();
  for (const auto& s : suite.scenes) sc.push_back({{"label", s.label}, {"path", s.path}});
  j["scenes"] = sc;
  nlohmann::ordered_json md = nlohmann::ordered_json::array();
  for (RenderMode m : suite.modes) md.push_back(renderModeName(m));
  j["modes"] = md;
  nlohmann::ordered_json results = nlohmann::ordered_json::array();
  for (const auto& r : res.rows) results.push_back(rowJson(suite, r));
  j["results"] = results;
  if (!res.rows.empty()) {
    const Row& worst = res.rows[res.worstIndex];
    j["worst"] = {{"scene", suite.scenes[worst.scene].label},
                  {"mode", renderModeName(worst.mode)},
                  {"frame", worst.frame},
                  {"device", suite.devices[worst.device]->index},
                  {"png", worstPng},
                  {"png_scale", res.worstScale}};
  } else {
    j["worst"] = nullptr;
  }
  j["summary"] = {{"comparisons", res.rows.size()},
                  {"identical", identical},
                  {"disagree", disagree},
                  {"agree", disagree == 0},
                  {"nothing_to_compare", !suite.compare}};
  std::cout << j.dump(2) << "\n";
}

void printRows(const Suite& suite, const Results& res) {
  char line[256];
  std::snprintf(line, sizeof line, "%-18s %-9s %5s %4s %10s %10s %10s %6s %10s %6s %4s %s", "scene",
                "mode", "frame", "dev", "relMSE", "relMSE*", "floor*", "ratio", "MAD", "lum z",
                "same", "verdict");
  std::cout << line << "\n";
  for (const auto& r : res.rows) {
    std::string verdict = r.verdict.agree ? "agree" : "DISAGREE";
    for (size_t i = 0; i < r.verdict.reasons.size(); ++i)
      verdict += (i ? "; " : ": ") + r.verdict.reasons[i];
    std::snprintf(line, sizeof line, "%-18s %-9s %5lld %4d %10s %10s %10s %6s %10s %6s %4s ",
                  suite.scenes[r.scene].label.c_str(), renderModeName(r.mode),
                  static_cast<long long>(r.frame), suite.devices[r.device]->index,
                  sci(r.diff.relMse).c_str(), sci(r.diff.relMseTrimmed).c_str(),
                  sci(r.floor.relMseTrimmed).c_str(), fixed(r.verdict.relMseRatio, 2).c_str(),
                  sci(r.diff.mad).c_str(), fixed(r.verdict.lumZ, 2).c_str(),
                  r.diff.identical ? "yes" : "no");
    std::cout << line << verdict << "\n";
  }
}

void printTable(const Suite& suite, const Results& res, const std::string& worstPng,
                size_t identical, size_t disagree) {
  const PortabilityOptions& o = suite.o;
  const auto& devices = suite.devices;
  std::cout << "devices:";
  for (size_t i = 0; i < devices.size(); ++i)
    std::cout << (i ? ", " : " ") << "[" << devices[i]->index << "] " << devices[i]->name
              << (i == 0 && !suite.stored ? " (reference)" : "");
  std::cout << "\n";
  if (suite.stored)
    std::cout << "reference: frames saved in " << o.referenceDir << " on " << suite.stored->device()
              << "\n";
  if (suite.save) std::cout << "saved the reference frames to " << o.saveReferenceDir << "\n";
  if (!suite.compare) {
    std::cout
        << "nothing to compare: only one device; rendered the suite on it (" << suite.scenes.size()
        << " scene(s) x " << suite.modes.size() << " mode(s) x " << suite.frames.size()
        << " frame(s)). Name a second one with --device, e.g. POCL_DEVICES=\"pthread basic\".\n";
    return;
  }
  std::cout << "suite: " << res.width << "x" << res.height << ", " << o.spp << " spp, seed "
            << o.seed << "; floor = reference at seeds " << o.seed + 1 << "-"
            << o.seed + kFloorSeeds << "; * = without the worst 1% of pixels\n"
            << "a device disagrees when relMSE* > " << o.tolerance.relMseFactor
            << " x floor*, when its mean luminance is " << o.tolerance.lumSigmas
            << " standard errors off (lum z), or on any NaN/Inf\n";
  printRows(suite, res);
  std::cout << "worst difference: " << worstPng;
  if (res.rows[res.worstIndex].diff.identical)
    std::cout << " (black: every frame is bit-identical)\n";
  else
    std::cout << " (|device - reference| x " << sci(res.worstScale) << ")\n";
  std::cout << (disagree ? "FAIL: " : "OK: ") << disagree << " of " << res.rows.size()
            << " comparisons disagree (" << identical << " bit-identical) across " << devices.size()
            << " devices\n";
}

}  // namespace

int runPortability(const PortabilityOptions& o) {
  validate(o);
  Suite suite(o);
  suite.frames = parseFrameList(o.frames);
  suite.modes = suiteModes(o.modes);
  suite.scenes = loadSuiteScenes(o);
  if (!o.referenceDir.empty()) suite.stored = std::make_unique<StoredReference>(o.referenceDir);
  suite.save = !o.saveReferenceDir.empty();
  suite.settings = suiteSettings(suite.frames, o.width, o.height, o.spp, o.seed);
  if (suite.stored) suite.stored->check(suite.settings);

  const auto all = enumerateDevices();
  if (all.empty()) throw NoDeviceError();
  if (o.devices.empty())
    for (const auto& d : all) suite.devices.push_back(&d);
  else
    for (const auto& spec : o.devices) suite.devices.push_back(&selectDevice(all, spec));
  suite.base = suiteRenderOptions(o);
  suite.firstCompared = suite.stored ? 0 : 1;
  suite.compare = suite.devices.size() > suite.firstCompared;

  if (suite.save) fs::create_directories(o.saveReferenceDir);
  Results res;
  for (size_t si = 0; si < suite.scenes.size(); ++si)
    for (RenderMode mode : suite.modes) runSceneMode(suite, si, mode, res);
  if (suite.save) writeManifest(suite, res.savedDropped);
  const std::string worstPng = writeWorstPng(suite, res);

  size_t disagree = 0, identical = 0;
  for (const auto& r : res.rows) {
    disagree += !r.verdict.agree;
    identical += r.diff.identical;
  }
  if (o.json)
    printJson(suite, res, worstPng, identical, disagree);
  else
    printTable(suite, res, worstPng, identical, disagree);
  return disagree > 0 ? kExitRuntime : kExitOk;
}

}  // namespace pr
