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
  int frame = 0;
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
                   const std::vector<int>& frames, bool quiet) {
  if (!quiet)
    std::cerr << "portability: " << s.label << " " << renderModeName(ro.mode) << " seed " << ro.seed
              << " on [" << device.index << "] " << device.name << "\n";
  RenderSession session(*s.scene, device, ro);
  FrameSet set;
  for (int f : frames) {  // increasing, so reuse carries paths from frame to frame
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

std::string referenceFile(const std::string& label, RenderMode mode, uint32_t seed, int frame) {
  return safeName(label) + "_" + renderModeName(mode) + "_s" + std::to_string(seed) + "_f" +
         std::to_string(frame) + ".exr";
}

nlohmann::json suiteSettings(const std::vector<int>& frames, int width, int height, int spp,
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
                const std::vector<int>& frames) {
    FrameSet set;
    for (int f : frames) {
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

std::vector<int> parseFrameList(const std::string& text) {
  std::vector<int> frames;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, ',')) {
    const FrameRange r = parseFrameRange(part);
    if (r.last - r.first > 1000) throw InputError("--frames " + text + ": at most 1000 frames");
    for (int f = r.first; f <= r.last; ++f) frames.push_back(f);
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

int runPortability(const PortabilityOptions& o) {
  validate(o);
  const std::vector<int> frames = parseFrameList(o.frames);
  std::vector<RenderMode> modes;
  for (const auto& m : o.modes) {
    const RenderMode mode = parseMode(m);
    if (std::find(modes.begin(), modes.end(), mode) == modes.end()) modes.push_back(mode);
  }
  if (modes.empty()) modes = {RenderMode::Reuse, RenderMode::Retrace, RenderMode::PathTrace};

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

  std::unique_ptr<StoredReference> stored;
  if (!o.referenceDir.empty()) stored = std::make_unique<StoredReference>(o.referenceDir);
  const bool save = !o.saveReferenceDir.empty();
  const nlohmann::json settings = suiteSettings(frames, o.width, o.height, o.spp, o.seed);
  if (stored) stored->check(settings);

  const auto all = enumerateDevices();
  if (all.empty()) throw NoDeviceError();
  std::vector<const DeviceEntry*> devices;
  if (o.devices.empty())
    for (const auto& d : all) devices.push_back(&d);
  else
    for (const auto& spec : o.devices) devices.push_back(&selectDevice(all, spec));

  RenderOptions base;
  base.width = o.width;
  base.height = o.height;
  base.spp = o.spp;
  base.seed = o.seed;
  base.quiet = true;
  // One estimator on every device (auto would resample connections on GPUs only): the suite
  // compares implementations, not per-device defaults.
  base.connections = 0;
  validateRenderOptions(base);

  // Against saved frames every device is compared; else every device but the first.
  const size_t firstCompared = stored ? 0 : 1;
  const bool compare = devices.size() > firstCompared;
  nlohmann::json savedDropped = nlohmann::json::object();
  if (save) fs::create_directories(o.saveReferenceDir);
  std::vector<Row> rows;
  double worstBadness =
      -1.0;  // the comparison furthest past its tolerance gets its difference written
  const Row* worstRow = nullptr;
  size_t worstIndex = 0;
  Image worstImage;
  double worstScale = 1.0;
  int width = 0, height = 0;
  for (size_t si = 0; si < scenes.size(); ++si) {
    const SuiteScene& s = scenes[si];
    for (RenderMode mode : modes) {
      RenderOptions ro = base;
      ro.scene = s.path;
      ro.mode = mode;
      auto reference = [&](uint32_t seed) {
        if (stored) return stored->load(s.label, mode, seed, frames);
        RenderOptions r = ro;
        r.seed = seed;
        FrameSet set = renderSet(s, *devices[0], r, frames, o.quiet);
        for (size_t fi = 0; save && fi < frames.size(); ++fi) {
          const std::string name = referenceFile(s.label, mode, seed, frames[fi]);
          writeExr((fs::path(o.saveReferenceDir) / name).string(), set.images[fi],
                   ExrPixels::Float);
          savedDropped[name] = set.dropped[fi];
        }
        return set;
      };
      const FrameSet ref = reference(o.seed);
      width = ref.images.front().width;
      height = ref.images.front().height;
      if (!compare && !save) continue;
      // The noise floor: the reference again with other seeds.
      std::vector<std::vector<Image>> others;
      for (uint32_t k = 1; k <= kFloorSeeds; ++k) others.push_back(reference(o.seed + k).images);
      if (!compare) continue;
      const std::vector<NoiseFloor> floors = measureNoiseFloors(ref.images, others);
      for (size_t di = firstCompared; di < devices.size(); ++di) {
        const FrameSet dev = renderSet(s, *devices[di], ro, frames, o.quiet);
        for (size_t fi = 0; fi < frames.size(); ++fi) {
          if (dev.images[fi].width != width || dev.images[fi].height != height)
            throw InputError("the reference frames are " + std::to_string(width) + "x" +
                             std::to_string(height) + ", the device's " +
                             std::to_string(dev.images[fi].width) + "x" +
                             std::to_string(dev.images[fi].height));
          Row r;
          r.scene = si;
          r.mode = mode;
          r.frame = frames[fi];
          r.device = di;
          r.diff = compareImages(dev.images[fi], ref.images[fi]);
          r.floor = floors[fi];
          r.dropped = dev.dropped[fi];
          r.refDropped = ref.dropped[fi];
          r.verdict = judge(r.diff, r.floor, o.tolerance, r.dropped, r.refDropped);
          const double b = badness(r, o.tolerance);
          if (b > worstBadness) {
            worstBadness = b;
            worstIndex = rows.size();
            worstImage = differenceImage(dev.images[fi], ref.images[fi], &worstScale);
          }
          rows.push_back(r);
        }
      }
    }
  }
  if (save) {
    const DeviceEntry& d = *devices[0];
    const nlohmann::json manifest = {
        {"settings", settings},
        {"device",
         {{"name", d.name}, {"platform", d.platformName}, {"driver_version", d.driverVersion}}},
        {"frames_dropped", savedDropped}};
    writeFileAtomic((fs::path(o.saveReferenceDir) / kManifest).string(), manifest.dump(2) + "\n");
  }

  std::string worstPng;
  if (!rows.empty()) {
    worstRow = &rows[worstIndex];
    worstPng = (fs::path(o.outDir) /
                ("worst_" + safeName(scenes[worstRow->scene].label) + "_" +
                 renderModeName(worstRow->mode) + "_f" + std::to_string(worstRow->frame) + "_dev" +
                 std::to_string(devices[worstRow->device]->index) + ".png"))
                   .string();
    writePng(worstPng, worstImage);
  }

  size_t disagree = 0, identical = 0;
  for (const auto& r : rows) {
    disagree += !r.verdict.agree;
    identical += r.diff.identical;
  }
  const int exitCode = disagree > 0 ? kExitRuntime : kExitOk;

  if (o.json) {
    nlohmann::ordered_json j;
    j["settings"] = {{"frames", frames}, {"width", width},
                     {"height", height}, {"spp", o.spp},
                     {"seed", o.seed},   {"noise_floor_seeds", {o.seed + 1, o.seed + kFloorSeeds}}};
    j["tolerance"] = {{"relmse_factor", o.tolerance.relMseFactor},
                      {"luminance_sigmas", o.tolerance.lumSigmas},
                      {"relmse_slack", o.tolerance.relMseSlack}};
    nlohmann::ordered_json devs = nlohmann::ordered_json::array();
    for (size_t i = 0; i < devices.size(); ++i)
      devs.push_back({{"index", devices[i]->index},
                      {"name", devices[i]->name},
                      {"platform", devices[i]->platformName},
                      {"driver_version", devices[i]->driverVersion},
                      {"reference", i == 0 && !stored}});
    j["devices"] = devs;
    if (stored) j["reference"] = {{"saved_in", o.referenceDir}, {"device", stored->device()}};
    if (save) j["saved_reference"] = o.saveReferenceDir;
    nlohmann::ordered_json sc = nlohmann::ordered_json::array();
    for (const auto& s : scenes) sc.push_back({{"label", s.label}, {"path", s.path}});
    j["scenes"] = sc;
    nlohmann::ordered_json md = nlohmann::ordered_json::array();
    for (RenderMode m : modes) md.push_back(renderModeName(m));
    j["modes"] = md;
    nlohmann::ordered_json results = nlohmann::ordered_json::array();
    for (const auto& r : rows)
      results.push_back({{"scene", scenes[r.scene].label},
                         {"mode", renderModeName(r.mode)},
                         {"frame", r.frame},
                         {"device", devices[r.device]->index},
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
                         {"reasons", r.verdict.reasons}});
    j["results"] = results;
    if (worstRow)
      j["worst"] = {{"scene", scenes[worstRow->scene].label},
                    {"mode", renderModeName(worstRow->mode)},
                    {"frame", worstRow->frame},
                    {"device", devices[worstRow->device]->index},
                    {"png", worstPng},
                    {"png_scale", worstScale}};
    else
      j["worst"] = nullptr;
    j["summary"] = {{"comparisons", rows.size()},
                    {"identical", identical},
                    {"disagree", disagree},
                    {"agree", disagree == 0},
                    {"nothing_to_compare", !compare}};
    std::cout << j.dump(2) << "\n";
    return exitCode;
  }

  std::cout << "devices:";
  for (size_t i = 0; i < devices.size(); ++i)
    std::cout << (i ? ", " : " ") << "[" << devices[i]->index << "] " << devices[i]->name
              << (i == 0 && !stored ? " (reference)" : "");
  std::cout << "\n";
  if (stored)
    std::cout << "reference: frames saved in " << o.referenceDir << " on " << stored->device()
              << "\n";
  if (save) std::cout << "saved the reference frames to " << o.saveReferenceDir << "\n";
  if (!compare) {
    std::cout
        << "nothing to compare: only one device; rendered the suite on it (" << scenes.size()
        << " scene(s) x " << modes.size() << " mode(s) x " << frames.size()
        << " frame(s)). Name a second one with --device, e.g. POCL_DEVICES=\"pthread basic\".\n";
    return kExitOk;
  }
  std::cout << "suite: " << width << "x" << height << ", " << o.spp << " spp, seed " << o.seed
            << "; floor = reference at seeds " << o.seed + 1 << "-" << o.seed + kFloorSeeds
            << "; * = without the worst 1% of pixels\n"
            << "a device disagrees when relMSE* > " << o.tolerance.relMseFactor
            << " x floor*, when its mean luminance is " << o.tolerance.lumSigmas
            << " standard errors off (lum z), or on any NaN/Inf\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-18s %-9s %5s %4s %10s %10s %10s %6s %10s %6s %4s %s", "scene",
                "mode", "frame", "dev", "relMSE", "relMSE*", "floor*", "ratio", "MAD", "lum z",
                "same", "verdict");
  std::cout << line << "\n";
  for (const auto& r : rows) {
    std::string verdict = r.verdict.agree ? "agree" : "DISAGREE";
    for (size_t i = 0; i < r.verdict.reasons.size(); ++i)
      verdict += (i ? "; " : ": ") + r.verdict.reasons[i];
    std::snprintf(line, sizeof line, "%-18s %-9s %5d %4d %10s %10s %10s %6s %10s %6s %4s ",
                  scenes[r.scene].label.c_str(), renderModeName(r.mode), r.frame,
                  devices[r.device]->index, sci(r.diff.relMse).c_str(),
                  sci(r.diff.relMseTrimmed).c_str(), sci(r.floor.relMseTrimmed).c_str(),
                  fixed(r.verdict.relMseRatio, 2).c_str(), sci(r.diff.mad).c_str(),
                  fixed(r.verdict.lumZ, 2).c_str(), r.diff.identical ? "yes" : "no");
    std::cout << line << verdict << "\n";
  }
  std::cout << "worst difference: " << worstPng;
  if (worstRow->diff.identical)
    std::cout << " (black: every frame is bit-identical)\n";
  else
    std::cout << " (|device - reference| x " << sci(worstScale) << ")\n";
  std::cout << (disagree ? "FAIL: " : "OK: ") << disagree << " of " << rows.size()
            << " comparisons disagree (" << identical << " bit-identical) across " << devices.size()
            << " devices\n";
  return exitCode;
}

}  // namespace pr
