// kernel_programs: writes every OpenCL program pathreuse builds, in every option variant of
// pr::kernelProgramVariants, as the host expands it (its includes inlined, #line directives
// naming the original files), for tools/ci/kernel-conformance.sh.
//   kernel_programs DIR   ->  DIR/NNN.cl and DIR/programs.tsv (NNN.cl <TAB> kernels/FILE <TAB>
//   options)
// Reads the kernel sources embedded in the build (or PATHREUSE_KERNEL_DIR's, where set).
#include <cstdio>
#include <string>

#include "cl/kernel_sources.h"
#include "render/kernel_programs.h"
#include "util/error.h"
#include "util/files.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: kernel_programs DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  try {
    std::string index;
    int n = 0;
    for (const pr::KernelProgram& p : pr::kernelProgramVariants()) {
      char name[32];
      std::snprintf(name, sizeof name, "%03d.cl", n++);
      pr::writeFileAtomic(dir + "/" + name, pr::expandKernelSource(p.file));
      index += std::string(name) + "\tkernels/" + p.file + "\t" + p.options + "\n";
    }
    pr::writeFileAtomic(dir + "/programs.tsv", index);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kernel_programs: %s\n", e.what());
    return 1;
  }
  return 0;
}
