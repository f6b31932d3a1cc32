// The preview's own knobs in lumislab-study (docs/method.md §4.7): the OpenGL image
// (`lumislab-preview`, headless, OSMesa here) and the exact reference at N samples per basis
// support (`lumislab-preview --reference`), each against the reference at many samples, on the
// crypt and on the receiver plane at 2d, for one slab; with the OSMesa frame time (`--bench`).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/image.h"

namespace lumislab {

// One render against the reference: scene (crypt | plane2d), knob and value, relative L2 of the
// image, the 95th percentile of the per-pixel relative error (PixelErrorPercentile), the median
// OSMesa frame (ms; 0 for the CPU reference and on the plane, whose view does not move) and
// the tool's wall time (s).
struct PreviewRow {
  std::string scene, knob, value;
  double rel_l2 = 0, p95 = 0, frame_ms = 0, wall_s = 0;
};

std::string PreviewCsvHeader();
std::string PreviewCsvLine(const PreviewRow& row);
// preview.csv back; another header or a damaged line is bad input naming the file and line.
std::vector<PreviewRow> ReadPreviewCsv(const std::string& path);
// The report's section: one table per scene.
std::string PreviewReport(const std::vector<PreviewRow>& rows);

// The q-quantile (0.95) over the lit pixels (r above 1e-3 of the image's largest r) of
// |image - reference| / max(r, floor), r the pixel's largest reference channel and |.| the
// largest channel difference; floor = 0.1 x the mean r of the lit pixels, so that a pixel in deep
// shadow is judged against the image's light rather than its own near-zero value. Same size,
// 3 channels (bad input otherwise); 0 when nothing is lit.
double PixelErrorPercentile(const ImageF& image, const ImageF& reference, double q);

// Runs lumislab-preview `args` --bench --bench-frames 5 (stdout and stderr into `log`, which is
// truncated first) and returns the median frame it logs, ms. A missing line is a failure.
double PreviewFrameMs(const std::string& slab, const std::vector<std::string>& args,
                      const std::string& log, int threads);

struct PreviewSweepOptions {
  std::string slab;                      // the base dataset's slab folder
  std::string work;                      // work/preview/: images and logs
  int width = 160, height = 120;         // the crypt's image; the plane is width x width
  int reference_samples = 8;             // N of the reference every image is measured against
  std::vector<int> samples = {1, 2, 4};  // the reference's own knob
  std::vector<int> shadow_sizes = {256, 1024, 2048};  // besides the default 512
  int threads = 0;
};

// Every point not yet in `rows` (matched by scene, knob, value) is rendered, measured and
// appended, and `save` is called after each (the CSV is rewritten with the new row only once the
// point is complete). Stops between points on a stop signal (a failure: run again).
void RunPreviewSweep(const PreviewSweepOptions& options, std::vector<PreviewRow>* rows,
                     const std::function<void()>& save);

}  // namespace lumislab
