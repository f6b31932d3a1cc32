#include "lib/lightfield/false_colour.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"

namespace lumislab {
namespace {

// Viridis at t = k/8 (docs in the header).
constexpr Rgb8 kViridis[9] = {{68, 1, 84},    {71, 44, 122},  {59, 81, 139},
                              {44, 113, 142}, {33, 144, 141}, {39, 173, 129},
                              {92, 200, 99},  {170, 220, 50}, {253, 231, 37}};

const Rgb8 kPanel{32, 32, 32};       // the bar panel's background
const Rgb8 kText{235, 235, 235};     // labels on the panel
const Rgb8 kNoValue{128, 128, 128};  // NaN pixels
const Rgb8 kBlack{0, 0, 0}, kWhite{255, 255, 255};

// The linear tick step for [lo, hi]: 1, 2 or 5 x 10^k, the smallest giving at most 8 intervals.
double LinearStep(double lo, double hi) {
  const double range = hi - lo;
  if (!(range > 0)) return 1;
  const double magnitude = std::pow(10.0, std::floor(std::log10(range / 8)));
  for (const double m : {1.0, 2.0, 5.0, 10.0})
    if (range / (m * magnitude) <= 8 + 1e-9) return m * magnitude;
  return 10 * magnitude;
}

std::vector<double> LinearTicks(double lo, double hi) {
  const double step = LinearStep(lo, hi);
  std::vector<double> ticks;
  for (double k = std::ceil(lo / step - 1e-9); k <= std::floor(hi / step + 1e-9); ++k)
    ticks.push_back(k * step);
  return ticks;
}

// Black or white, whichever stands out on colour c (by its Rec. 709 luma: a display colour,
// not a photometric quantity).
Rgb8 ContrastingColour(Rgb8 c) {
  return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b > 110 ? kBlack : kWhite;
}

double Measure(double value, bool log) {
  if (!log) return value;
  return value > 0 ? std::log10(value) : -1e30;
}

// A nice length (1, 2 or 5 x 10^k mm) at most `target` mm, and its label.
std::pair<double, std::string> ScaleBarLength(double target_mm) {
  const double magnitude = std::pow(10.0, std::floor(std::log10(target_mm)));
  double length = magnitude;
  for (const double m : {2.0, 5.0})
    if (m * magnitude <= target_mm) length = m * magnitude;
  const std::string label = length >= 1000 ? FormatTick(length / 1000, length / 1000) + " m"
                                           : FormatTick(length, length) + " mm";
  return {length, label};
}

void DrawScaleBar(Rgb8Image& image, int width, int height, double mm_per_pixel, int s) {
  const auto [length_mm, label] = ScaleBarLength(width / 4.0 * mm_per_pixel);
  const int pixels = int(std::lround(length_mm / mm_per_pixel));
  const int x0 = 8 * s, y0 = height - 10 * s;
  FillRect(image, x0 - s, y0 - 12 * s, x0 + std::max(pixels, TextWidth(label, s)) + s, y0 + 5 * s,
           kBlack);
  FillRect(image, x0, y0, x0 + pixels, y0 + 3 * s, kWhite);
  DrawText(image, x0, y0 - 10 * s, label, kWhite, s);
}

}  // namespace

Rgb8 Viridis(double t) {
  if (!(t > 0)) return kViridis[0];
  if (t >= 1) return kViridis[8];
  const double x = t * 8;
  const int k = std::min(7, int(x));
  const double f = x - k;
  auto mix = [f](uint8_t a, uint8_t b) { return uint8_t(std::lround(a + f * (double(b) - a))); };
  const Rgb8 &a = kViridis[k], &b = kViridis[k + 1];
  return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
}

double FalseColourScale::Position(double value) const {
  const double lo = Measure(min, log), hi = Measure(max, log), v = Measure(value, log);
  if (!(v > lo)) return 0;
  return std::min(1.0, (v - lo) / (hi - lo));
}

std::vector<double> FalseColourScale::Ticks() const {
  if (!log) return LinearTicks(min, max);
  const bool fine = std::log10(max / min) <= 3 + 1e-9;  // the automatic 3 decades included
  std::vector<double> ticks;
  for (int e = int(std::floor(std::log10(min))); e <= int(std::ceil(std::log10(max))); ++e)
    for (const double m : {1.0, 2.0, 5.0}) {
      const double v = m * std::pow(10.0, e);
      if ((m == 1 || fine) && v >= min * (1 - 1e-9) && v <= max * (1 + 1e-9)) ticks.push_back(v);
    }
  return ticks.size() >= 2 ? ticks : LinearTicks(min, max);
}

void FalseColourScale::Check(const std::string& what) const {
  if (!std::isfinite(min) || !std::isfinite(max) || !(min < max))
    throw InputError(what, "range", "min < max, both finite",
                     std::to_string(min) + ":" + std::to_string(max));
  if (log && !(min > 0))
    throw InputError(what, "range", "min > 0 on a log scale", std::to_string(min));
}

FalseColourScale AutoScale(const std::vector<float>& values, bool log) {
  // The 99.5th percentile, not the maximum: a hot spot of a few pixels (a wall next to the
  // luminaire) would otherwise squeeze the rest of the picture into the bottom colours.
  std::vector<float> lit;
  for (const float v : values)
    if (v > 0 && std::isfinite(v)) lit.push_back(v);
  FalseColourScale scale;
  scale.log = log;
  double top = 0;
  if (!lit.empty()) {
    const size_t k = std::min(lit.size() - 1, size_t(lit.size() * 0.995));
    std::nth_element(lit.begin(), lit.begin() + k, lit.end());
    top = lit[k];
  }
  if (!(top > 0)) {
    scale.min = log ? 1e-3 : 0;
    scale.max = 1;
  } else if (log) {
    scale.max = std::pow(10.0, std::ceil(std::log10(top)));
    scale.min = scale.max / 1000;
  } else {
    const double step = LinearStep(0, top);
    scale.min = 0;
    scale.max = std::ceil(top / step - 1e-9) * step;
  }
  return scale;
}

std::vector<float> PixelLuminance(const ImageF& image, const Eigen::Vector3d& channel_weights) {
  const Eigen::Vector3d& w = channel_weights;
  std::vector<float> out(size_t(image.width) * image.height);
  for (size_t p = 0; p < out.size(); ++p) {
    const float* v = &image.data[p * image.channels];
    out[p] = image.channels >= 3 ? float(w.x() * v[0] + w.y() * v[1] + w.z() * v[2]) : v[0];
  }
  return out;
}

std::vector<uint8_t> IsoLineMask(const std::vector<float>& values, int width, int height,
                                 const std::vector<double>& levels, bool log) {
  std::vector<uint8_t> mask(values.size(), 0);
  std::vector<double> measured_levels;
  for (const double level : levels) measured_levels.push_back(Measure(level, log));
  auto pair = [&](size_t p, size_t n) {
    const double a = Measure(values[p], log), b = Measure(values[n], log);
    if (std::isnan(a) || std::isnan(b)) return;
    for (const double level : measured_levels)
      if ((a < level) != (b < level)) mask[std::abs(a - level) <= std::abs(b - level) ? p : n] = 1;
  };
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t p = size_t(y) * width + x;
      if (x + 1 < width) pair(p, p + 1);
      if (y + 1 < height) pair(p, p + width);
    }
  return mask;
}

