#include "cl/kernel_binding.h"

#include <string>

#include "util/error.h"

namespace pr::kargs {

namespace {

std::string argLabel(const char* kernelName, size_t index, const char* name) {
  return std::string("kernel ") + kernelName + ": argument " + std::to_string(index) + " (" + name +
         ")";
}

}  // namespace

void checkKernelArgs(const cl::Kernel& kernel, const char* kernelName, const ArgSpec* specs,
                     size_t count) {
  cl_uint built = 0;
  CL_CHECK(kernel.getInfo(CL_KERNEL_NUM_ARGS, &built));
  if (built != count)
    throw RuntimeError(std::string("kernel ") + kernelName + " takes " + std::to_string(built) +
                       " arguments, its table in kernels/shared/kernel_args.h lists " +
                       std::to_string(count));
  for (size_t i = 0; i < count; ++i) {
    const ArgSpec& s = specs[i];
    std::string name, type;
    // Platforms may keep no argument info (a binary from another build, or none at all).
    if (kernel.getArgInfo(cl_uint(i), CL_KERNEL_ARG_NAME, &name) != CL_SUCCESS ||
        kernel.getArgInfo(cl_uint(i), CL_KERNEL_ARG_TYPE_NAME, &type) != CL_SUCCESS)
      return;
    cl_kernel_arg_address_qualifier space = 0;
    cl_kernel_arg_type_qualifier qualifiers = 0;
    CL_CHECK(kernel.getArgInfo(cl_uint(i), CL_KERNEL_ARG_ADDRESS_QUALIFIER, &space));
    CL_CHECK(kernel.getArgInfo(cl_uint(i), CL_KERNEL_ARG_TYPE_QUALIFIER, &qualifiers));
    // Some platforms pad the strings they return with a NUL.
    while (!name.empty() && name.back() == '\0') name.pop_back();
    while (!type.empty() && type.back() == '\0') type.pop_back();
    const bool buffer = s.kind != Kind::Val;
    const bool wantConst = s.kind == Kind::In;
    std::string wrong;
    if (name != s.name)
      wrong = "is named " + name + " in the kernel";
    else if (type != s.type)
      wrong = "has type " + type + " in the kernel, " + s.type + " in the table";
    else if (buffer != (space == CL_KERNEL_ARG_ADDRESS_GLOBAL))
      wrong = buffer ? "is not a __global buffer in the kernel" : "is a buffer in the kernel";
    else if (buffer && wantConst != ((qualifiers & CL_KERNEL_ARG_TYPE_CONST) != 0))
      wrong = wantConst ? "is not const in the kernel (the table says IN)"
                        : "is const in the kernel (the table says OUT)";
    if (!wrong.empty())
      throw RuntimeError(argLabel(kernelName, i, s.name) + " " + wrong +
                         " (kernels/shared/kernel_args.h)");
  }
}

}  // namespace pr::kargs
