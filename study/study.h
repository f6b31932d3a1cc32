// lumislab-study (docs/method.md §4.7): what accuracy costs in time. A sweep over a synthetic
// scene, one knob at a time around a base setting; each point runs the whole chain (acquire synth
// -> calibrate screen -> reconstruct) and measures the slab against truth/ and the receiver-plane
// irradiance of the exact reference against the analytic image at D = d, 2d, 4d, with the times.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/lab_model.h"

namespace lumislab {

// One point of the sweep: its knob and value, every setting, every error and time (a CSV row).
struct StudyRow {
  std::string knob, value, key;  // key: every setting, so equal points share results
  double h_mm = 0;
  int nu = 0, nv = 0, photo_w = 0, photo_h = 0, k_max = 0, slab_res = 0, samples = 0, render_px = 0;
  double slab_rel_l2 = 0;
  double err[3] = {0, 0, 0};   // relative L2 of the reference vs the analytic image at d, 2d, 4d
  double flux[3] = {0, 0, 0};  // its flux over the analytic image's
  // The same error over the pixels the grid covers (GridCovers: all the light of every emitter
  // reaches them through the slab), -1 when none is; and the analytic flux's share there.
  double err_covered[3] = {0, 0, 0};
  double covered[3] = {0, 0, 0};
  double full_well_e = 0;  // sensor_noise's full well (0: the scene's effects as given)
  int brackets = 1;        // exposures per slide (the lab model's brackets)
  double lambda = -1;      // reconstruct --lambda (-1: its default, 1e-4)
  double lab_s = 0, acquire_s = 0, calibrate_s = 0, reconstruct_s = 0, render_s = 0, total_s = 0;
  double preview_ms = 0;  // median OSMesa frame of the crypt with this slab (not in total_s)
  int positions() const { return nu * nv; }
};

// The CSV (header line + one line per row) and back; a file with another header or a damaged
// line is bad input naming the file and line.
std::string StudyCsvHeader();
std::string StudyCsvLine(const StudyRow& row);
std::vector<StudyRow> ReadStudyCsv(const std::string& path);
// The fields of one CSV line (no quoting: the study's values hold no comma).
std::vector<std::string> SplitCsvLine(const std::string& line);
// The data lines of a CSV the study wrote (study.csv, preview.csv): the first line must be
// `header`, each other line `fields` fields that `parse` accepts (it throws std::exception on a
// field that is not a number); otherwise bad input naming the file and line.
void ReadCsvLines(const std::string& path, const std::string& header, size_t fields,
                  const std::function<void(const std::vector<std::string>&)>& parse);

// Measured times scatter with the machine's load (reconstruct's and render's the most);
// totals within this fraction of each other count as the same time, so that a point is not put
// on the front, or named cheapest, over a more accurate one for a few hundred ms of scatter.
constexpr double kTimeScatter = 0.05;

// Indices of the rows on the Pareto front of (total_s, err[d_index]): no other row is more
// accurate within kTimeScatter of its time (or as accurate and faster); one row per key;
// sorted by time.
std::vector<size_t> ParetoFront(const std::vector<StudyRow>& rows, int d_index);

// report.md text (tables per knob in `knob_order`, the Pareto fronts at d and 4d) and the
// front tables alone (what is printed on stdout).
std::string StudyReport(const std::vector<StudyRow>& rows,
                        const std::vector<std::string>& knob_order, const std::string& header);
std::string ParetoTables(const std::vector<StudyRow>& rows);
// For targets 5 %, 2 %, 1 %, 0.5 % at D = d and 4d, the measured row of least total time within
// each (or "none measured"; of the rows within kTimeScatter of that time the most accurate),
// with its lab, reconstruct, render and preview times.
std::string TargetTable(const std::vector<StudyRow>& rows);
// Error at D = d_index against total time, log axes, one curve per knob, the front marked.
std::string StudySvg(const std::vector<StudyRow>& rows, const std::vector<std::string>& knob_order,
                     int d_index);

// The study's settings (lumislab-study's options, study/cli.cc).
struct StudyOptions {
  std::string scene = "default";
  std::string out;
  bool quick = false;
  std::string knobs = "all";
  LabModel lab;             // its brackets are the scene's (or the brackets knob's)
  double photo_scale = 0;   // base photo size over the scene camera's (0: 1, --quick 0.25)
  int resolution = 0;       // base slab texels per side (0: 150, --quick 48)
  int render_px = 0;        // receiver-plane image side (0: 96, --quick 40)
  int samples = 1;          // base N of the reference
  int preview_width = 0;    // crypt image W x 3W/4 of the preview knobs and frame times
  int preview_samples = 8;  // N of the reference the preview knobs are measured against
  bool keep_photos = false;
  int values = 3;  // values per knob: the first 2 or all 3 of each list
};

// The sweep into `options.out` (made if missing; a study of another scene or lab model there is
// bad input): every point not yet in study.csv, then the preview's own knobs, then report.md and
// the plots. Returns the rows of study.csv.
std::vector<StudyRow> RunStudySweep(const StudyOptions& options, int threads);

}  // namespace lumislab
