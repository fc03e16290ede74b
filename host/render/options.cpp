#include "render/options.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "util/error.h"

namespace pr {

int defaultBvhWidth(bool gpu) {
  // 4 on GPUs: on an H200 it traced 24-33% more rays per second than 2 (and than 8 in incoherent
  // rays) and kept connect's registers in check where 8 slowed reuse by a fifth
  // (docs/experiments/bvh-width.md).
  return gpu ? 4 : 8;
}

int defaultConnections(bool gpu) {
  // Measured with tools/bench/bench_connections.py (docs/experiments/resampled-connections.md): on
  // an H200 two resampled connections reached a given error 1.6-2.0x sooner than tracing every
  // candidate; on a CPU (PoCL) tracing all was 1.15x better on the demo scenes and 1.2x worse on
  // the atrium.
  return gpu ? 2 : 0;
}

ResampleSettings resolveResample(const RenderOptions& o) {
  ResampleSettings r = o.resample;
  const bool reuse = o.mode != RenderMode::PathTrace;
  // Off by default under a shutter: there it lowered reuse's error 12-36% at 4 spp but cost more
  // than that on a CPU (relMSE x s 0.81-1.03x of reuse without it; bench_shutter_reuse).
  r.enabled = r.asked.value_or(reuse && o.connect.eyePaths && !(o.shutter > 0.0));
  if (r.neighbors < 0) r.neighbors = reuse ? 0 : 1;
  return r;
}

bool resolveLightTracing(const RenderOptions& o) {
  return o.connect.lightTracing.value_or(o.mode != RenderMode::PathTrace && o.connect.eyePaths);
}

const char* renderModeName(RenderMode m) {
  switch (m) {
    case RenderMode::Reuse:
      return "reuse";
    case RenderMode::Retrace:
      return "retrace";
    case RenderMode::PathTrace:
      return "pathtrace";
  }
  return "?";
}

const char* materialModelName(MaterialModel m) {
  return m == MaterialModel::Gltf ? "gltf-reference" : "energy";
}

namespace {

// A whole number 0 .. INT_MAX (a frame number: 2^31 - 1 frames are 2.8 years at 24 fps).
// A frame number: decimal digits, from 0 to kMaxFrame.
bool parseFrameNumber(const std::string& s, int64_t* out) {
  if (s.empty() || s.size() > 19) return false;
  for (char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  const unsigned long long v = std::stoull(s);
  if (v > static_cast<unsigned long long>(kMaxFrame)) return false;
  *out = static_cast<int64_t>(v);
  return true;
}

// Finds the single integer conversion: its position and length. Returns false if malformed.
bool findConversion(const std::string& p, size_t* pos, size_t* len, std::string* why) {
  int found = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    if (p[i] != '%') continue;
    if (i + 1 < p.size() && p[i + 1] == '%') {
      ++i;
      continue;
    }
    size_t j = i + 1;
    while (j < p.size() && (p[j] == '0' || p[j] == '-' || p[j] == '+' || p[j] == ' ')) ++j;
    size_t digits = 0;
    while (j < p.size() && std::isdigit(static_cast<unsigned char>(p[j]))) ++j, ++digits;
    if (digits > 2) {
      *why = "field width too large";
      return false;
    }
    if (j >= p.size() || (p[j] != 'd' && p[j] != 'i' && p[j] != 'u')) {
      *why = "only an integer conversion such as %04d is allowed";
      return false;
    }
    ++found;
    *pos = i;
    *len = j - i + 1;
    i = j;
  }
  if (found != 1) {
    *why = found == 0 ? "no frame number conversion such as %04d"
                      : "more than one frame number conversion";
    return false;
  }
  return true;
}

}  // namespace

FrameRange parseFrameRange(const std::string& text) {
  FrameRange r;
  const size_t dash = text.find('-');
  bool ok;
  if (dash == std::string::npos) {
    ok = parseFrameNumber(text, &r.first);
    r.last = r.first;
  } else {
    ok = parseFrameNumber(text.substr(0, dash), &r.first) &&
         parseFrameNumber(text.substr(dash + 1), &r.last);
  }
  if (!ok)
    throw InputError("--frames " + text + ": expected A-B or A, with whole numbers from 0 to " +
                     std::to_string(kMaxFrame));
  if (r.last < r.first)
    throw InputError("--frames " + text + ": the last frame is before the first");
  return r;
}

void validateOutPattern(const std::string& pattern) {
  size_t pos = 0, len = 0;
  std::string why;
  if (!findConversion(pattern, &pos, &len, &why)) throw InputError("--out " + pattern + ": " + why);
  if (std::filesystem::path(pattern).filename().empty())
    throw InputError("--out " + pattern + ": names a folder, not a file");
}

std::string formatOutPath(const std::string& pattern, int64_t frame) {
  size_t pos = 0, len = 0;
  std::string why;
  if (!findConversion(pattern, &pos, &len, &why)) throw InputError("--out " + pattern + ": " + why);
  char buf[64];
  const std::string conv = pattern.substr(pos, len - 1) + "lld";
  std::snprintf(buf, sizeof buf, conv.c_str(), static_cast<long long>(frame));
  std::string out;
  // Unescape %% outside the conversion.
  auto unescape = [](const std::string& s) {
    std::string r;
    for (size_t i = 0; i < s.size(); ++i) {
      r += s[i];
      if (s[i] == '%' && i + 1 < s.size() && s[i + 1] == '%') ++i;
    }
    return r;
  };
  return unescape(pattern.substr(0, pos)) + buf + unescape(pattern.substr(pos + len));
}

std::string withExtension(const std::string& path, const std::string& ext) {
  std::filesystem::path p(path);
  p.replace_extension(ext);
  return p.string();
}

void parseColor(const std::string& text, float rgb[3]) {
  const std::string bad = "--env-color " + text + ": must be R,G,B (three numbers, 0 or more)";
  size_t pos = 0;
  for (int c = 0; c < 3; ++c) {
    const size_t end = c < 2 ? text.find(',', pos) : text.size();
    if (end == std::string::npos) throw InputError(bad);
    const std::string part = text.substr(pos, end - pos);
    char* stop = nullptr;
    const float v = std::strtof(part.c_str(), &stop);
    if (part.empty() || stop != part.c_str() + part.size() || !std::isfinite(v) || v < 0.0f)
      throw InputError(bad);
    rgb[c] = v;
    pos = end + 1;
  }
}

}  // namespace pr
