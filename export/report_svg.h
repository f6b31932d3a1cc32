// Drawing pieces of the lab report (export/report_html.cc): Cartesian axes in SVG, iso-lines by
// marching squares as SVG path data, and an RGB picture as an inline PNG data URI.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "lib/lightfield/polar_plot.h"  // XmlEscape
#include "lib/lightfield/raster.h"

namespace lumislab {

// A plot area: data ranges mapped to a width x height SVG with margins for the tick labels.
struct SvgAxes {
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;  // data ranges
  double width = 320, height = 220;       // the whole SVG (px)
  double left = 54, right = 12, top = 12, bottom = 38;
  double X(double x) const { return left + (x - x0) / (x1 - x0) * (width - left - right); }
  double Y(double y) const {
    return height - bottom - (y - y0) / (y1 - y0) * (height - top - bottom);
  }
  // "<svg ...>" with a frame, grid lines and labelled ticks, the axis titles; close with "</svg>".
  std::string Open(const std::string& x_title, const std::string& y_title) const;
  // A polyline through (x, y) pairs; NaN values break it.
  std::string Polyline(const std::vector<double>& x, const std::vector<double>& y,
                       const std::string& colour, double width = 1.5, double dash = 0) const;
};

// Ticks from `lo` to `hi` at a round step (FalseColourScale's), and that step.
std::vector<double> NiceTicks(double lo, double hi, double* step);

// SVG path data ("M x y L x y ...", one segment per cell crossing) of the iso-line `level` of
// values on an nx x ny grid (v[iy * nx + ix]); `page` maps fractional grid indices (fx, fy) to
// SVG coordinates. Cells with a corner where `valid` is 0 (when given) are left out.
std::string ContourPath(const std::vector<double>& v, int nx, int ny, double level,
                        const std::function<std::pair<double, double>(double, double)>& page,
                        const std::vector<uint8_t>& valid = {});

// "data:image/png;base64,..." of the picture (written through lib/photo's PNG writer, the one
// PNG encoder, into a temporary file, read back and removed).
std::string PngDataUri(const Rgb8Image& image);

// A number with `digits` significant digits; "—" for NaN.
std::string Fmt(double v, int digits = 4);
// "12.3°"; "—" for NaN.
std::string Deg(double v, int decimals = 1);

}  // namespace lumislab
