#include "render/renderer.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <numeric>

#include <nlohmann/json.hpp>

#include "cl/context.h"
#include "cl/device.h"
#include "io/image.h"
#include "io/video.h"
#include "render/film.h"
#include "render/frame_writer.h"
#include "render/gpu_scene.h"
#include "render/history_format.h"
#include "render/multi_device.h"
#include "render/path_reuse.h"
#include "render/path_tracer.h"
#include "render/session.h"
#include "scene/gltf_loader.h"
#include "scene/image_decode.h"
#include "util/check.h"
#include "util/error.h"
#include "util/files.h"
#include "util/input_file.h"
#include "util/interrupt.h"

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

// One JSON line per frame, flushed at once so that an interrupted run keeps its lines; a
// failed write (disk full) is an error naming the file.
class StatsFile {
 public:
  StatsFile(const std::string& path, bool append) : path_(path) {
    const auto parent = std::filesystem::path(path).parent_path();
    std::error_code ec;
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
    if (append) dropPartialLine();
    fd_ =
        ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | (append ? O_APPEND : O_TRUNC), 0644);
    if (fd_ < 0) fail();
  }
  ~StatsFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  StatsFile(const StatsFile&) = delete;
  StatsFile& operator=(const StatsFile&) = delete;
  // The line whole or not at all: where a write falls short (a full disk) the file is cut back
  // to where the line began, then the error is raised.
  void writeLine(const std::string& line) {
    const std::string text = line + "\n";
    struct stat st {};
    const bool regular = ::fstat(fd_, &st) == 0 && S_ISREG(st.st_mode);
    size_t done = 0;
    while (done < text.size()) {
      errno = 0;
      const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const int err = errno ? errno : ENOSPC;
        if (regular && done > 0 && ::ftruncate(fd_, st.st_size) != 0) {
          // The cut-back failed too: the next run's dropPartialLine removes the half line.
        }
        errno = err;
        fail();
      }
      done += size_t(n);
    }
  }

 private:
  // A run stopped by a full disk may have left half a line: appending to it would join two
  // records into one unparseable line. Keep the complete lines only.
  void dropPartialLine() {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path_, ec)) return;
    std::string text;
    if (!readFile(path_, &text)) fail();
    if (text.empty() || text.back() == '\n') return;
    const size_t keep = text.rfind('\n') == std::string::npos ? 0 : text.rfind('\n') + 1;
    errno = 0;
    if (::truncate(path_.c_str(), off_t(keep)) != 0) fail();
  }
  [[noreturn]] void fail() const {
    throw RuntimeError(path_ +
                       ": cannot write the stats file: " + std::strerror(errno ? errno : EIO));
  }
  std::string path_;
  int fd_ = -1;
};

// The files a render reads: none of its outputs may replace one (`--out out/%d.gltf` over the
// scene, `--stats` naming a texture), by any name or link.
class InputFiles {
 public:
  InputFiles(const Scene& scene, const RenderOptions& o) : files_(scene.inputFiles) {
    if (!o.env.empty() && o.env != "none") files_.push_back(o.env);
  }
  // Throws InputError, naming `option` and the file, where `path` is one of them.
  void refuse(const std::string& path, const char* option) const {
    std::error_code ec;
    for (const std::string& in : files_)
      if (std::filesystem::equivalent(path, in, ec))
        throw InputError(std::string(option) + " " + path + ": " +
                         (path == in ? "" : "the same file as " + in + ", ") +
                         "a file this render reads (an output never replaces an input)");
  }
  // Every file frame f writes.
  void refuseFrame(const RenderOptions& o, int64_t f, bool history) const {
    const std::string exr = formatOutPath(o.outPattern, f);
    refuse(exr, "--out");
    if (o.png) refuse(withExtension(exr, ".png"), "--out");
    if (history) refuse(exr + ".history", "--out");
  }

 private:
  std::vector<std::string> files_;
};

std::string frameSpan(int64_t a, int64_t b) {
  return a == b ? std::to_string(a) : std::to_string(a) + "-" + std::to_string(b);
}

