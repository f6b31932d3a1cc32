// lumislab-export's pictures for a lab report (docs/method.md §4.9, docs/architecture.md §7):
//   irradiance --slab <dir> --distance-mm D [--extent-mm W] --out x.png|x.exr
//       the slab's irradiance (illuminance) on the plane z = D, false colour with colour bar and
//       iso-lines (.png) or linear (.exr)
//   polar --slab <dir> --out x.svg|x.png
//       the far-field polar diagram, planes C0-C180 and C90-C270
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <optional>

#include "core/command_line.h"
#include "lib/lightfield/polar_plot.h"

namespace lumislab {

// Runs the subcommand of a set that was parsed, with the tool's resolved thread count; nothing
// when none of the set's subcommands was on the command line. (The same alias as
// export/cli_formats.h's; a repeated alias of one type is allowed.)
using ParsedCommand = std::function<std::optional<int>(int threads)>;

// What `polar` draws: the far field of the slab at `slab_dir` (a slab folder, or a luminaire
// folder: the merged far field, gamma 0-180) in the planes C0, C90, C180 and C270, up to the
// largest gamma all four saw, every `gamma_step_deg`, with `samples` x `samples` quadrature.
PolarPlotData PolarData(const std::string& slab_dir, double gamma_step_deg, int samples,
                        int threads);

// Adds irradiance and polar to `app` (each with the common options bound to `common`).
ParsedCommand AddPlotCommands(CLI::App& app, CommonOptions* common);

}  // namespace lumislab
