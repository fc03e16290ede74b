#include "util/check.h"

#include <string>

#include "util/error.h"

namespace pr {

void checkFailed(const char* condition, const char* file, int line) {
  throw RuntimeError(std::string("internal check failed: ") + condition + " (" + file + ":" +
                     std::to_string(line) + ")");
}

}  // namespace pr