// A frame that --resume may skip: a complete EXR of the session's size (and its PNG when asked).
bool frameDone(const std::string& exr, const RenderOptions& o, int width, int height) {
  if (!std::filesystem::exists(exr)) return false;
  try {
    const Image img = readExr(exr);
    if (img.width != width || img.height != height) return false;
    if (!o.png) return true;
    // The PNG whole too: a cut or corrupt one fails its CRCs or lacks its end.
    DecodedImage png;
    std::string why;
    return decodeImageRgba8(readInputFile(withExtension(exr, ".png"), kMaxImageFileBytes), &png,
                            &why) &&
           png.width == width && png.height == height;
  } catch (const InputError&) {
    return false;  // missing, truncated or corrupt: render it again
  }
}

// A scene without lights: lit by a white environment unless asked otherwise, said once.
void noteUnlitScene(const Scene& scene, const RenderOptions& o) {
  // A scene with nothing to render is an error of one line (RenderSession), without this note.
  if (scene.staticTriangleCount() + scene.dynamicTriangleCount() == 0) return;
  if (!sceneHasNoLights(scene) || o.quiet) return;
  if (o.env.empty() && o.envColor.empty())
    std::cerr << "note: " << o.scene
              << ": no lights; lit by a uniform white environment (--env none keeps it dark)\n";
  else if (o.env == "none")
    std::cerr << "warning: " << o.scene << ": no lights and --env none; frames will be black\n";
}

void printStart(const RenderOptions& o, MultiDeviceSession& session, const FrameRange& range) {
  std::cerr << "rendering " << o.scene << " frames " << range.first << "-" << range.last << " at "
            << session.width() << "x" << session.height() << ", " << o.spp << " spp, mode "
            << renderModeName(o.mode) << (resolveResample(o).enabled ? ", resampled" : "")
            << ", on ";
  for (size_t i = 0; i < session.deviceCount(); ++i)
    std::cerr << (i ? " + " : "") << session.device(i).name;
  const std::string more = session.session(0).integrator().describe();
  if (!more.empty()) std::cerr << "; " << more;
  std::cerr << "\n";
}

// The stats file's line for one frame.
std::string statsLine(int64_t f, const RenderOptions& o, const FrameStats& fs,
                      const std::vector<DeviceFrame>& parts) {
  nlohmann::ordered_json j;
  j["frame"] = f;
  j["mode"] = renderModeName(o.mode);
  j["resample"] = resolveResample(o).enabled;
  j["wall_s"] = fs.wallSeconds;
  j["stages_s"] = fs.stageSeconds;
  j["host_s"] = fs.hostSeconds;
  if (fs.motionSteps > 1) j["motion_steps"] = fs.motionSteps;
  if (!fs.buildSeconds.empty()) j["build_s"] = fs.buildSeconds;
  j["rays"] = fs.rays;
  if (!fs.counters.empty()) j["counters"] = fs.counters;
  j["device_bytes"] = fs.deviceBytes;
  j["device_buffers"] = fs.deviceBuffers;
  j["bad_samples"] = fs.badSamples;
  // Samples per pixel: each pixel's own under --noise-threshold, else every pixel the same
  // (--time-limit cuts whole passes).
  if (fs.sppMean >= 0.0)
    j["spp"] = {{"mean", fs.sppMean}, {"max", fs.sppMax}};
  else
    j["spp"] = {{"mean", fs.passes}, {"max", fs.passes}};
  // Per device: its rows and sample passes, their share of the frame's pixel samples, its wall
  // and kernel times.
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const DeviceFrame& p : parts) {
    nlohmann::ordered_json d;
    d["index"] = p.index;
    d["name"] = p.name;
    d["row_begin"] = p.rowBegin;
    d["rows"] = p.rowEnd - p.rowBegin;
    d["pass_begin"] = p.passBegin;
    d["passes"] = p.passEnd - p.passBegin;
    d["share"] = p.share;
    d["wall_s"] = p.wallSeconds;
    d["stages_s"] = p.stats.stageSeconds;
    d["rays"] = p.stats.rays;
    list.push_back(std::move(d));
  }
  j["devices"] = std::move(list);
  return j.dump();
}

