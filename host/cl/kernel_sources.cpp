#include "cl/kernel_sources.h"

#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "util/error.h"

namespace pr {

std::string readKernelFile(const std::string& path) {
  if (const char* dir = std::getenv(kKernelDirEnv); dir && *dir) {
    const std::string full = std::string(dir) + "/" + path;
    std::ifstream in(full, std::ios::binary);
    if (!in) throw RuntimeError(full + ": kernel source not found (" + kKernelDirEnv + " is set)");
    std::ostringstream os;
    os << in.rdbuf();
    return os.str();
  }
  for (const auto& s : embeddedKernelSources())
    if (path == s.path) return std::string(s.data, s.size);
  throw RuntimeError("kernel source '" + path + "' is not embedded in this build");
}

namespace {

void expandInto(const std::string& path, std::set<std::string>& seen, std::string& out, int depth) {
  if (depth > 32) throw RuntimeError("kernel source '" + path + "': includes nested too deeply");
  if (!seen.insert(path).second) return;  // every header is included once
  const std::string text = readKernelFile(path);
  std::istringstream in(text);
  std::string line;
  int lineNo = 0;
  out += "#line 1 \"" + path + "\"\n";
  while (std::getline(in, line)) {
    ++lineNo;
    size_t p = line.find_first_not_of(" \t");
    if (p != std::string::npos && line.compare(p, 8, "#include") == 0) {
      const size_t q1 = line.find('"', p);
      const size_t q2 = q1 == std::string::npos ? q1 : line.find('"', q1 + 1);
      if (q2 != std::string::npos) {
        expandInto(line.substr(q1 + 1, q2 - q1 - 1), seen, out, depth + 1);
        out += "#line " + std::to_string(lineNo + 1) + " \"" + path + "\"\n";
        continue;
      }
    }
    // `#pragma once` means nothing to a single expanded string; the set above does its job.
    if (p != std::string::npos && line.compare(p, 12, "#pragma once") == 0) {
      out += "\n";
      continue;
    }
    out += line;
    out += '\n';
  }
}

}  // namespace

std::string expandKernelSource(const std::string& path) {
  std::set<std::string> seen;
  std::string out;
  expandInto(path, seen, out, 0);
  return out;
}

}  // namespace pr
