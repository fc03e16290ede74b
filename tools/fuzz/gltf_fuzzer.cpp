// libFuzzer target for the glTF loader: any bytes, as .gltf text or GLB, must either load or
// fail with one pr::InputError. Any other exception, a crash, a sanitizer report, a timeout or
// an allocation beyond -rss_limit_mb is a finding. Built by -DPATHREUSE_FUZZ=ON (clang);
// run by tools/fuzz.sh.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "scene/gltf_loader.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  // The name decides text or GLB only when the GLB magic is absent; external URIs resolve in
  // a folder that does not exist, so no file outside the input is ever read.
  const char* name = "/nonexistent-pathreuse-fuzz/input.gltf";
  pr::LoadOptions options;
  options.printWarnings = false;
  try {
    (void)pr::loadSceneFromMemory(bytes, name, options);
  } catch (const pr::InputError&) {
    // Broken input, reported as it should be.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gltf_fuzzer: unexpected exception: %s\n", e.what());
    std::abort();
  }
  return 0;
}