// What the frames of one run came to, for the progress line and the summary.
struct Tally {
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  uint64_t raysSoFar = 0, badSamples = 0;
  int rendered = 0, skipped = 0, badFrames = 0;
};

void printProgress(const FrameRange& range, const Tally& t, int64_t f) {
  const int64_t total = range.last - range.first + 1;
  const int64_t done = f - range.first + 1;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t.start).count();
  const double eta = t.rendered > 0 ? elapsed / t.rendered * double(total - done) : 0.0;
  std::fprintf(stderr, "\rframe %lld of %lld (#%lld)  %.2f Mrays/s  elapsed %s  ETA %s   ",
               static_cast<long long>(done), static_cast<long long>(total),
               static_cast<long long>(f), elapsed > 0 ? t.raysSoFar / elapsed * 1e-6 : 0.0,
               clock(elapsed).c_str(), clock(eta).c_str());
  std::fflush(stderr);
}

// Frames before f are complete (rendered now or found complete); f onwards are not.
int reportInterrupt(const RenderOptions& o, const FrameRange& range, int64_t f) {
  const int sig = interruptSignal();
  std::cerr << "interrupted by "
            << (sig == SIGTERM  ? "SIGTERM"
                : sig == SIGINT ? "SIGINT"
                                : "signal")
            << ": "
            << (f > range.first ? "frames " + frameSpan(range.first, f - 1) + " complete"
                                : "no frame complete")
            << " in " << o.outPattern << "; " << frameSpan(f, range.last)
            << " not rendered (run again with --resume to finish)\n";
  return 128 + sig;
}

void printSummary(const RenderOptions& o, const FrameRange& range, const Tally& t) {
  const int64_t total = range.last - range.first + 1;
  std::cerr << "rendered " << t.rendered << " frame(s) to "
            << formatOutPath(o.outPattern, range.first)
            << (total > 1 ? " ... " + formatOutPath(o.outPattern, range.last) : "");
  if (t.skipped > 0) std::cerr << "; " << t.skipped << " already complete, skipped";
  std::cerr << "\n";
  if (t.badSamples > 0)
    std::cerr << "warning: " << t.badSamples << " non-finite samples were dropped in "
              << t.badFrames << " frame(s)\n";
}

// --resume with --resample: the resampled paths' history of frame f, kept beside its EXR so that a
// resumed run (or the next chunk of frames, where it starts after this one ended) goes on as one
// uninterrupted run. With several devices each keeps the chains of its own sample passes.
std::string historyPath(const RenderOptions& o, int64_t f) {
  return formatOutPath(o.outPattern, f) + ".history";
}

bool keepsHistory(const RenderOptions& o) {
  const ResampleSettings r = resolveResample(o);
  return o.resume && r.enabled && r.history > 0;
}

// Everything a history depends on besides its frame: every option that can change a frame
// (RenderOptions::estimatorKey), the image's size, the devices, the content of every file the
// render reads (the scene and its files, the environment map) and the program itself, whose
// kernels and defaults made it. (The split of the passes is in the file, and the run that reads
// it takes that split.)
std::string historyKey(const RenderOptions& o, MultiDeviceSession& session) {
  PR_CHECK(!o.estimatorKey.empty() && !session.session(0).scene().inputDigest.empty());
  std::string key = o.estimatorKey;
  key += "size " + std::to_string(session.width()) + "x" + std::to_string(session.height()) + "\n";
  for (size_t i = 0; i < session.deviceCount(); ++i) {
    const DeviceEntry& d = session.device(i);
    key += "device " + d.platformName + " / " + d.name + " / " + d.driverVersion + "\n";
  }
  key += "scene " + session.session(0).scene().inputDigest + "\n";
  key += "environment " + session.session(0).environmentDigest() + "\n";
  key += "program " + executableDigest() + "\n";
  return key;
}

// Before a frame f > 0 whose previous frame this run did not render: whether the history frame
// f - 1 left was read.
bool readHistory(const RenderOptions& o, MultiDeviceSession& session, const std::string& key,
                 int64_t f) {
  std::string data;
  const bool read =
      readFile(historyPath(o, f - 1), &data) && unpackHistories(data, session, key, f - 1);
  if (read && !o.quiet)
    std::cerr << "note: --resume: goes on from frame " << f - 1 << "'s resampled paths\n";
  return read;
}