int BarPanelWidth(int height) { return 92 * std::max(1, height / 320); }

Rgb8Image RenderFalseColour(const std::vector<float>& values, int width, int height,
                            const FalseColourOptions& options) {
  const FalseColourScale& scale = options.scale;
  scale.Check("false-colour scale");
  if (values.size() != size_t(width) * height)
    throw Failure("false colour: " + std::to_string(values.size()) + " values for a " +
                  std::to_string(width) + "x" + std::to_string(height) + " picture");
  const int s = std::max(1, height / 320);  // text and bar scale
  const int total_height = std::max(height, 120 * s);
  const std::string unit_line = options.unit + (scale.log ? " (log)" : "");
  Rgb8Image image(width + std::max(BarPanelWidth(height), TextWidth(unit_line, s) + 20 * s),
                  total_height, kPanel);
  const std::vector<double> ticks = scale.Ticks();
  // No iso-line at the bottom tick: at 0 it would outline every unlit surface.
  std::vector<double> levels;
  for (const double tick : ticks)
    if (scale.Position(tick) > 1e-9) levels.push_back(tick);
  const std::vector<uint8_t> iso = options.iso_lines
                                       ? IsoLineMask(values, width, height, levels, scale.log)
                                       : std::vector<uint8_t>(values.size(), 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t p = size_t(y) * width + x;
      const Rgb8 c = std::isnan(values[p]) ? kNoValue : Viridis(scale.Position(values[p]));
      image.Set(x, y, c);
      if (iso[p]) image.Set(x, y, ContrastingColour(c), 0.85);
    }
  if (options.mm_per_pixel > 0) DrawScaleBar(image, width, height, options.mm_per_pixel, s);
  if (!options.title.empty()) {
    FillRect(image, 0, 0, TextWidth(options.title, s) + 8 * s, 13 * s, kBlack);
    DrawText(image, 4 * s, 3 * s, options.title, kWhite, s);
  }

  // The bar: top = max, bottom = min; a tick (and the iso-line's colour across the bar) at each
  // level, labelled to its right; the unit above it.
  const int bar_x0 = width + 10 * s, bar_x1 = bar_x0 + 16 * s;
  const int bar_y0 = 24 * s, bar_y1 = total_height - 10 * s;
  DrawText(image, bar_x0, 8 * s, unit_line, kText, s);
  for (int y = bar_y0; y < bar_y1; ++y) {
    const Rgb8 c = Viridis(1.0 - double(y - bar_y0) / (bar_y1 - 1 - bar_y0));
    FillRect(image, bar_x0, y, bar_x1, y + 1, c);
  }
  const double step = scale.log ? 0 : LinearStep(scale.min, scale.max);
  for (const double tick : ticks) {
    const double t = scale.Position(tick);
    const int y = int(std::lround(bar_y1 - 1 - t * (bar_y1 - 1 - bar_y0)));
    FillRect(image, bar_x0, y, bar_x1, y + s, ContrastingColour(Viridis(t)));
    FillRect(image, bar_x1, y, bar_x1 + 5 * s, y + s, kText);
    const int text_y = std::clamp(y - 3 * s, bar_y0 - 4 * s, total_height - 8 * s);
    DrawText(image, bar_x1 + 8 * s, text_y, FormatTick(tick, scale.log ? tick : step), kText, s);
  }
  return image;
}

