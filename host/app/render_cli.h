// The `render` subcommand's options, declared once in a table (render_cli.cpp): each row gives
// an option's names, group, who it is for, whether it can change a frame's pixels, where its
// value lands, its range or choices and its help. The command line, `--help` / `--help-all`,
// the resume history's estimator key and the generated option tables (`pathreuse options`,
// README.md, docs/options.md) all come from that table.
#pragma once

#include <string>
#include <vector>

#include "render/options.h"

namespace CLI {
class App;
}

namespace pr {

// Everyday options are listed by `render --help`; research knobs (strategies' parameters,
// diagnostics) by `render --help-all`, grouped. Both kinds parse alike.
enum class OptionAudience { Everyday, Research };

// Whether an option can change a frame's pixels (then it is part of the estimator key, and a
// resume history recorded under another value is not used), or only where frames go and how
// the run reports.
enum class OptionEffect { Estimator, RunOnly };

// The render options as typed; toRenderOptions turns the texts into RenderOptions' enums.
struct RenderArgs {
  RenderOptions ro;
  std::string frames;
  std::string mode = "reuse", lightSampler = "auto", envLightChoice = "auto",
              materialModel = "energy";
  std::string terminator = "on", bvhWidth = "auto", connections = "auto";
  bool resample = false, noResample = false;
};

// Adds `render` to `app` with every option of the table. Research knobs are listed under their
// groups where `listResearch`, else hidden from help (they parse the same).
CLI::App* addRenderCommand(CLI::App& app, RenderArgs& a, bool listResearch);

// The parsed options as RenderOptions, with the estimator key built from the table.
RenderOptions toRenderOptions(const RenderArgs& a, const CLI::App& render);

// Each option's range in the table, checked on options built in code (the command line's are
// checked as it is parsed): a value other than RenderOptions' default outside its option's range
// throws InputError naming the option. What joins several options is validateRenderOptions'.
void checkOptionRanges(const RenderOptions& o);

// Whether the command line asks for --help-all (the research knobs are then listed).
bool asksForHelpAll(int argc, const char* const* argv);

// The table as Markdown: the everyday options, or with `research` every option, by group.
std::string renderOptionsMarkdown(bool research);

// Each option's name, audience and effect, in table order (for tests and docs).
struct OptionSummary {
  std::string name;  // the first long name, e.g. "--spp"
  OptionAudience audience;
  OptionEffect effect;
  bool flag;  // takes no value
};
std::vector<OptionSummary> renderOptionSummaries();

}  // namespace pr
