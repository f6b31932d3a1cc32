// lumislab-export report: the lab report a photometry lab hands its customer (docs/method.md
// §4.11), from a slab: the summary numbers (lib/photometry/photometric_summary.h), zonal lumens,
// polar, linear and iso-candela diagrams, the illuminance on planes at user distances, the
// near-field advantage against the far field's inverse square, a candela table, the stated
// uncertainty (export/report_uncertainty.h), colour (calib/colour.json) and the capture's
// metadata. One self-contained HTML file (inline SVG and PNG, no network) printable on A4; a PDF
// through headless Chromium.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/command_line.h"
#include "core/image.h"
#include "export/report_uncertainty.h"
#include "lib/photometry/intensity_distribution.h"
#include "lib/photometry/photometric_summary.h"

namespace lumislab {

struct ReportOptions {
  std::string slab;  // dataset folder, its slab/, or a luminaire folder (merged far field)
  std::string out;   // .html
  std::string pdf;   // "" or .pdf (headless Chromium)
  double input_watts = 0;
  std::vector<double> distances_mm;  // empty: d, 2d, 4d
  double c_step = 5, gamma_step = 1;
  int samples = 4;        // far field: N x N quadrature per position
  int plane_size = 121;   // pixels per side of each plane picture (odd: a centre pixel)
  int plane_samples = 2;  // the plane's reference render
  bool per_klm = false;   // diagrams in cd/klm
  UncertaintyOptions uncertainty;
  std::string title;
  bool force = false;
};

// The illuminance on one plane: the slab's picture, and on the centre line (y = 0, along +x) the
// slab's value against the far field's inverse square.
struct ReportPlane {
  double distance_mm = 0, extent_mm = 0;
  std::vector<float> luminance;  // size x size, row 0 on top (+y up), W/m^2 or lx
  int size = 0;
  std::vector<double> profile_x_mm, profile_slab, profile_far;  // far: NaN where not seen
  double centre_slab = 0, centre_far = 0;
  std::string note;  // CheckPlaneResolved's warning: nearer S than the model is trusted (or "")
};

// The colour section's content (calib/colour.json through lib/lightfield/light_colour.h);
// present = false when the dataset has no colour calibration.
struct ReportColour {
  bool present = false;
  double x = 0, y = 0, cct_k = 0;  // the total light's chromaticity and CCT (NaN: none)
  double duv = 0;                  // the total light's Duv (CCT is NaN beyond |Duv| 0.05)
  std::string source;              // the calibration file, relative to the dataset
  std::vector<std::string> rows;   // Duv, the CCT's range over directions
  // Per direction: x, y and CCT (NaN where not seen or without a chromaticity) at
  // table_gamma x table_c, cells[ig * table_c.size() + ic].
  std::vector<double> table_c, table_gamma;
  struct Cell {
    double x = 0, y = 0, cct_k = 0;
  };
  std::vector<Cell> cells;
};

struct ReportData {
  std::string title, slab_dir, dataset_dir, generated_utc, software;
  // What the report is of, for its heading: the slab folder, or the luminaire folder with its
  // orientations and the one whose near field the planes show.
  std::string measured;
  SlabInfo info;
  IntensityDistribution distribution;  // C 0-360, gamma 0-90 (cd or W/sr)
  std::vector<uint8_t> seen;           // per value of `distribution`
  PhotometricSummary summary;
  double seen_cone_deg = 0;  // every direction seen up to this gamma
  double seen_fraction = 0;  // of the hemisphere's (sphere's) directions (solid angle) seen
  // The far field's gamma range: 90 for a slab, 180 for a luminaire folder measured over the
  // sphere (its merged far field, docs/formats.md §19).
  double gamma_span_deg = 90;
  double flux_in_cone = 0;  // flux within seen_cone_deg
  FarFieldUncertainty uncertainty;
  std::vector<ReportPlane> planes;
  ReportColour colour;
  // Metadata rows (label, value): setup, calibration RMS, dates, ...
  std::vector<std::pair<std::string, std::string>> metadata;
  bool per_klm = false;
  std::string IntensityUnit() const;    // "cd", "cd/klm", "W/sr"
  std::string FluxUnit() const;         // "lm" or "W"
  std::string IlluminanceUnit() const;  // "lx" or "W/m²"
  std::string Domain() const { return gamma_span_deg > 90 ? "sphere" : "hemisphere"; }
};

// Everything the report shows, from the slab (read on `threads` threads).
ReportData MakeReportData(const ReportOptions& options, int threads);
// The HTML document (export/report_html.cc).
std::string ReportHtml(const ReportData& data);

// Adds `report` to `app` (its options bound to `common`).
using ParsedCommand = std::function<std::optional<int>(int threads)>;
ParsedCommand AddReportCommand(CLI::App& app, CommonOptions* common);

}  // namespace lumislab
