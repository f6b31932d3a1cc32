#include "acquire/filter_print.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "core/atomic_file.h"
#include "core/basis.h"
#include "core/error.h"
#include "core/json.h"
#include "lib/photo/photo_write.h"

namespace lumislab {

void FilterPrintOptions::Check() const {
  if (!(spacing_mm > 0 && spacing_mm <= 1000))
    throw BadInput("--spacing-mm: expected a length in (0, 1000] mm, got " +
                   std::to_string(spacing_mm));
  if (k_max < kMinFilterTruncation || k_max > kMaxFilterTruncation)
    throw BadInput("--k-max: expected an integer in [" + std::to_string(kMinFilterTruncation) +
                   ", " + std::to_string(kMaxFilterTruncation) + "], got " + std::to_string(k_max));
  if (!(dpi >= 10 && dpi <= 20000))
    throw BadInput("--dpi: expected dots per inch in [10, 20000], got " + std::to_string(dpi));
  if (out_dir.empty()) throw BadInput("--out: expected a folder, got nothing");
  const double px = 2 * (k_max + 1) * spacing_mm / 25.4 * dpi;
  if (px > 20000)
    throw BadInput("--dpi: expected a slide of at most 20000 px, got " + std::to_string(int(px)) +
                   " px");
}

FilterPrintReport PrintFilter(const FilterPrintOptions& options) {
  options.Check();
  const DualFilter filter = DualFilter::Truncated(options.k_max);
  FilterPrintReport report;
  report.peak = filter.Peak2D();
  report.size_mm = 2 * filter.SupportHalfWidth() * options.spacing_mm;
  report.size_px = std::max(2, int(std::lround(report.size_mm / 25.4 * options.dpi)));
  const double pixel_mm = report.size_mm / report.size_px;
  cv::Mat plus(report.size_px, report.size_px, CV_16UC1), minus(plus.size(), CV_16UC1);
  for (int row = 0; row < report.size_px; ++row)
    for (int col = 0; col < report.size_px; ++col) {
      // Pixel centre in units of h, relative to the filter centre; row 0 on top (+v).
      const double u = (-0.5 * report.size_mm + (col + 0.5) * pixel_mm) / options.spacing_mm;
      const double v = (0.5 * report.size_mm - (row + 0.5) * pixel_mm) / options.spacing_mm;
      const double t = filter.Eval2D(u, v) / report.peak;
      plus.at<uint16_t>(row, col) =
          cv::saturate_cast<uint16_t>(std::lround(std::max(t, 0.0) * 65535));
      minus.at<uint16_t>(row, col) =
          cv::saturate_cast<uint16_t>(std::lround(std::max(-t, 0.0) * 65535));
    }
  MakeDirectories(options.out_dir);
  report.plus_png = options.out_dir + "/filter_p.png";
  report.minus_png = options.out_dir + "/filter_n.png";
  report.json = options.out_dir + "/filter.json";
  WriteImageFile(report.plus_png, plus);
  WriteImageFile(report.minus_png, minus);
  nlohmann::json j;
  j["schema_version"] = 1;
  j["basis"] = "bell";
  j["spacing_mm"] = options.spacing_mm;
  j["k_max"] = options.k_max;
  j["dual_coefficients"] = filter.coefficients();
  j["integral"] = filter.Integral();
  j["peak"] = report.peak;
  // Response to the neighbouring basis functions, k = 1 .. K + 1 (beyond, the supports do not
  // overlap): the largest is not always at k = 1, 2 (for K = 2 it is at k = 3).
  for (int k = 1; k <= options.k_max + 1; ++k)
    j["cross_talk"]["k" + std::to_string(k)] = filter.CrossTalk(k);
  j["size_mm"] = report.size_mm;
  j["dpi"] = options.dpi;
  j["size_px"] = report.size_px;
  j["slides"] = {{"p", "filter_p.png"}, {"n", "filter_n.png"}};
  j["encoding"] = "16-bit grayscale, transmittance = value / 65535, row 0 on top (+v)";
  WriteJsonAtomically(report.json, j);
  return report;
}

}  // namespace lumislab
