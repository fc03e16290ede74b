// libFuzzer target for the glTF loader: any bytes, as .gltf text or GLB, must either load or
// fail with one pr::InputError. Any other exception, a crash, a sanitizer report, a timeout or
// an allocation beyond -rss_limit_mb is a finding. Built by -DPATHREUSE_FUZZ=ON (clang);
// run by tools/fuzz/fuzz.sh.
//
// Structure-aware: an input that parses as JSON is mutated as a glTF document (a number set to
// an edge value, an index moved past its array, an array emptied or grown, a member dropped or
// given another type, a URI pointed outside, nesting deepened), so the loader's index, range and
// limit checks are reached far more often than byte flips reach them. Other inputs (GLB, broken
// JSON) get libFuzzer's own mutations.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/gltf_loader.h"
#include "util/error.h"

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t maxSize);

namespace {

using nlohmann::json;

// Every value in the document, depth first, as pointers (the document outlives the list).
void collect(json& j, std::vector<json*>* out, int depth) {
  out->push_back(&j);
  if (depth > 64) return;
  if (j.is_object() || j.is_array())
    for (auto& v : j) collect(v, out, depth + 1);
}

json edgeNumber(std::mt19937& rng) {
  static const double values[] = {
      0.0,          -1.0,         1.0,           2.0,    3.0,    4.0,     255.0,  65535.0,
      4294967295.0, 2147483647.0, -2147483648.0, 1e38,   3e38,   -3e38,   1e-45,  0.5,
      5120.0,       5121.0,       5123.0,        5125.0, 5126.0, 34962.0, 34963.0};
  const size_t n = sizeof values / sizeof values[0];
  const double v = values[rng() % n];
  if (std::fabs(v) < 9e18 && v == std::floor(v) && rng() % 2) return int64_t(v);
  return v;
}

void mutateValue(json* v, std::mt19937& rng, const json& doc) {
  switch (rng() % 9) {
    case 0:
      *v = edgeNumber(rng);
      break;
    case 1:
      if (v->is_number_integer())
        *v = v->get<int64_t>() + int64_t(rng() % 5) - 2;
      else
        *v = edgeNumber(rng);
      break;
    case 2:  // another type
      *v = rng() % 3 == 0 ? json("x") : rng() % 2 ? json::array() : json::object();
      break;
    case 3:  // an array emptied, or one of its elements repeated
      if (v->is_array() && !v->empty()) {
        if (rng() % 2)
          v->clear();
        else
          v->push_back((*v)[rng() % v->size()]);
      } else {
        *v = json::array({edgeNumber(rng)});
      }
      break;
    case 4:  // a member dropped
      if (v->is_object() && !v->empty()) {
        auto it = v->begin();
        std::advance(it, long(rng() % v->size()));
        v->erase(it.key());
      }
      break;
    case 5: {  // a URI that leaves the folder, names a device, or is a bad data: URI
      static const char* uris[] = {"../outside.bin",
                                   "%2e%2e/%2e%2e/etc/passwd",
                                   "/dev/zero",
                                   "/etc/passwd",
                                   "data:application/octet-stream;base64,AAAA",
                                   "data:image/png;base64,iVBORw0KGgo=",
                                   "",
                                   "."};
      *v = uris[rng() % (sizeof uris / sizeof uris[0])];
      break;
    }
    case 6: {  // nested deeper
      json inner = *v;
      const int levels = 1 + int(rng() % 300);
      for (int i = 0; i < levels; ++i) inner = json::array({inner});
      *v = inner;
      break;
    }
    case 7:  // a value copied from elsewhere in the document (indices, accessors, whole objects)
      if (v->is_number() && doc.is_object() && doc.contains("nodes") && doc["nodes"].is_array())
        *v = int64_t(doc["nodes"].size()) - int64_t(rng() % 2);
      else
        *v = nullptr;
      break;
    default:
      if (v->is_number())
        *v = -v->get<double>();
      else
        *v = edgeNumber(rng);
      break;
  }
}

}  // namespace

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t maxSize,
                                          unsigned int seed) {
  std::mt19937 rng(seed);
  json doc = json::parse(data, data + size, nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || rng() % 8 == 0)
    return LLVMFuzzerMutate(data, size, maxSize);
  const int edits = 1 + int(rng() % 3);
  for (int e = 0; e < edits; ++e) {
    std::vector<json*> values;
    collect(doc, &values, 0);
    mutateValue(values[rng() % values.size()], rng, doc);
  }
  const std::string out = doc.dump();
  if (out.size() > maxSize) return LLVMFuzzerMutate(data, size, maxSize);
  std::memcpy(data, out.data(), out.size());
  return out.size();
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  // The name decides text or GLB only when the GLB magic is absent; external URIs resolve in
  // a folder that does not exist, so no file outside the input is ever read.
  const char* name = "/nonexistent-pathreuse-fuzz/input.gltf";
  pr::LoadOptions options;
  options.printWarnings = false;
  try {
    // What `info` and the renderer derive from any scene that loads: the emitting triangles,
    // weighed by their emission textures' texels (scene/emission_power.h).
    const pr::Scene scene = pr::loadSceneFromMemory(bytes, name, options);
    (void)scene.emissiveTriangleCount();
  } catch (const pr::InputError&) {
    // Broken input, reported as it should be.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gltf_fuzzer: unexpected exception: %s\n", e.what());
    std::abort();
  }
  return 0;
}