// The same frame f without that history: frames f - --warm-up .. f - 1 rendered and not written,
// or the history starts afresh (both said when `say`).
void warmUp(const RenderOptions& o, MultiDeviceSession& session, int64_t f, bool say) {
  const int64_t first = std::max<int64_t>(0, f - o.warmUp);
  if (say && !o.quiet) {
    if (first < f)
      std::cerr << "note: --warm-up: frames " << first << "-" << f - 1
                << " rendered and not written, for frame " << f << "'s resampled paths"
                << (first == 0 ? " (as an uninterrupted run's)\n" : "\n");
    else
      std::cerr << "note: --resume: the resampled paths' history starts afresh at frame " << f
                << " (frames from here differ from an uninterrupted run's, unbiased)\n";
  }
  for (int64_t w = first; w < f && !interrupted(); ++w) {
    FrameStats fs;
    std::vector<DeviceFrame> parts;
    session.renderFrame(w, &fs, &parts);
  }
}

// After frame f is written: its history (packHistories's bytes) replaces the previous frame's.
void writeHistory(const RenderOptions& o, const std::string& packed, int64_t f) {
  writeFileAtomic(historyPath(o, f), packed);
  std::error_code ec;
  std::filesystem::remove(historyPath(o, f - 1), ec);
}

// Whether process `pid` is running (a temporary file of a live run is not stale).
bool processAlive(long pid) {
  return pid > 0 && (::kill(pid_t(pid), 0) == 0 || errno != ESRCH);
}

// Files a run over this output pattern left that nothing will use: the hidden temporaries of
// runs that died (SIGKILL, a crash) and resume histories that no resumed frame can need (frame
// g's, where frame g + 1's EXR exists or g's does not, or g is the animation's last). Removed,
// and counted in a note. Only where the frame number is in the file name, not in a folder.
void removeStaleFiles(const RenderOptions& o, int frameCount) {
  namespace fs = std::filesystem;
  const fs::path a(formatOutPath(o.outPattern, 0)), b(formatOutPath(o.outPattern, 1));
  if (a.parent_path() != b.parent_path()) return;
  const std::string name = fs::path(o.outPattern).filename().string();
  const std::string prefix = name.substr(0, name.find('%'));
  const fs::path dir = a.parent_path().empty() ? fs::path(".") : a.parent_path();
  std::error_code ec;
  int removed = 0;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string file = e.path().filename().string();
    bool stale = false;
    const size_t tmp = file.rfind(".tmp");
    if (file.size() > 1 && file[0] == '.' && tmp != std::string::npos &&
        file.compare(1, prefix.size(), prefix) == 0) {
      // .NAME.tmpPID_N (util/files.h)
      const std::string tail = file.substr(tmp + 4);
      const size_t bar = tail.find('_');
      if (bar != std::string::npos && bar > 0 &&
          tail.find_first_not_of("0123456789_") == std::string::npos)
        stale = !processAlive(std::strtol(tail.substr(0, bar).c_str(), nullptr, 10));
    } else if (file.size() > 8 && file.compare(file.size() - 8, 8, ".history") == 0 &&
               file.compare(0, prefix.size(), prefix) == 0) {
      const std::string exr = file.substr(0, file.size() - 8);
      const size_t digits = exr.find_first_not_of("0123456789", prefix.size());
      if (digits == prefix.size() || digits == std::string::npos || digits - prefix.size() > 9)
        continue;
      const int g = std::stoi(exr.substr(prefix.size(), digits - prefix.size()));
      if (fs::path(formatOutPath(o.outPattern, g)).filename() != exr) continue;
      stale = g >= frameCount - 1 || !fs::exists(dir / exr, ec) ||
              fs::exists(formatOutPath(o.outPattern, g + 1), ec);
    }
    if (stale && fs::remove(e.path(), ec)) ++removed;
  }
  if (removed > 0 && !o.quiet)
    std::cerr << "note: removed " << removed
              << " stale resume histories and temporary files of earlier runs beside "
              << formatOutPath(o.outPattern, 0) << "\n";
}

