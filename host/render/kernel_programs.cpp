#include "render/kernel_programs.h"

#include "shared/lights.h"

namespace pr {

std::string kernelBuildOptions(const KernelFeatures& f) {
  std::string o = "-DPR_BVH_WIDTH=" + std::to_string(f.bvhWidth);
  if (f.alpha) o += " -DPR_HAS_ALPHA=1";
  if (f.sheen) o += " -DPR_HAS_SHEEN=1";
  if (f.coat) o += " -DPR_HAS_COAT=1";
  if (f.anisotropy) o += " -DPR_HAS_ANISOTROPY=1";
  if (!f.terminatorOffset) o += " -DPR_TERMINATOR_OFFSET=0";
  if (f.gltfModel) o += " -DPR_HAS_GLTF_MODEL=1 -DPR_HAS_ENERGY_MODEL=0";
  // One value picks the receivers' light sampler; the kernels compile all three (shared/lights.h).
  o += " -DPR_LIGHT_SAMPLER=" + std::to_string(f.lightSampler);
  return o;
}

std::string techniqueBuildOptions(const Techniques& t) {
  std::string o;
  if (t.eyePaths) o += " -DPR_EYE_PATHS=1";
  if (t.resample) o += " -DPR_RESAMPLE=1";
  return o;
}

std::vector<KernelProgram> kernelProgramVariants() {
  // Three scene variants between them take each BVH width and light sampler once, and every
  // flag both ways; the first is what the demo scenes build.
  KernelFeatures plain;
  plain.lightSampler = PR_LIGHT_SAMPLER_EXHAUSTIVE;
  KernelFeatures all;
  all.bvhWidth = 2;
  all.alpha = all.sheen = all.coat = all.anisotropy = true;
  all.terminatorOffset = false;
  all.lightSampler = PR_LIGHT_SAMPLER_BVH;
  KernelFeatures gltf = all;
  gltf.bvhWidth = 8;
  gltf.gltfModel = true;
  gltf.terminatorOffset = true;
  gltf.lightSampler = PR_LIGHT_SAMPLER_POWER;
  const std::string bitreverse = std::string(" ") + kBitreverseTableOption;
  std::vector<std::string> scene = {kernelBuildOptions(plain), kernelBuildOptions(all),
                                    kernelBuildOptions(gltf) + bitreverse};

  std::vector<KernelProgram> out;
  for (const char* file :
       {"pathtrace/generate.cl", "pathtrace/extend.cl", "pathtrace/shadow.cl",
        "pathtrace/resample.cl", "reuse/invalidate.cl", "reuse/light_trace.cl", "reuse/eye_hit.cl",
        "reuse/connect_shadow.cl", "reuse/camera_splat.cl", "aov.cl"})
    for (const std::string& o : scene) out.push_back({file, o});
  // The stages with technique hooks, in every combination their integrators build.
  const Techniques none, eye{true, false}, resample{false, true}, both{true, true};
  for (const std::string& o : scene) {
    for (const Techniques& t : {none, eye, resample, both})
      out.push_back({"pathtrace/shade.cl", o + techniqueBuildOptions(t)});
    for (const Techniques& t : {none, eye})
      out.push_back({"reuse/connect.cl", o + techniqueBuildOptions(t)});
  }
  // The film's programs take no scene.
  for (const char* file : {"accumulate.cl", "adaptive.cl"}) {
    out.push_back({file, ""});
    out.push_back({file, kBitreverseTableOption});
  }
  // The tests' own programs.
  for (int width : {2, 4, 8})
    out.push_back({"test/trace.cl", "-DPR_BVH_WIDTH=" + std::to_string(width)});
  for (const char* file : {"test/layout.cl", "test/math_check.cl"}) out.push_back({file, ""});
  out.push_back({"test/shared_check.cl", kSharedCheckOptions});
  out.push_back({"test/smoke.cl", ""});
  out.push_back({"test/smoke.cl", "-DPR_CACHE_PROBE=1"});
  return out;
}

}  // namespace pr
