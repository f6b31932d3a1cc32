#include "acquire/cli.h"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <sstream>

#include "acquire/filter_print.h"
#include "acquire/scene.h"
#include "acquire/synth.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"

namespace lumislab {

int RunAcquire(int argc, char** argv) {
  CLI::App app{"lumislab-acquire: synthetic capture of a luminaire and filter-slide printing"};
  app.require_subcommand(1);
  bool verbose = false;
  app.add_flag("--verbose", verbose, "log details");

  SynthOptions synth;
  bool print_scene = false;
  CLI::App* synth_cmd = app.add_subcommand(
      "synth",
      "render the photos of a synthetic scene through both filter slides, a "
      "calibration photo, dataset.json and the analytic truth/ into a dataset folder");
  synth_cmd->add_option("--scene", synth.scene, "scene file (JSON) or \"default\"")->required();
  synth_cmd->add_option("--out", synth.out_dir, "dataset folder to write");
  synth_cmd->add_option("--interval", synth.interval_s,
                        "live acquisition: dataset.json and the calibration photo first, then "
                        "the positions one by one with this pause (s)");
  synth_cmd->add_flag("--force", synth.force, "redo a dataset that is already complete");
  synth_cmd->add_option("--threads", synth.threads, "worker threads (0: all cores)")
      ->capture_default_str();
  synth_cmd
      ->add_option("--truth-resolution", synth.truth_resolution,
                   "texels per side of the truth slab")
      ->capture_default_str();
  synth_cmd->add_flag("--compress", synth.compress_exr, "PIZ-compress the float EXR photos");
  synth_cmd->add_flag("--print-scene", print_scene,
                      "print the scene as JSON (the built-in one for --scene default) and exit");
  synth_cmd->add_flag("--verbose", verbose, "log details");

  FilterPrintOptions filter;
  CLI::App* filter_cmd =
      app.add_subcommand("filter",
                         "write the printable filter slides T+ and T- as 16-bit PNG "
                         "plus filter.json (coefficients, peak, cross-talk)");
  filter_cmd->add_option("--spacing-mm", filter.spacing_mm, "grid spacing h (mm)")
      ->capture_default_str();
  filter_cmd->add_option("--k-max", filter.k_max, "truncation K of the dual: support +-(K+1)h")
      ->capture_default_str();
  filter_cmd->add_option("--dpi", filter.dpi, "print resolution")->capture_default_str();
  filter_cmd->add_option("--out", filter.out_dir, "output folder")->required();
  filter_cmd->add_flag("--verbose", verbose, "log details");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : static_cast<int>(ExitCode::kBadInput);
  }
  SetLogTool("acquire");
  if (verbose) SetLogLevel(LogLevel::kDebug);

  if (filter_cmd->parsed()) {
    LogInfo("parameters: spacing_mm=", filter.spacing_mm, " k_max=", filter.k_max,
            " dpi=", filter.dpi, " out=", filter.out_dir);
    const FilterPrintReport r = PrintFilter(filter);
    std::printf("filter slides (%d x %d px, %.3f mm, peak %.6f): %s %s %s\n", r.size_px, r.size_px,
                r.size_mm, r.peak, r.plus_png.c_str(), r.minus_png.c_str(), r.json.c_str());
    return 0;
  }

  if (print_scene) {
    if (synth.scene == "default") {
      std::fputs(DefaultSceneJson().c_str(), stdout);
    } else {
      LoadScene(synth.scene);  // validates
      std::fputs(ReadTextFile(synth.scene).c_str(), stdout);
    }
    return 0;
  }
  while (synth.out_dir.size() > 1 && synth.out_dir.back() == '/') synth.out_dir.pop_back();
  std::ostringstream params;
  params << "scene=" << synth.scene << " out=" << synth.out_dir << " interval="
         << (synth.interval_s >= 0 ? std::to_string(synth.interval_s) + " s" : "none")
         << " force=" << (synth.force ? "yes" : "no") << " threads=" << synth.threads;
  LogInfo("parameters: ", params.str());
  synth.Check();
  const SynthReport r = RunSynth(synth);
  if (!r.skipped)
    LogInfo("wrote ", r.photos_written, " photos, radiometric scale ", r.radiometric_scale,
            " W/m^2 per unit");
  std::printf("dataset: %s\n", synth.out_dir.c_str());
  return 0;
}

}  // namespace lumislab
