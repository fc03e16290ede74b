// Checked OpenCL calls: every error becomes a ClError naming the call, the error's
// symbolic name, and the file and line of the call.
#pragma once

#include <string>

#include "util/error.h"

namespace pr {

// Symbolic name of an OpenCL error code ("CL_OUT_OF_RESOURCES"), or "CL_ERROR(<code>)".
std::string clErrorName(int code);

class ClError : public RuntimeError {
 public:
  ClError(const std::string& call, int code, const char* file, int line,
          const std::string& detail = "");
  int code() const { return code_; }
  const std::string& call() const { return call_; }

 private:
  std::string call_;
  int code_;
};

// Throws ClError when `code` is not CL_SUCCESS.
void clCheck(int code, const char* call, const char* file, int line);

}  // namespace pr

// CL_CHECK(expr): evaluates an OpenCL call returning cl_int and throws on failure.
#define CL_CHECK(expr) ::pr::clCheck(static_cast<int>(expr), #expr, __FILE__, __LINE__)