// --video: every frame of the range (rendered now, or complete before with --resume) from its
// PNG, in order.
void writeVideo(const RenderOptions& o, const FrameRange& range) {
  std::vector<std::string> pngs;
  for (int64_t f = range.first; f <= range.last; ++f)
    pngs.push_back(withExtension(formatOutPath(o.outPattern, f), ".png"));
  encodeVideo(findFfmpeg(), pngs, o.fps, o.video);
  if (!o.quiet)
    std::cerr << "video: " << o.video << " (" << pngs.size() << " frames at " << o.fps << " fps)\n";
}

// Renders the session's frames in order, each written (render/frame_writer.h) while the next
// one renders.
int renderFrames(const RenderOptions& o, MultiDeviceSession& session, const FrameRange& range,
                 StatsFile* stats, const InputFiles& inputs) {
  FrameWriter writer;
  const bool progress = !o.quiet && isatty(STDERR_FILENO);
  Tally t;
  int64_t f = range.first;
  const bool history = keepsHistory(o);
  const ResampleSettings rs = resolveResample(o);
  const bool resampled = rs.enabled && rs.history > 0;
  const std::string key = history ? historyKey(o, session) : std::string();
  int64_t lastRendered = -2;
  removeStaleFiles(o, session.session(0).frameCount());
  endLoadingPhase();  // a signal from here on finishes cleanly between launches
  for (; f <= range.last && !interrupted(); ++f) {
    const std::string exr = formatOutPath(o.outPattern, f);
    inputs.refuseFrame(o, f, history);
    if (o.resume && frameDone(exr, o, session.width(), session.height())) {
      ++t.skipped;
      continue;
    }
    if (t.skipped > 0 && t.rendered == 0 && o.connect.historyCap > 0 &&
        o.mode != RenderMode::PathTrace && !o.quiet)
      std::cerr << "note: --resume: the connection history starts afresh at frame " << f
                << " (frames from here differ from an uninterrupted run's, unbiased)\n";
    if (lastRendered != f - 1 && f > 0 && resampled) {
      const bool read = history && readHistory(o, session, key, f);
      // A run's first frame without --resume and --warm-up starts afresh as ever: no note.
      if (!read && (history || o.warmUp > 0)) warmUp(o, session, f, true);
    }
    const auto t0 = std::chrono::steady_clock::now();
    FrameStats fs;
    std::vector<DeviceFrame> parts;
    Image img = session.renderFrame(f, &fs, &parts);
    if (interrupted()) break;  // the film may be partial: drop the frame
    // The devices' state is read now, before the next frame changes it; the files are written
    // on the writer's thread, the frame before this one's first (its wall time counts here).
    std::string packed = history ? packHistories(session, key) : std::string();
    writer.wait();
    lastRendered = f;
    ++t.rendered;
    fs.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (const auto& [k, v] : fs.rays) t.raysSoFar += v;
    std::string line = stats ? statsLine(f, o, fs, parts) : std::string();
    writer.submit([&o, stats, history, f, exr, img = std::move(img), packed = std::move(packed),
                   line = std::move(line)] {
      writeExr(exr, img, o.exrFloat ? ExrPixels::Float : ExrPixels::Half);
      if (o.png) writePng(withExtension(exr, ".png"), img, o.exposure);
      if (history) writeHistory(o, packed, f);
      if (stats) stats->writeLine(line);
    });
    if (fs.badSamples > 0) {
      t.badSamples += fs.badSamples;
      ++t.badFrames;
      if (!o.quiet)
        std::cerr << (progress ? "\n" : "") << "warning: frame " << f << ": " << fs.badSamples
                  << " non-finite samples were dropped\n";
    }
    if (progress) printProgress(range, t, f);
  }
  writer.wait();
  if (progress) std::fprintf(stderr, "\n");
  // The animation's last frame has no next one to take its history.
  if (history && f > range.last && range.last >= session.session(0).frameCount() - 1) {
    std::error_code ec;
    std::filesystem::remove(historyPath(o, range.last), ec);
  }
  // A signal after the last frame changes nothing.
  if (interrupted() && f <= range.last) return reportInterrupt(o, range, f);
  if (!o.quiet) printSummary(o, range, t);
  if (!o.video.empty()) writeVideo(o, range);
  return kExitOk;
}

}  // namespace

