// lumislab-acquire filter: the two printable filter slides T+ and T- (docs/method.md §2).
#pragma once

#include <string>

namespace lumislab {

struct FilterPrintOptions {
  double spacing_mm = 5;  // h
  int k_max = 1;          // truncation: support +-(K+1) h
  double dpi = 1200;
  std::string out_dir;
  void Check() const;  // BadInput naming the option
};

struct FilterPrintReport {
  int size_px = 0;  // the slides are size_px x size_px
  double size_mm = 0;
  double peak = 0;
  std::string plus_png, minus_png, json;
};

// Writes filter_p.png and filter_n.png (16-bit grayscale transmittance of one filter window,
// row 0 on top = +v) and filter.json (coefficients, peak, cross-talk for k = 1 .. K + 1, size).
FilterPrintReport PrintFilter(const FilterPrintOptions& options);

}  // namespace lumislab
