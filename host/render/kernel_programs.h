// The OpenCL programs pathreuse builds and the -D options they are built with, in one place: the
// renderer takes its options from here, and the conformance gate (tools/ci/kernel-conformance.sh)
// checks every program in every variant listed here with a strict OpenCL C 1.2 compiler.
#pragma once

#include <string>
#include <vector>

namespace pr {

// What a scene's programs are compiled for (GpuScene::buildOptions).
struct KernelFeatures {
  int bvhWidth = 4;                                                     // 2, 4 or 8
  bool alpha = false, sheen = false, coat = false, anisotropy = false;  // of any material
  bool terminatorOffset = true;
  bool gltfModel = false;  // --material-model gltf-reference
  int lightSampler = 0;    // PR_LIGHT_SAMPLER_* (shared/lights.h)
};

// The -D options of a scene's programs.
std::string kernelBuildOptions(const KernelFeatures& f);

// The techniques a stage's program is built with (kernels/shared/techniques.h): its hooks are
// compiled in where they are on, and absent where off.
struct Techniques {
  bool eyePaths = false;  // PR_EYE_PATHS: eye paths weighted against the connections
  bool resample = false;  // PR_RESAMPLE: path and direct-light resampling
};

// The -D options of the techniques, to append to a scene's (empty where none is on).
std::string techniqueBuildOptions(const Techniques& t);
// The shared helpers' device test (tests/shared_device_test.cpp): every BSDF feature.
inline constexpr const char* kSharedCheckOptions =
    "-DPR_HAS_SHEEN=1 -DPR_HAS_COAT=1 -DPR_HAS_ANISOTROPY=1 -DPR_HAS_GLTF_MODEL=1 "
    "-DPR_HAS_ENERGY_MODEL=1";
// Oclgrind's LLVM lacks llvm.bitreverse (tools/ci/oclgrind-check.sh sets it).
inline constexpr const char* kBitreverseTableOption = "-DPR_BITREVERSE_TABLE";

struct KernelProgram {
  std::string file;     // under kernels/
  std::string options;  // as passed to clBuildProgram, less -cl-std and -cl-kernel-arg-info
};

// Every program the renderer and the tests build, each in enough variants that every value of
// every option is taken at least once and every feature both on and off.
std::vector<KernelProgram> kernelProgramVariants();

}  // namespace pr
