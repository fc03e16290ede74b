#include "app/cli_checks.h"

#include <cmath>
#include <string>

namespace pr {

CLI::Validator finiteIn(double lo, double hi) {
  const std::string range =
      "[" + CLI::detail::to_string(lo) + " - " + CLI::detail::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v) || !std::isfinite(v) || v < lo || v > hi)
          return "Value " + text + " not in range " + range;
        return "";
      },
      "in " + range);
}

const char* const kOutsideUrisHelp =
    "Let the scene's buffer and image URIs name files outside its folder (by default a scene "
    "reads files in its own folder and below only)";

}  // namespace pr
