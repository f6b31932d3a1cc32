// lumislab-study's command line: the options of the sweep (study.h StudyOptions), then the
// Pareto and target tables on stdout.
#include "study/cli.h"

#include <CLI/CLI.hpp>
#include <iostream>
#include <string>
#include <vector>

#include "core/command_line.h"
#include "core/log.h"
#include "study/study.h"

namespace lumislab {

int RunStudy(int argc, char** argv) {
  CLI::App app{
      "lumislab-study: what accuracy costs in time. Sweeps one knob at a time around a base "
      "setting on a synthetic scene, each point end to end (acquire synth -> calibrate screen -> "
      "reconstruct -> exact reference against the analytic image at D = d, 2d, 4d), and writes "
      "study.csv, report.md and error-against-time plots (SVG) into --out. Resumes: points "
      "already in study.csv are skipped."};
  StudyOptions o;
  CommonOptions common;
  AddCommonOptions(&app, &common);
  app.add_option("--scene", o.scene, "scene file (JSON) or \"default\" (acquire synth's)")
      ->capture_default_str();
  app.add_option("--out", o.out, "folder for study.csv, report.md, the plots and work/")
      ->required();
  app.add_flag(
      "--quick", o.quick,
      "photos at 0.25 of the scene camera's size (x1, 1.5, 2 for the photo knob), 48 texels, 40 px "
      "renders");
  app.add_option("--knobs", o.knobs,
                 "comma-separated subset of spacing,extent,photo,k_max,resolution,samples,noise,"
                 "brackets,lambda,preview, or all")
      ->capture_default_str();
  AddLabModelOptions(&app, &o.lab, /*brackets_option=*/false);
  app.add_option("--photo-scale", o.photo_scale,
                 "base photo size over the scene camera's (default 1, --quick 0.25)")
      ->check(FiniteIn(0.05, 4));
  app.add_option("--resolution", o.resolution,
                 "base slab texels per side (default 150, --quick 48)")
      ->check(CLI::Range(8, 1000));
  app.add_option("--render-size", o.render_px,
                 "receiver-plane image side in px (default 96, --quick 40)")
      ->check(CLI::Range(8, 2048));
  app.add_option("--samples", o.samples, "base samples per basis support N of the reference")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option("--values", o.values, "values per knob: 2 (the first two of each list) or 3")
      ->check(CLI::Range(2, 3))
      ->capture_default_str();
  app.add_option("--preview-width", o.preview_width,
                 "crypt image W x 3W/4 (the plane's W x W) of the preview knobs and of each "
                 "point's OSMesa frame time (default 240, --quick 120)")
      ->check(CLI::Range(16, 2048));
  app.add_option("--preview-samples", o.preview_samples,
                 "N of the exact reference the preview knobs are measured against")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_flag("--keep-photos", o.keep_photos, "keep each dataset's photos (removed by default)");
  if (const auto code = ParseCommandLine(app, argc, argv)) return *code;
  const int threads = StartTool("study", common);
  LogInfo("parameters: scene=", o.scene, " out=", o.out, " quick=", o.quick ? "yes" : "no",
          " knobs=", o.knobs, " values=", o.values, " lab=", o.lab.Describe(),
          " photo_scale=", o.photo_scale, " resolution=", o.resolution,
          " render_size=", o.render_px, " samples=", o.samples, " preview_width=", o.preview_width,
          " preview_samples=", o.preview_samples, " keep_photos=", o.keep_photos ? "yes" : "no",
          " threads=", threads);
  const std::vector<StudyRow> rows = RunStudySweep(o, threads);
  std::cout << ParetoTables(rows) << TargetTable(rows) << TrimTrailingSlashes(o.out)
            << "/report.md\n";
  return 0;
}

}  // namespace lumislab
