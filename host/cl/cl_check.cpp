#include "cl/cl_check.h"

#include <cstring>

namespace pr {

namespace {
const char* knownErrorName(int code) {
  switch (code) {
#define PR_CL_CASE(name, value) \
  case value:                   \
    return #name;
    PR_CL_CASE(CL_SUCCESS, 0)
    PR_CL_CASE(CL_DEVICE_NOT_FOUND, -1)
    PR_CL_CASE(CL_DEVICE_NOT_AVAILABLE, -2)
    PR_CL_CASE(CL_COMPILER_NOT_AVAILABLE, -3)
    PR_CL_CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE, -4)
    PR_CL_CASE(CL_OUT_OF_RESOURCES, -5)
    PR_CL_CASE(CL_OUT_OF_HOST_MEMORY, -6)
    PR_CL_CASE(CL_PROFILING_INFO_NOT_AVAILABLE, -7)
    PR_CL_CASE(CL_MEM_COPY_OVERLAP, -8)
    PR_CL_CASE(CL_IMAGE_FORMAT_MISMATCH, -9)
    PR_CL_CASE(CL_IMAGE_FORMAT_NOT_SUPPORTED, -10)
    PR_CL_CASE(CL_BUILD_PROGRAM_FAILURE, -11)
    PR_CL_CASE(CL_MAP_FAILURE, -12)
    PR_CL_CASE(CL_MISALIGNED_SUB_BUFFER_OFFSET, -13)
    PR_CL_CASE(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST, -14)
    PR_CL_CASE(CL_COMPILE_PROGRAM_FAILURE, -15)
    PR_CL_CASE(CL_LINKER_NOT_AVAILABLE, -16)
    PR_CL_CASE(CL_LINK_PROGRAM_FAILURE, -17)
    PR_CL_CASE(CL_DEVICE_PARTITION_FAILED, -18)
    PR_CL_CASE(CL_KERNEL_ARG_INFO_NOT_AVAILABLE, -19)
    PR_CL_CASE(CL_INVALID_VALUE, -30)
    PR_CL_CASE(CL_INVALID_DEVICE_TYPE, -31)
    PR_CL_CASE(CL_INVALID_PLATFORM, -32)
    PR_CL_CASE(CL_INVALID_DEVICE, -33)
    PR_CL_CASE(CL_INVALID_CONTEXT, -34)
    PR_CL_CASE(CL_INVALID_QUEUE_PROPERTIES, -35)
    PR_CL_CASE(CL_INVALID_COMMAND_QUEUE, -36)
    PR_CL_CASE(CL_INVALID_HOST_PTR, -37)
    PR_CL_CASE(CL_INVALID_MEM_OBJECT, -38)
    PR_CL_CASE(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR, -39)
    PR_CL_CASE(CL_INVALID_IMAGE_SIZE, -40)
    PR_CL_CASE(CL_INVALID_SAMPLER, -41)
    PR_CL_CASE(CL_INVALID_BINARY, -42)
    PR_CL_CASE(CL_INVALID_BUILD_OPTIONS, -43)
    PR_CL_CASE(CL_INVALID_PROGRAM, -44)
    PR_CL_CASE(CL_INVALID_PROGRAM_EXECUTABLE, -45)
    PR_CL_CASE(CL_INVALID_KERNEL_NAME, -46)
    PR_CL_CASE(CL_INVALID_KERNEL_DEFINITION, -47)
    PR_CL_CASE(CL_INVALID_KERNEL, -48)
    PR_CL_CASE(CL_INVALID_ARG_INDEX, -49)
    PR_CL_CASE(CL_INVALID_ARG_VALUE, -50)
    PR_CL_CASE(CL_INVALID_ARG_SIZE, -51)
    PR_CL_CASE(CL_INVALID_KERNEL_ARGS, -52)
    PR_CL_CASE(CL_INVALID_WORK_DIMENSION, -53)
    PR_CL_CASE(CL_INVALID_WORK_GROUP_SIZE, -54)
    PR_CL_CASE(CL_INVALID_WORK_ITEM_SIZE, -55)
    PR_CL_CASE(CL_INVALID_GLOBAL_OFFSET, -56)
    PR_CL_CASE(CL_INVALID_EVENT_WAIT_LIST, -57)
    PR_CL_CASE(CL_INVALID_EVENT, -58)
    PR_CL_CASE(CL_INVALID_OPERATION, -59)
    PR_CL_CASE(CL_INVALID_GL_OBJECT, -60)
    PR_CL_CASE(CL_INVALID_BUFFER_SIZE, -61)
    PR_CL_CASE(CL_INVALID_MIP_LEVEL, -62)
    PR_CL_CASE(CL_INVALID_GLOBAL_WORK_SIZE, -63)
    PR_CL_CASE(CL_INVALID_PROPERTY, -64)
    PR_CL_CASE(CL_INVALID_IMAGE_DESCRIPTOR, -65)
    PR_CL_CASE(CL_INVALID_COMPILER_OPTIONS, -66)
    PR_CL_CASE(CL_INVALID_LINKER_OPTIONS, -67)
    PR_CL_CASE(CL_INVALID_DEVICE_PARTITION_COUNT, -68)
    PR_CL_CASE(CL_INVALID_PIPE_SIZE, -69)
    PR_CL_CASE(CL_INVALID_DEVICE_QUEUE, -70)
    PR_CL_CASE(CL_PLATFORM_NOT_FOUND_KHR, -1001)
#undef PR_CL_CASE
    default:
      return nullptr;
  }
}
}  // namespace

std::string clErrorName(int code) {
  const char* name = knownErrorName(code);
  return name ? std::string(name) : "CL_ERROR(" + std::to_string(code) + ")";
}

namespace {
std::string describe(const std::string& call, int code, const char* file, int line,
                     const std::string& detail) {
  std::string msg = call + " failed with " + clErrorName(code);
  const char* base = std::strrchr(file, '/');
  msg += " at " + std::string(base ? base + 1 : file) + ":" + std::to_string(line);
  if (!detail.empty()) msg += ": " + detail;
  return msg;
}
}  // namespace

ClError::ClError(const std::string& call, int code, const char* file, int line,
                 const std::string& detail)
    : RuntimeError(describe(call, code, file, line, detail)), call_(call), code_(code) {}

void clCheck(int code, const char* call, const char* file, int line) {
  if (code != 0) throw ClError(call, code, file, line);
}

}  // namespace pr
