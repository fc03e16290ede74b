// The host's side of the kernel tables (kernels/shared/kernel_args.h): per kernel, a struct with
// one member per parameter (cl::Buffer for IN/OUT, the value's type for VAL) that sets the
// kernel's arguments in table order, and the table itself, which checkKernelArgs compares with
// what the built kernel reports.
#pragma once

#include <cstddef>
#include <string>

#include "cl/cl.h"
#include "cl/context.h"
#include "cl/cl_check.h"
#include "shared/camera.h"
#include "shared/kernel_args.h"
#include "shared/reuse.h"

namespace pr {

// Sets consecutive arguments of `kernel` from index `first` on; returns the index after the
// last one set. For the test and benchmark kernels, which have no table.
template <typename... Args>
cl_uint setKernelArgs(cl::Kernel& kernel, cl_uint first, const Args&... args) {
  (CL_CHECK(kernel.setArg(first++, args)), ...);
  return first;
}

namespace kargs {

using namespace pr::dev;  // the tables name shared types unqualified
using uint = cl_uint;

// When an argument changes; a set of them selects what ArgsStruct::set writes.
enum Role : unsigned { kScene = 1u, kFrame = 2u, kPass = 4u, kAllRoles = 7u };
enum class Kind { In, Out, Val };

struct ArgSpec {
  Role role;
  Kind kind;
  const char* type;  // as clGetKernelArgInfo names it: "uint", "ReuseParams", "EyeVertex*"
  const char* name;
};

#define PR_KARG_STR_(x) #x
#define PR_KARG_STR(x) PR_KARG_STR_(x)
#define PR_KARG_ROLE_GEOM kScene
#define PR_KARG_ROLE_SHADING kScene
#define PR_KARG_ROLE_LIGHTS kScene
#define PR_KARG_ROLE_FRAME kFrame
#define PR_KARG_ROLE_PASS kPass
#define PR_KARG_KIND_IN Kind::In
#define PR_KARG_KIND_OUT Kind::Out
#define PR_KARG_KIND_VAL Kind::Val
#define PR_KARG_HOST_IN(type) cl::Buffer
#define PR_KARG_HOST_OUT(type) cl::Buffer
#define PR_KARG_HOST_VAL(type) type
#define PR_KARG_TYPE_IN(type) #type "*"
#define PR_KARG_TYPE_OUT(type) #type "*"
#define PR_KARG_TYPE_VAL(type) #type
#define PR_KARG_MEMBER_(role, kind, type, name) PR_KARG_HOST_##kind(type) PR_ARG_NAME(role, name){};
#define PR_KARG_SPEC_(role, kind, type, name)                                  \
  ArgSpec{PR_KARG_ROLE_##role, PR_KARG_KIND_##kind, PR_KARG_TYPE_##kind(type), \
          PR_KARG_STR(PR_ARG_NAME(role, name))},
#define PR_KARG_SET_(role, kind, type, name)                                                \
  if (roles & PR_KARG_ROLE_##role) CL_CHECK(kernel.setArg(index, PR_ARG_NAME(role, name))); \
  ++index;
#define PR_KARG_COPY_(role, kind, type, name) \
  to->PR_ARG_NAME(role, name) = from.PR_ARG_NAME(role, name);

// struct ConnectArgs { cl::Buffer pr_g_static_nodes; ...; ReuseParams rp; uint sample; ... }
#define PR_KARG_STRUCT_(kernelName, Struct, table)                                             \
  struct Struct {                                                                              \
    static constexpr const char* kKernel = #kernelName;                                        \
    static constexpr ArgSpec kSpecs[] = {table(PR_KARG_SPEC_, PR_KARG_SPEC_)};                 \
    static constexpr size_t kCount = sizeof(kSpecs) / sizeof(kSpecs[0]);                       \
    table(PR_KARG_MEMBER_, PR_KARG_MEMBER_) /* Sets the arguments whose role is in `roles`. */ \
        void set(cl::Kernel& kernel, unsigned roles = kAllRoles) const {                       \
      cl_uint index = 0;                                                                       \
      table(PR_KARG_SET_, PR_KARG_SET_)                                                        \
    }                                                                                          \
  };
PR_KERNEL_TABLES(PR_KARG_STRUCT_)
PR_KARG_STRUCT_(scene, SceneArgs, PR_ARGS_SCENE)

// Copies the scene's members into a kernel's argument struct.
template <class KernelArgs>
void setScene(KernelArgs* to, const SceneArgs& from) {
  PR_ARGS_SCENE(PR_KARG_COPY_, PR_KARG_COPY_)
}

// Every table, for tests: (kernel name, specs, count).
struct TableEntry {
  const char* kernel;
  const ArgSpec* specs;
  size_t count;
};
#define PR_KARG_ENTRY_(kernelName, Struct, table) \
  TableEntry{Struct::kKernel, Struct::kSpecs, Struct::kCount},
inline constexpr TableEntry kTables[] = {PR_KERNEL_TABLES(PR_KARG_ENTRY_)};

// Compares the built `kernel` with its table: the argument count always, and where the
// platform reports argument info (programs are built with -cl-kernel-arg-info), each
// argument's name, type, address space and constness. Throws RuntimeError, one line naming the
// kernel and the first argument that differs.
void checkKernelArgs(const cl::Kernel& kernel, const char* kernelName, const ArgSpec* specs,
                     size_t count);

template <class KernelArgs>
void checkKernelArgs(const cl::Kernel& kernel) {
  checkKernelArgs(kernel, KernelArgs::kKernel, KernelArgs::kSpecs, KernelArgs::kCount);
}

// The kernel of KernelArgs from kernels/<file>, built with `options` and checked.
template <class KernelArgs>
cl::Kernel kernel(Context& ctx, const std::string& file, const std::string& options = "") {
  cl::Kernel k = ctx.kernel(file, KernelArgs::kKernel, options);
  checkKernelArgs<KernelArgs>(k);
  return k;
}

}  // namespace kargs
}  // namespace pr
