// libFuzzer target for the files pathreuse derives and reads back: the kernel cache's format
// (cl/binary_cache.h) and the resume history's (render/history_format.h). Any bytes must be
// refused or accepted without a crash, a sanitizer report or a hang. What is accepted must hold:
// a cache file packs back to its own bytes; every record of an accepted history part is in
// range, checked here again by what the kernels compute of it (finite, non-negative).
// The first byte picks the target: 0 the cache file, 1 and 2 the history file for one and two
// devices, 3 and 4 the same with each part's checksum made right first, so that the records'
// checks are reached rather than the checksum's; 5 the cache file with its MAC made right first.
// Built by -DPATHREUSE_FUZZ=ON (clang); run by tools/fuzz/fuzz.sh (formats, cache or history).
// FORMAT_FUZZER_SEEDS=DIR writes valid seeds there at start.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "cl/binary_cache.h"
#include "render/history_format.h"
#include "shared/path_state.h"
#include "util/hash.h"

namespace {

using namespace pr;

const std::string kKey = "0123456789abcdef0123456789abcdef";
const std::string kSecret(kCacheSecretBytes, 's');
constexpr uint32_t kRows = 3, kChains = 2;

HistoryLayout layout() {
  HistoryLayout l;
  l.key = Hash128().add(std::string("fuzz")).low();
  l.frame = 1;
  l.chains = kChains;
  l.first = 0;
  l.end = kRows;
  return l;
}

HistoryScene scene() {
  HistoryScene s;
  s.lights = 3;
  s.validSurface = [](uint32_t prim, uint32_t inst) {
    return prim < 50 && (inst == PR_INVALID_INDEX || inst < 2);
  };
  return s;
}

// A part whose header says what it holds but whose checksum may be wrong: made right.
void fixChecksum(std::string* part) {
  HistoryHeader h{};
  if (part->size() < sizeof h + sizeof(uint64_t)) return;
  std::memcpy(&h, part->data(), sizeof h);
  const size_t records = part->size() - sizeof h - sizeof(uint64_t);
  const uint64_t check = Hash128().add(part->data() + sizeof h, records).low();
  std::memcpy(&(*part)[part->size() - sizeof check], &check, sizeof check);
}

void requireUsable(const float f[3], float p_hat, float w_sum) {
  for (int c = 0; c < 3; ++c) {
    const float v = p_hat > 0.0f ? f[c] * (w_sum / p_hat) : 0.0f;
    if (!std::isfinite(v) || v < 0.0f) std::abort();
  }
}

void checkHistory(const std::string& bytes, size_t devices, bool fix) {
  std::vector<int> split;
  std::vector<std::string> parts;
  if (!unpackHistoryFile(bytes, devices, &split, &parts)) return;
  for (std::string& part : parts) {
    if (fix) fixChecksum(&part);
    HistoryHeader h{};
    if (!checkHistoryPart(part, layout(), scene(), &h)) continue;
    for (uint32_t c = 0; c < h.chains; ++c)
      for (uint32_t k = 0; k < h.end - h.first; ++k) {
        dev::PathHistory rec;
        std::memcpy(&rec, historyRecords(part, c) + k * sizeof rec, sizeof rec);
        const float rf[3] = {rec.r.f_r, rec.r.f_g, rec.r.f_b};
        const float df[3] = {rec.d.f_r, rec.d.f_g, rec.d.f_b};
        requireUsable(rf, rec.r.p_hat, rec.r.w_sum);
        requireUsable(df, rec.d.p_hat, rec.d.w_sum);
      }
  }
}

// A valid history part with plausible records (a path kept in some, none in others).
std::string seedPart() {
  HistoryHeader h{};
  h.key = layout().key;
  h.frame = layout().frame;
  h.chains = kChains;
  h.first = 0;
  h.end = kRows;
  std::string part = beginHistoryPart(h);
  for (uint32_t c = 0; c < kChains; ++c)
    for (uint32_t k = 0; k < kRows; ++k) {
      dev::PathHistory rec{};
      rec.prim = k == 0 ? PR_INVALID_INDEX : 3 * k;
      rec.inst = PR_INVALID_INDEX;
      rec.b1 = 0.25f, rec.b2 = 0.5f, rec.wz = 1.0f;
      rec.r.prim = k == 2 ? 7 : PR_INVALID_INDEX;
      rec.r.inst = PR_INVALID_INDEX;
      rec.r.f_r = rec.r.f_g = rec.r.f_b = 0.5f, rec.r.p_hat = 0.5f, rec.r.w_sum = 2.0f;
      rec.r.m = 4.0f, rec.r.rest_r = rec.r.rest_g = rec.r.rest_b = 1.0f, rec.r.g_src = 0.3f;
      rec.d.light = k == 1 ? 2 : PR_INVALID_INDEX;
      rec.d.f_r = 1.0f, rec.d.p_hat = 0.3f, rec.d.w_sum = 1.0f, rec.d.m = 1.0f;
      std::memcpy(historyRecords(&part, c) + k * sizeof rec, &rec, sizeof rec);
    }
  sealHistoryPart(&part);
  return part;
}

void writeSeed(const std::string& dir, const std::string& name, char mode, const std::string& s) {
  std::ofstream(dir + "/" + name, std::ios::binary) << mode << s;
}

// Mode 5: a cache file whose MAC is made right first, so the reader's checks past the MAC run.
void checkCacheWithMac(std::string bytes) {
  constexpr size_t kHeader = 8 + kCacheKeyChars + 8, kMac = 32;
  if (bytes.size() < kHeader + kMac) return;
  const std::string key = bytes.substr(8, kCacheKeyChars), binary = bytes.substr(kHeader + kMac);
  bytes.replace(kHeader, kMac, cacheFileMac(kSecret, key, binary));
  const std::string got = unpackCacheFile(bytes, key, kSecret);
  uint64_t size = 0;
  std::memcpy(&size, bytes.data() + 8 + kCacheKeyChars, sizeof size);
  const bool whole =
      bytes.compare(0, 8, cacheFormatTag()) == 0 && size == binary.size() && !binary.empty();
  if (got != (whole ? binary : std::string())) std::abort();
}

// FORMAT_FUZZER_ONLY=cache or history keeps to one format's modes.
int pickMode(uint8_t byte) {
  static const char* env = std::getenv("FORMAT_FUZZER_ONLY");
  static const std::string only = env ? env : "";
  if (only == "cache") return byte % 2 ? 5 : 0;
  if (only == "history") return 1 + (byte + 3) % 4;  // the seeds' bytes 1-4 keep their modes
  return byte % 6;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* dir = std::getenv("FORMAT_FUZZER_SEEDS"); dir && *dir) {
    writeSeed(dir, "cache", 0, packCacheFile(kKey, std::string(300, 'b'), kSecret));
    writeSeed(dir, "cache-mac", 5, packCacheFile(kKey, std::string(300, 'b'), kSecret));
    const std::string part = seedPart();
    writeSeed(dir, "history-1", 1, packHistoryFile({2}, {part}));
    writeSeed(dir, "history-2", 2, packHistoryFile({1, 1}, {part, part}));
    writeSeed(dir, "history-1-fix", 3, packHistoryFile({2}, {part}));
    writeSeed(dir, "history-2-rows", 4, packHistoryFile({0, 0}, {part, std::string()}));
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  switch (pickMode(data[0])) {
    case 0: {
      const std::string binary = unpackCacheFile(bytes, kKey, kSecret);
      if (!binary.empty() && packCacheFile(kKey, binary, kSecret) != bytes) std::abort();
      break;
    }
    case 1:
      checkHistory(bytes, 1, false);
      break;
    case 2:
      checkHistory(bytes, 2, false);
      break;
    case 3:
      checkHistory(bytes, 1, true);
      break;
    case 4:
      checkHistory(bytes, 2, true);
      break;
    default:
      checkCacheWithMac(bytes);
      break;
  }
  return 0;
}
