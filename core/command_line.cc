#include "core/command_line.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/error.h"
#include "core/log.h"
#include "core/parallel.h"

namespace lumislab {

void AddCommonOptions(CLI::App* app, CommonOptions* options) {
  app->add_flag("--verbose", options->verbose, "log details");
  app->add_option("--threads", options->threads,
                  "worker threads (0: all cores, at most " + std::to_string(kMaxThreads) + ")")
      ->capture_default_str();
}

std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv) {
  // CLI11 answers a mistyped subcommand with "A subcommand is required": name the word.
  const auto subcommands = app.get_subcommands([](CLI::App*) { return true; });
  if (argc > 1 && !subcommands.empty() && argv[1][0] != '-') {
    std::string names;
    bool known = false;
    for (const CLI::App* sub : subcommands) {
      known = known || sub->get_name() == argv[1];
      names += (names.empty() ? "" : " | ") + sub->get_name();
    }
    if (!known) {
      const std::string tool = std::filesystem::path(argv[0]).filename().string();
      std::fprintf(stderr, "%s: error: unknown subcommand \"%s\" (expected %s)\n", tool.c_str(),
                   argv[1], names.c_str());
      return static_cast<int>(ExitCode::kBadInput);
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : static_cast<int>(ExitCode::kBadInput);
  }
  return std::nullopt;
}

int StartTool(const std::string& tool, const CommonOptions& options) {
  SetLogTool(tool);
  if (options.verbose) SetLogLevel(LogLevel::kDebug);
  return ResolveThreads(options.threads);
}

CLI::Validator FiniteIn(double lo, double hi) {
  const std::string range =
      "[" + CLI::detail::to_string(lo) + ", " + CLI::detail::to_string(hi) + "]";
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double v = 0;
        if (!CLI::detail::lexical_cast(text, v) || !std::isfinite(v) || v < lo || v > hi)
          return "expected a number in " + range + ", got " + text;
        return "";
      },
      "NUMBER in " + range);
}

std::string TrimTrailingSlashes(std::string path) {
  while (path.size() > 1 && path.back() == '/') path.pop_back();
  return path;
}

}  // namespace lumislab
