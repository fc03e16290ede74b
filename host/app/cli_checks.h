// Pieces that every subcommand's options share.
#pragma once

#include <CLI/CLI.hpp>

namespace pr {

// Numbers a user types: finite (CLI::Range lets NaN through), within bounds that --help shows.
CLI::Validator finiteIn(double lo, double hi);

extern const char* const kOutsideUrisHelp;

}  // namespace pr