// The devices' histories in one file: the split of the passes (the device count, 4 bytes, then
// each device's passes, 4 bytes each; 0 where the devices split rows), then per device its
// history's size (8 bytes) and its history ("" where the device chains no passes).
std::string packHistories(MultiDeviceSession& session, const std::string& key) {
  std::vector<int> split(session.deviceCount(), 0);
  std::vector<std::string> parts(session.deviceCount());
  for (size_t i = 0; i < session.deviceCount(); ++i) {
    if (!session.passes().empty()) split[i] = session.passes()[i];
    RenderSession& s = session.session(i);
    if (s.hasHistory()) parts[i] = s.writeHistory(key);
  }
  return packHistoryFile(split, parts);
}

bool unpackHistories(const std::string& data, MultiDeviceSession& session, const std::string& key,
                     int64_t frame) {
  std::vector<int> split;
  std::vector<std::string> parts;
  if (!unpackHistoryFile(data, session.deviceCount(), &split, &parts)) return false;
  const int spp = std::accumulate(split.begin(), split.end(), 0);
  const std::vector<int> before = session.passes();
  if (!before.empty()) {
    if (spp != std::accumulate(before.begin(), before.end(), 0) ||
        (size_t(spp) >= split.size() && std::count(split.begin(), split.end(), 0) > 0))
      return false;
    if (split != before) session.setPassSplit(split);  // the writing run's
  }
  // All or nothing: every device's part is checked before any is loaded.
  for (size_t i = 0; i < parts.size(); ++i) {
    if (!parts[i].empty() && !session.session(i).checkHistory(parts[i], key, frame)) {
      if (!before.empty() && split != before) session.setPassSplit(before);
      return false;
    }
  }
  for (size_t i = 0; i < parts.size(); ++i)
    if (!parts[i].empty()) session.session(i).applyHistory(parts[i]);
  return true;
}

int runRender(const RenderOptions& o) {
  installInterruptHandlers(o.scene);
  validateRenderOptions(o);
  if (!o.video.empty()) {
    if (!videoContainerKnown(o.video))
      throw InputError("--video " + o.video + ": name a .mp4, .mov or .mkv file");
    if (findFfmpeg().empty())
      throw InputError("--video " + o.video +
                       ": ffmpeg is not on PATH (Debian: apt-get install ffmpeg, which "
                       "tools/setup/install-deps.sh does)");
  }
  LoadOptions loadOptions;
  loadOptions.allowOutsideUris = o.allowOutsideUris;
  loadOptions.animation = o.animation;
  loadOptions.emitBaseColor = o.emitBaseColor;
  loadOptions.emitStrength = o.emitStrength;
  loadOptions.digestInputs = keepsHistory(o);
  const Scene scene = loadScene(o.scene, loadOptions);
  noteUnlitScene(scene, o);
  const InputFiles inputs(scene, o);
  const int64_t first = o.framesGiven ? o.frames.first : 0;
  inputs.refuseFrame(o, first, keepsHistory(o));
  if (!o.statsFile.empty()) inputs.refuse(o.statsFile, "--stats");
  // Unwritable output is found before the kernels are built, not after the first frame.
  checkWritable(formatOutPath(o.outPattern, first));
  if (!o.video.empty()) {
    inputs.refuse(o.video, "--video");
    checkWritable(o.video);
  }
  std::unique_ptr<StatsFile> stats;
  if (!o.statsFile.empty()) stats = std::make_unique<StatsFile>(o.statsFile, o.resume);
  const auto devices = enumerateDevices();
  MultiDeviceSession session(scene, selectDevices(devices, o.devices), o);
  const FrameRange range = session.frameRange();
  if (!o.quiet) printStart(o, session, range);
  return renderFrames(o, session, range, stats.get(), inputs);
}

}  // namespace pr
