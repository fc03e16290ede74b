// The resume history's formats (docs/design.md section 1, "Resuming"), apart from the devices so
// that they can be checked and fuzzed alone. A part is one device's: a header, the records of its
// chains over the film's rows, a checksum of the records. The file holds the devices' split of
// the sample passes, then each device's part with its size.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "shared/camera.h"
#include "shared/path_state.h"

namespace pr {

struct HistoryHeader {
  char magic[8];
  uint64_t key;  // Hash128 of the caller's key
  int64_t frame;
  uint32_t stamp, chains, first, end, record;
  dev::CameraParams camera;
};

// What a reader expects of a part: its key, frame, chains and film rows.
struct HistoryLayout {
  uint64_t key = 0;
  int64_t frame = 0;
  uint32_t chains = 0, first = 0, end = 0;
};

// What a record may name: the scene's lights (by index) and surfaces (triangle, instance).
struct HistoryScene {
  uint32_t lights = 0;
  std::function<bool(uint32_t prim, uint32_t inst)> validSurface;
};

// How checkHistoryPart checks a field of a record (dev::PathHistory). Each field is named once in
// historyRecordFields, whose sizes add up to the record's (a static_assert), so a field added to
// the record without a check does not build.
enum class RecordCheck {
  Any,        // every value is safe (the stamp)
  Finite,     // floats, each finite (directions, positions, ratios)
  Bounded,    // floats, each in [0, 1e18] (a product of two stays finite)
  Reservoir,  // f, p_hat, w_sum, m: bounded, and so is f w_sum / p_hat
  Surface,    // prim, inst: a triangle of the scene where prim is not PR_INVALID_INDEX
  Light,      // a light of the scene, or PR_INVALID_INDEX
  Bary,       // barycentrics of the surface or light named beside them
  Kind,       // PR_RS_DEEP, _NEE2 or _HIT2 with the flags PR_RS_JOINED, _LAST2, _CAMERA
  Suffix,     // the count of points in sp, at most PR_RS_SUFFIX, with its flags
};
struct RecordField {
  const char* name;
  size_t offset, size;
  RecordCheck check;
};
const std::vector<RecordField>& historyRecordFields();

// A part of h.chains chains of (h.end - h.first) records each, zeroed, under header h (its magic
// and record size set here); historyRecords gives chain c's records to fill, sealHistoryPart then
// writes the checksum.
std::string beginHistoryPart(HistoryHeader h);
char* historyRecords(std::string* part, uint32_t chain);
void sealHistoryPart(std::string* part);

// Whether `part` is a whole part as `want` expects, every record in range (non-negative, bounded,
// finite products, surfaces and lights of `scene`). Its header into *h where it is.
bool checkHistoryPart(const std::string& part, const HistoryLayout& want, const HistoryScene& scene,
                      HistoryHeader* h);
// Chain c's records of a checked part.
const char* historyRecords(const std::string& part, uint32_t chain);

// The file of `parts` (one per device, "" where a device keeps none) and the split of the passes
// (0s where the devices split rows); and back, for `devices` devices: false where the file is
// not whole (another device count, a size past its end, bytes after the last part).
std::string packHistoryFile(const std::vector<int>& split, const std::vector<std::string>& parts);
bool unpackHistoryFile(const std::string& data, size_t devices, std::vector<int>* split,
                       std::vector<std::string>* parts);

}  // namespace pr