FalseColourScale FalseColourRequest::Resolve(const std::vector<float>& values) const {
  if (!(max > min)) return AutoScale(values, log);
  FalseColourScale scale{min, max, log};
  scale.Check("false-colour range");
  return scale;
}

void ParseFalseColourRange(const std::string& text, const std::string& option,
                           FalseColourRequest* request) {
  if (text == "auto") {
    request->min = request->max = 0;
    return;
  }
  const size_t colon = text.find(':');
  double min = NAN, max = NAN;
  try {
    size_t used_min = 0, used_max = 0;
    min = std::stod(text.substr(0, colon), &used_min);
    max = std::stod(text.substr(colon + 1), &used_max);
    if (colon == std::string::npos || used_min != colon || used_max != text.size() - colon - 1)
      min = max = NAN;
  } catch (const std::exception&) {
    min = max = NAN;
  }
  FalseColourScale scale{min, max, request->log};
  if (std::isnan(min) || std::isnan(max))
    throw InputError(option, "", "min:max (e.g. 0:500) or auto", text);
  scale.Check(option);
  request->min = min;
  request->max = max;
}

Rgb8Image FalseColourPicture(const ImageF& irradiance, const Eigen::Vector3d& channel_weights,
                             const FalseColourRequest& request, const std::string& unit,
                             double mm_per_pixel, const std::string& title) {
  const std::vector<float> values = PixelLuminance(irradiance, channel_weights);
  FalseColourOptions options;
  options.scale = request.Resolve(values);
  options.unit = unit;
  options.mm_per_pixel = mm_per_pixel;
  options.title = title;
  return RenderFalseColour(values, irradiance.width, irradiance.height, options);
}

std::string FormatTick(double value, double step) {
  char text[32];
  if (std::abs(value) < 1e-9 * std::abs(step)) value = 0;  // no "-0.0" from k * step
  const double magnitude = std::abs(value);
  if (magnitude >= 1e6 || (magnitude > 0 && magnitude < 1e-3)) {
    std::snprintf(text, sizeof text, "%.3g", value);
  } else {
    const int decimals = std::max(0, int(-std::floor(std::log10(std::abs(step)) + 1e-9)));
    std::snprintf(text, sizeof text, "%.*f", std::min(decimals, 6), value);
  }
  return text;
}

std::string IrradianceUnitLabel(const std::string& slab_units) {
  if (slab_units == "lux") return "lx";
  if (slab_units == "W/m^2") return "W/m\u00B2";
  return slab_units;
}

std::string IntensityUnitLabel(const std::string& slab_units) {
  if (slab_units == "lux") return "cd";
  if (slab_units == "W/m^2") return "W/sr";
  return slab_units;
}

}  // namespace lumislab
