#include "render/history_format.h"

#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>

#include "util/check.h"
#include "util/hash.h"

namespace pr {

namespace {

constexpr char kHistoryMagic[8] = {'P', 'R', 'H', 'I', 'S', 'T', '2', '\0'};

size_t chainBytes(const HistoryHeader& h) {
  return size_t(h.end - h.first) * h.record;
}

// The largest number a record may hold: a product of two stays finite in float.
constexpr float kMaxRecordValue = 1e18f;

bool finiteIn(float x, float lo, float hi) {
  return std::isfinite(x) && x >= lo && x <= hi;
}

// Every field of a record, in order, with its check.
// clang-format off
#define PR_RECORD_FIELDS(X)                                                             \
  X(r.prim, Surface) X(r.inst, Surface) X(r.b1, Bary) X(r.b2, Bary)                     \
  X(r.wx, Finite) X(r.wy, Finite) X(r.wz, Finite)                                       \
  X(r.g_src, Bounded) X(r.rest_r, Bounded) X(r.rest_g, Bounded) X(r.rest_b, Bounded)    \
  X(r.pdf_light, Bounded)                                                               \
  X(r.f_r, Reservoir) X(r.f_g, Reservoir) X(r.f_b, Reservoir) X(r.kind, Kind)           \
  X(r.p_hat, Reservoir) X(r.w_sum, Reservoir) X(r.m, Reservoir)                         \
  X(r.suffix, Suffix) X(r.sp, Finite) X(r.rn, Finite) X(r.rh, Finite)                   \
  X(d.light, Light) X(d.b1, Bary) X(d.b2, Bary) X(d.wx, Finite) X(d.wy, Finite)         \
  X(d.wz, Finite) X(d.f_r, Reservoir) X(d.f_g, Reservoir) X(d.f_b, Reservoir)           \
  X(d.p_hat, Reservoir) X(d.w_sum, Reservoir) X(d.m, Reservoir)                         \
  X(prim, Surface) X(inst, Surface) X(b1, Bary) X(b2, Bary)                             \
  X(wx, Finite) X(wy, Finite) X(wz, Finite) X(stamp, Any)
// clang-format on

#define PR_FIELD_SIZE(field, check) +sizeof(dev::PathHistory::field)
static_assert(0 PR_RECORD_FIELDS(PR_FIELD_SIZE) == sizeof(dev::PathHistory),
              "every field of a history record is listed in PR_RECORD_FIELDS with its check");
#undef PR_FIELD_SIZE

// A reservoir's numbers: its path's value f (per channel), target p_hat, weight sum w_sum and
// confidence m are non-negative and bounded, and so is what the kernels make of them, f w_sum /
// p_hat (its unbiased contribution).
bool validReservoir(const float f[3], float p_hat, float w_sum, float m) {
  for (int c = 0; c < 3; ++c)
    if (!finiteIn(f[c], 0.0f, kMaxRecordValue)) return false;
  if (!finiteIn(p_hat, 0.0f, kMaxRecordValue) || !finiteIn(w_sum, 0.0f, kMaxRecordValue) ||
      !finiteIn(m, 0.0f, kMaxRecordValue))
    return false;
  if (p_hat == 0.0f) return true;
  const float weight = w_sum / p_hat;
  for (int c = 0; c < 3; ++c)
    if (!finiteIn(f[c] * weight, 0.0f, kMaxRecordValue)) return false;
  return true;
}

// Barycentrics of a point on a triangle.
bool validBarycentrics(float b1, float b2) {
  const float slack = 1e-3f;
  return finiteIn(b1, -slack, 1.0f + slack) && finiteIn(b2, -slack, 1.0f + slack) &&
         b1 + b2 <= 1.0f + slack;
}

bool validKind(uint32_t kind) {
  const uint32_t base = kind & PR_RS_KIND_MASK;
  const uint32_t flags = PR_RS_JOINED | PR_RS_LAST2 | PR_RS_CAMERA | PR_RS_NO_L;
  return (base == PR_RS_DEEP || base == PR_RS_NEE2 || base == PR_RS_HIT2) &&
         (kind & ~(PR_RS_KIND_MASK | flags)) == 0u &&
         ((kind & PR_RS_NO_L) == 0u || (kind & PR_RS_JOINED) != 0u);  // only on a joined path
}

// The checks of one field alone; the relational ones (Reservoir, Surface, Light, Bary) follow in
// validRecord.
bool validField(const char* record, const RecordField& field) {
  const char* at = record + field.offset;
  auto floats = [&](float lo, float hi) {
    for (size_t i = 0; i < field.size / sizeof(float); ++i) {
      float x;
      std::memcpy(&x, at + i * sizeof x, sizeof x);
      if (!finiteIn(x, lo, hi)) return false;
    }
    return true;
  };
  uint32_t u = 0;
  if (field.size == sizeof u) std::memcpy(&u, at, sizeof u);
  switch (field.check) {
    case RecordCheck::Finite:
      return floats(-std::numeric_limits<float>::max(), std::numeric_limits<float>::max());
    case RecordCheck::Bounded:
      return floats(0.0f, kMaxRecordValue);
    case RecordCheck::Kind:
      return validKind(u);
    case RecordCheck::Suffix:
      return (u & PR_RS_COUNT_MASK) <= PR_RS_SUFFIX;
    default:
      return true;
  }
}

// A record the kernels can read safely and sum into a frame without overflow: its surfaces in
// the scene, its numbers finite, its values, weights and pdfs non-negative and bounded.
bool validRecord(const char* record, const HistoryScene& scene) {
  for (const RecordField& field : historyRecordFields())
    if (!validField(record, field)) return false;
  dev::PathHistory h;
  std::memcpy(&h, record, sizeof h);
  const dev::DirectReservoir& d = h.d;
  const float df[3] = {d.f_r, d.f_g, d.f_b};
  if (!validReservoir(df, d.p_hat, d.w_sum, d.m)) return false;
  if (d.light != PR_INVALID_INDEX && (d.light >= scene.lights || !validBarycentrics(d.b1, d.b2)))
    return false;
  const dev::PathReservoir& r = h.r;
  const float rf[3] = {r.f_r, r.f_g, r.f_b};
  if (!validReservoir(rf, r.p_hat, r.w_sum, r.m)) return false;
  if (h.prim != PR_INVALID_INDEX &&
      (!scene.validSurface(h.prim, h.inst) || !validBarycentrics(h.b1, h.b2)))
    return false;
  return r.prim == PR_INVALID_INDEX ||
         (scene.validSurface(r.prim, r.inst) && validBarycentrics(r.b1, r.b2));
}

}  // namespace

const std::vector<RecordField>& historyRecordFields() {
#define PR_FIELD_ENTRY(field, check)                                                      \
  RecordField{#field, offsetof(dev::PathHistory, field), sizeof(dev::PathHistory::field), \
              RecordCheck::check},
  static const std::vector<RecordField> fields = {PR_RECORD_FIELDS(PR_FIELD_ENTRY)};
#undef PR_FIELD_ENTRY
  return fields;
}

std::string beginHistoryPart(HistoryHeader h) {
  std::memcpy(h.magic, kHistoryMagic, sizeof h.magic);
  h.record = sizeof(dev::PathHistory);
  PR_CHECK(h.end >= h.first);
  std::string out(sizeof h + chainBytes(h) * h.chains + sizeof(uint64_t), '\0');
  std::memcpy(&out[0], &h, sizeof h);
  return out;
}

char* historyRecords(std::string* part, uint32_t chain) {
  HistoryHeader h{};
  std::memcpy(&h, part->data(), sizeof h);
  PR_CHECK(chain < h.chains);
  return &(*part)[sizeof h + chain * chainBytes(h)];
}

const char* historyRecords(const std::string& part, uint32_t chain) {
  HistoryHeader h{};
  std::memcpy(&h, part.data(), sizeof h);
  PR_CHECK(chain < h.chains);
  return part.data() + sizeof h + chain * chainBytes(h);
}

void sealHistoryPart(std::string* part) {
  HistoryHeader h{};
  std::memcpy(&h, part->data(), sizeof h);
  const uint64_t check = Hash128().add(part->data() + sizeof h, chainBytes(h) * h.chains).low();
  std::memcpy(&(*part)[part->size() - sizeof check], &check, sizeof check);
}

bool checkHistoryPart(const std::string& part, const HistoryLayout& want, const HistoryScene& scene,
                      HistoryHeader* out) {
  HistoryHeader h{};
  if (part.size() < sizeof h) return false;
  std::memcpy(&h, part.data(), sizeof h);
  if (std::memcmp(h.magic, kHistoryMagic, sizeof h.magic) != 0 || h.key != want.key ||
      h.frame != want.frame || h.chains != want.chains || h.first != want.first ||
      h.end != want.end || h.end < h.first || h.record != sizeof(dev::PathHistory))
    return false;
  const size_t bytes = chainBytes(h);
  if (part.size() != sizeof h + bytes * h.chains + sizeof(uint64_t)) return false;
  uint64_t check = 0;
  std::memcpy(&check, part.data() + part.size() - sizeof check, sizeof check);
  if (Hash128().add(part.data() + sizeof h, bytes * h.chains).low() != check) return false;
  for (size_t k = 0; k < bytes * h.chains; k += h.record)
    if (!validRecord(part.data() + sizeof h + k, scene)) return false;
  *out = h;
  return true;
}

std::string packHistoryFile(const std::vector<int>& split, const std::vector<std::string>& parts) {
  PR_CHECK(split.size() == parts.size());
  std::string out;
  const auto put = [&out](const auto& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof v);
  };
  put(uint32_t(parts.size()));
  for (int p : split) put(int32_t(p));
  for (const std::string& part : parts) {
    put(uint64_t(part.size()));
    out += part;
  }
  return out;
}

bool unpackHistoryFile(const std::string& data, size_t devices, std::vector<int>* split,
                       std::vector<std::string>* parts) {
  size_t at = 0;
  const auto get = [&](auto* v) {
    if (data.size() - at < sizeof *v) return false;
    std::memcpy(v, data.data() + at, sizeof *v);
    at += sizeof *v;
    return true;
  };
  uint32_t count = 0;
  if (!get(&count) || count != devices) return false;
  split->assign(devices, 0);
  for (int& p : *split) {
    int32_t v = 0;
    if (!get(&v) || v < 0 || v > 1 << 20) return false;
    p = v;
  }
  parts->assign(devices, std::string());
  for (std::string& part : *parts) {
    uint64_t n = 0;
    if (!get(&n) || n > data.size() - at) return false;
    part = data.substr(at, n);
    at += n;
  }
  return at == data.size();
}

}  // namespace pr
