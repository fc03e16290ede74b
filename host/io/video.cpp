#include "io/video.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "util/error.h"
#include "util/files.h"

extern char** environ;

namespace pr {

namespace fs = std::filesystem;

namespace {

std::string extensionOf(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

// ffmpeg's muxer for the container (picked by name, since the temporary file has none).
const char* muxerFor(const std::string& path) {
  const std::string e = extensionOf(path);
  return e == ".mp4" ? "mp4" : e == ".mov" ? "mov" : "matroska";
}

// The last non-empty line of a text file ("" where none).
std::string lastLine(const std::string& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

// Runs argv[0] (a path) with stdin from /dev/null and stdout and stderr into `log`; its exit
// status, or -1 where it could not be started or was killed.
int run(const std::vector<std::string>& args, const std::string& log) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  const int err = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) return -1;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

std::string findFfmpeg() {
  const char* path = std::getenv("PATH");
  if (!path) return "";
  std::stringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const std::string candidate = (fs::path(dir) / "ffmpeg").string();
    if (access(candidate.c_str(), X_OK) == 0 && fs::is_regular_file(candidate)) return candidate;
  }
  return "";
}

bool videoContainerKnown(const std::string& path) {
  const std::string e = extensionOf(path);
  return e == ".mp4" || e == ".mov" || e == ".mkv";
}

void encodeVideo(const std::string& ffmpeg, const std::vector<std::string>& frames, double fps,
                 const std::string& out) {
  // The frames as one numbered sequence of links, whatever the --out pattern and the frame list.
  std::error_code ec;
  const fs::path dir = temporaryNameFor(out) + ".frames";
  fs::create_directories(dir, ec);
  if (ec) throw RuntimeError("--video " + out + ": cannot create " + dir.string());
  auto cleanUp = [&] { fs::remove_all(dir, ec); };
  for (size_t i = 0; i < frames.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%08zu.png", i);
    fs::create_symlink(fs::absolute(frames[i]), dir / name, ec);
    if (ec) {
      cleanUp();
      throw RuntimeError("--video " + out + ": cannot link " + frames[i] + " into " + dir.string());
    }
  }
  const std::string tmp = temporaryNameFor(out), log = (dir / "ffmpeg.log").string();
  std::vector<std::string> args = {ffmpeg,         "-nostdin",
                                   "-hide_banner", "-loglevel",
                                   "error",        "-y",
                                   "-framerate",   std::to_string(fps),
                                   "-i",           (dir / "%08d.png").string(),
                                   "-vf",          "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                   "-c:v",         "libx264",
                                   "-pix_fmt",     "yuv420p",
                                   "-crf",         "18"};
  if (std::string(muxerFor(out)) != "matroska") {
    args.push_back("-movflags");
    args.push_back("+faststart");
  }
  args.insert(args.end(), {"-f", muxerFor(out), tmp});
  const int status = run(args, log);
  const std::string message = lastLine(log);
  cleanUp();
  if (status != 0) {
    fs::remove(tmp, ec);
    throw RuntimeError("--video " + out + ": ffmpeg " +
                       (status < 0 ? std::string("could not run")
                                   : "failed (exit " + std::to_string(status) + ")") +
                       (message.empty() ? "" : ": " + message));
  }
  fs::rename(tmp, out, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw RuntimeError("--video " + out + ": cannot write it");
  }
}

}  // namespace pr
