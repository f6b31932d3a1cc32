#include "lib/lightfield/polar_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/error.h"
#include "lib/lightfield/false_colour.h"

namespace lumislab {
namespace {

const Rgb8 kGrid{190, 190, 190}, kAxis{90, 90, 90}, kLabel{40, 40, 40};
const Rgb8 kC0{200, 30, 30}, kC90{30, 70, 200};  // the two planes' curves
constexpr double kHeader = 44;                   // px above the diagram: title and legend

std::string Hex(Rgb8 c) {
  char text[8];
  std::snprintf(text, sizeof text, "#%02x%02x%02x", c.r, c.g, c.b);
  return text;
}

// The curve of one plane: the left half-plane's values from its largest gamma to 0, then the
// right one's from 0 outwards; `side` +1 right, -1 left.
std::vector<double> CurvePoints(const PolarPlotData& data, const std::vector<double>& left,
                                const std::vector<double>& right, double cx, double cy,
                                double pixels_per_unit) {
  std::vector<double> xy;
  auto add = [&](double gamma_deg, double value, double side) {
    const double g = gamma_deg * M_PI / 180, r = value * pixels_per_unit;
    xy.push_back(cx + side * r * std::sin(g));
    xy.push_back(cy + r * std::cos(g));
  };
  for (size_t k = left.size(); k-- > 0;) add(data.gamma_deg[k], left[k], -1);
  for (size_t k = 0; k < right.size(); ++k) add(data.gamma_deg[k], right[k], +1);
  return xy;
}

double LargestValue(const PolarPlotData& data) {
  double top = 0;
  for (const auto* curve : {&data.c0, &data.c180, &data.c90, &data.c270})
    for (const double v : *curve) top = std::max(top, v);
  return top;
}

}  // namespace

void PolarPlotData::Check() const {
  if (gamma_deg.size() < 2) throw BadInput("polar plot: at least two gamma angles");
  for (size_t k = 0; k < gamma_deg.size(); ++k)
    if (!(gamma_deg[k] >= 0 && gamma_deg[k] <= 180) ||
        (k > 0 && !(gamma_deg[k] > gamma_deg[k - 1])))
      throw BadInput("polar plot: gamma angles must ascend within [0, 180]");
  bool any = false;
  for (const auto* curve : {&c0, &c180, &c90, &c270}) {
    if (curve->empty()) continue;
    any = true;
    if (curve->size() != gamma_deg.size())
      throw BadInput("polar plot: a curve's length differs from the gamma angles'");
    for (const double v : *curve)
      if (!(std::isfinite(v) && v >= 0))
        throw BadInput("polar plot: intensities must be finite and >= 0");
  }
  if (!any) throw BadInput("polar plot: no curve to draw");
}

PolarPlot MakePolarPlot(const PolarPlotData& data, int size) {
  data.Check();
  PolarPlot plot;
  plot.width = size;
  plot.height = size + kHeader;
  // A semicircle when all gamma are within 90 degrees (the luminaire lights one hemisphere),
  // else the whole circle; the diagram's centre (the luminaire) accordingly.
  const bool half = data.gamma_deg.back() <= 90 + 1e-9;
  const double margin = 46;
  const double radius = size / 2.0 - margin;
  const double cx = size / 2.0, cy = kHeader + (half ? margin * 0.6 : size / 2.0);
  const double gamma_max = half ? 90 : 180;

  FalseColourScale scale;  // the radial axis: 0 to the largest value rounded up to a nice tick
  const double top = LargestValue(data) > 0 ? LargestValue(data) : 1;
  scale.max = top;
  const std::vector<double> ticks0 = scale.Ticks();
  const double step = ticks0.size() >= 2 ? ticks0[1] - ticks0[0] : top;
  scale.max = std::ceil(top / step - 1e-9) * step;
  const double pixels_per_unit = radius / scale.max;

  for (const double tick : scale.Ticks()) {  // grid circles (arcs over the shown gamma range)
    if (tick <= 0) continue;
    PolarPlot::Line arc{{}, kGrid, 1, 0};
    for (int k = 0; k <= int(gamma_max); ++k) {  // 2-degree chords: 0.04 px from the circle
      const double g = (-gamma_max + 2 * k) * M_PI / 180;
      arc.xy.push_back(cx + tick * pixels_per_unit * std::sin(g));
      arc.xy.push_back(cy + tick * pixels_per_unit * std::cos(g));
    }
    plot.lines.push_back(arc);
    // Labelled where the circle meets the right-hand 90-degree line, away from the curves
    // (brightest near gamma = 0).
    plot.texts.push_back(
        {cx + tick * pixels_per_unit, cy - 8, FormatTick(tick, step), 11, 0, kLabel});
  }
  for (int g = -int(gamma_max); g <= int(gamma_max); g += 15) {  // radial lines
    if (!half && g == 180) continue;                             // the same line as -180
    const double a = g * M_PI / 180;
    const double ex = std::sin(a), ey = std::cos(a);
    plot.lines.push_back(
        {{cx, cy, cx + radius * ex, cy + radius * ey}, g == 0 ? kAxis : kGrid, 1, 0});
    if (g % 30 == 0)
      plot.texts.push_back({cx + (radius + 16) * ex,
                            // 90 degrees: below its line, the circles' labels are above it
                            cy + (radius + 12) * ey + (std::abs(g) == 90 ? 10 : 0),
                            std::to_string(std::abs(g)) + "\u00B0", 11, 0, kLabel});
  }
  const std::string unit_label = "I in " + data.unit;
  plot.texts.push_back({cx + 4, cy + radius + (half ? 30 : 34), unit_label, 11, -1, kLabel});

  // The curves and the legend.
  double legend_x = 12;
  auto curve = [&](const std::vector<double>& left, const std::vector<double>& right,
                   const std::string& name, Rgb8 colour, double dash) {
    if (left.empty() && right.empty()) return;
    plot.lines.push_back(
        {CurvePoints(data, left, right, cx, cy, pixels_per_unit), colour, 2, dash});
    plot.lines.push_back({{legend_x, 32, legend_x + 28, 32}, colour, 2, dash});
    plot.texts.push_back({legend_x + 34, 32, name, 12, -1, kLabel});
    legend_x += 150;
  };
  curve(data.c180, data.c0, "C0\u2013C180", kC0, 0);
  curve(data.c270, data.c90, "C90\u2013C270", kC90, 6);
  for (const PolarPlotData::Mark& m : data.marks) {
    if (!std::isfinite(m.signed_gamma_deg) || std::abs(m.signed_gamma_deg) > gamma_max) continue;
    const double a = m.signed_gamma_deg * M_PI / 180;
    const double ex = std::sin(a), ey = std::cos(a);
    const Rgb8 colour = m.c90_pair ? kC90 : kC0;
    plot.lines.push_back({{cx, cy, cx + radius * ex, cy + radius * ey}, colour, 1, 3});
    // Inside the rim, clear of the gamma labels outside it.
    plot.texts.push_back({cx + (radius - 8) * ex + (ex < 0 ? -3 : 3), cy + (radius - 8) * ey,
                          m.label, 10, ex < 0 ? 1 : -1, colour});
  }
  if (!data.title.empty()) plot.texts.push_back({12, 12, data.title, 13, -1, kLabel});
  if (half) plot.height = std::ceil(cy + radius + 48);  // no empty upper half
  return plot;
}

std::string XmlEscape(const std::string& s) {
  std::string out;
  for (const char ch : s) {
    if (ch == '&')
      out += "&amp;";
    else if (ch == '<')
      out += "&lt;";
    else if (ch == '>')
      out += "&gt;";
    else if (ch == '"')
      out += "&quot;";
    else
      out += ch;
  }
  return out;
}

std::string PolarPlotSvg(const PolarPlot& plot) {
  std::ostringstream os;
  os << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << plot.width << "\" height=\""
     << plot.height << "\" viewBox=\"0 0 " << plot.width << " " << plot.height << "\">\n"
     << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  os.precision(2);
  os << std::fixed;
  for (const PolarPlot::Line& line : plot.lines) {
    os << "<polyline fill=\"none\" stroke=\"" << Hex(line.colour) << "\" stroke-width=\""
       << line.width << "\"";
    if (line.dash > 0) os << " stroke-dasharray=\"" << line.dash << "," << line.dash << "\"";
    os << " points=\"";
    for (size_t k = 0; k + 1 < line.xy.size(); k += 2)
      os << (k ? " " : "") << line.xy[k] << "," << line.xy[k + 1];
    os << "\"/>\n";
  }
  for (const PolarPlot::Text& t : plot.texts) {
    const char* anchor = t.anchor < 0 ? "start" : t.anchor == 0 ? "middle" : "end";
    os << "<text x=\"" << t.x << "\" y=\"" << t.y << "\" font-family=\"sans-serif\" font-size=\""
       << t.size << "\" text-anchor=\"" << anchor << "\" dominant-baseline=\"middle\" fill=\""
       << Hex(t.colour) << "\">" << XmlEscape(t.text) << "</text>\n";
  }
  os << "</svg>\n";
  return os.str();
}

Rgb8Image PolarPlotImage(const PolarPlot& plot) {
  // Drawn at twice the size, then each 2 x 2 block averaged: smooth curves without an
  // anti-aliasing rasteriser.
  Rgb8Image big(int(std::lround(2 * plot.width)), int(std::lround(2 * plot.height)),
                {255, 255, 255});
  for (const PolarPlot::Line& line : plot.lines) {
    std::vector<double> xy(line.xy);
    for (double& v : xy) v *= 2;
    DrawPolyline(big, xy, line.colour, 2 * line.width, 2 * line.dash);
  }
  for (const PolarPlot::Text& t : plot.texts) {
    const int scale = std::max(1, int(std::lround(t.size / 5)));  // 7-pixel glyphs ~ cap height
    const int w = TextWidth(t.text, scale);
    const int x = int(std::lround(2 * t.x)) - (t.anchor < 0 ? 0 : t.anchor == 0 ? w / 2 : w);
    DrawText(big, x, int(std::lround(2 * t.y - 3.5 * scale)), t.text, t.colour, scale);
  }
  return Downsample2x(big);
}

}  // namespace lumislab
