// The text of a kernel's __constant table, as the table tools write them into kernels/shared/.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

namespace pr {

// Appends "// what" and "PR_TABLE float name[n] = {...};", eight values a line.
inline void appendKernelTable(std::string& s, const char* name, const char* what,
                              const std::vector<float>& v) {
  s += std::string("// ") + what + "\n";
  s += std::string("PR_TABLE float ") + name + "[" + std::to_string(v.size()) + "] = {\n";
  for (size_t i = 0; i < v.size(); ++i) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6ff,", double(v[i]));
    s += (i % 8 == 0 ? "    " : " ") + std::string(buf);
    if (i % 8 == 7 || i + 1 == v.size()) s += "\n";
  }
  s += "};\n\n";
}

}  // namespace pr
