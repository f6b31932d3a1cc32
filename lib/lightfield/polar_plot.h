// The photometric polar diagram (docs/method.md §4.9): intensity against gamma in the planes
// C0-C180 and C90-C270 (photometry type C, docs/formats.md §17: C0 towards +x, C90 towards -y of
// the luminaire frame), gamma = 0 pointing down as in a lab's report, C0 and C90 to the right,
// C180 and C270 to the left (a layout, not a view from any side); grid circles labelled in the
// intensity's unit, radial lines every 15 degrees labelled every 30. One drawing (PolarPlot)
// written either as SVG text or as an RGB picture (drawn at twice the size and averaged down:
// anti-aliased).
#pragma once

#include <string>
#include <vector>

#include "lib/lightfield/raster.h"

namespace lumislab {

struct PolarPlotData {
  std::vector<double> gamma_deg;            // ascending, within [0, 180]
  std::vector<double> c0, c180, c90, c270;  // intensity at each gamma; empty: not drawn
  std::string unit = "cd";                  // cd or W/sr
  std::string title;
  // Angles marked by a thin dashed radial line in the pair's colour with a label at its end (the
  // report's beam and field edges): signed gamma, + on the C0 / C90 side (right), - on the
  // C180 / C270 side (left).
  struct Mark {
    double signed_gamma_deg = 0;
    bool c90_pair = false;  // the C90-C270 pair's colour, else C0-C180's
    std::string label;
  };
  std::vector<Mark> marks;
  // Check(): BadInput unless gamma_deg is ascending in [0, 180] with >= 2 values, each curve
  // empty or of its length, at least one curve, values finite and >= 0 (negative noise is
  // clamped to 0 by the caller, not here).
  void Check() const;
};

// The drawing, in pixels of a size x (size + header) picture.
struct PolarPlot {
  struct Line {
    std::vector<double> xy;  // x0, y0, x1, y1, ...
    Rgb8 colour;
    double width = 1;
    double dash = 0;  // > 0: dashes and gaps of this length
  };
  struct Text {
    double x = 0, y = 0;  // the anchor point, vertically the text's middle
    std::string text;
    double size = 12;  // font size (px)
    int anchor = -1;   // -1 start, 0 middle, 1 end
    Rgb8 colour;
  };
  double width = 0, height = 0;
  std::vector<Line> lines;
  std::vector<Text> texts;
};

PolarPlot MakePolarPlot(const PolarPlotData& data, int size = 600);
std::string PolarPlotSvg(const PolarPlot& plot);

// Text for SVG and HTML, element content or a quoted attribute: & < > " escaped. The polar
// plot's labels and the lab report (export/report_html.cc) use it.
std::string XmlEscape(const std::string& s);
Rgb8Image PolarPlotImage(const PolarPlot& plot);

}  // namespace lumislab
