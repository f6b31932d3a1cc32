#include "export/report_svg.h"

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/atomic_file.h"
#include "core/log.h"
#include "lib/lightfield/false_colour.h"
#include "lib/photo/photo_write.h"

namespace lumislab {

std::string Fmt(double v, int digits) { return std::isfinite(v) ? Num(v, digits) : "\u2014"; }

std::string Deg(double v, int decimals) {
  if (!std::isfinite(v)) return "\u2014";
  char text[32];
  std::snprintf(text, sizeof text, "%.*f\u00B0", decimals, v);
  return text;
}

std::vector<double> NiceTicks(double lo, double hi, double* step) {
  FalseColourScale scale;
  scale.min = 0;
  scale.max = hi - lo > 0 ? hi - lo : 1;
  const std::vector<double> t = scale.Ticks();
  *step = t.size() >= 2 ? t[1] - t[0] : scale.max;
  std::vector<double> ticks;
  for (double v = std::ceil(lo / *step - 1e-9) * *step; v <= hi + 1e-9 * *step; v += *step)
    ticks.push_back(std::abs(v) < 1e-12 * *step ? 0 : v);
  return ticks;
}

std::string SvgAxes::Open(const std::string& x_title, const std::string& y_title) const {
  std::ostringstream os;
  os.precision(5);
  os << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
     << "\" viewBox=\"0 0 " << width << " " << height
     << "\" font-family=\"sans-serif\" font-size=\"10\">\n";
  os << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << width - left - right
     << "\" height=\"" << height - top - bottom << "\" fill=\"white\" stroke=\"#555\"/>\n";
  double step;
  for (double t : NiceTicks(x0, x1, &step)) {
    os << "<line x1=\"" << X(t) << "\" y1=\"" << top << "\" x2=\"" << X(t) << "\" y2=\""
       << height - bottom << "\" stroke=\"#ddd\"/><text x=\"" << X(t) << "\" y=\""
       << height - bottom + 12 << "\" text-anchor=\"middle\">" << FormatTick(t, step)
       << "</text>\n";
  }
  for (double t : NiceTicks(y0, y1, &step)) {
    os << "<line x1=\"" << left << "\" y1=\"" << Y(t) << "\" x2=\"" << width - right << "\" y2=\""
       << Y(t) << "\" stroke=\"#ddd\"/><text x=\"" << left - 4 << "\" y=\"" << Y(t) + 3
       << "\" text-anchor=\"end\">" << FormatTick(t, step) << "</text>\n";
  }
  os << "<text x=\"" << (left + width - right) / 2 << "\" y=\"" << height - 6
     << "\" text-anchor=\"middle\">" << XmlEscape(x_title) << "</text>\n";
  os << "<text transform=\"translate(11," << (top + height - bottom) / 2
     << ") rotate(-90)\" text-anchor=\"middle\">" << XmlEscape(y_title) << "</text>\n";
  return os.str();
}

std::string SvgAxes::Polyline(const std::vector<double>& x, const std::vector<double>& y,
                              const std::string& colour, double width_px, double dash) const {
  std::ostringstream os;
  os.precision(5);
  std::string points;
  auto flush = [&] {
    if (points.empty()) return;
    os << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"" << width_px << "\"";
    if (dash > 0) os << " stroke-dasharray=\"" << dash << "," << dash << "\"";
    os << " points=\"" << points << "\"/>\n";
    points.clear();
  };
  for (size_t k = 0; k < x.size(); ++k) {
    if (!std::isfinite(x[k]) || !std::isfinite(y[k])) {
      flush();
      continue;
    }
    std::ostringstream p;
    p.precision(5);
    p << X(x[k]) << "," << Y(y[k]) << " ";
    points += p.str();
  }
  flush();
  return os.str();
}

std::string ContourPath(const std::vector<double>& v, int nx, int ny, double level,
                        const std::function<std::pair<double, double>(double, double)>& page,
                        const std::vector<uint8_t>& valid) {
  std::ostringstream os;
  os.precision(5);
  for (int iy = 0; iy + 1 < ny; ++iy)
    for (int ix = 0; ix + 1 < nx; ++ix) {
      // Corners in order around the cell: (ix, iy), (ix+1, iy), (ix+1, iy+1), (ix, iy+1).
      const int cx[4] = {ix, ix + 1, ix + 1, ix}, cy[4] = {iy, iy, iy + 1, iy + 1};
      double value[4];
      bool ok = true;
      for (int k = 0; k < 4; ++k) {
        const size_t at = size_t(cy[k]) * nx + cx[k];
        value[k] = v[at];
        ok = ok && (valid.empty() || valid[at]);
      }
      if (!ok) continue;
      std::vector<std::pair<double, double>> cross;
      for (int k = 0; k < 4; ++k) {
        const int n = (k + 1) % 4;
        const bool a = value[k] >= level, b = value[n] >= level;
        if (a == b) continue;
        const double f = (level - value[k]) / (value[n] - value[k]);
        cross.push_back(page(cx[k] + f * (cx[n] - cx[k]), cy[k] + f * (cy[n] - cy[k])));
      }
      for (size_t k = 0; k + 1 < cross.size(); k += 2)
        os << "M" << cross[k].first << " " << cross[k].second << "L" << cross[k + 1].first << " "
           << cross[k + 1].second;
    }
  return os.str();
}

std::string PngDataUri(const Rgb8Image& image) {
  namespace fs = std::filesystem;
  static std::atomic<int> count{0};
  const std::string tmp =
      (fs::temp_directory_path() /
       ("lumislab_report_" + std::to_string(getpid()) + "_" + std::to_string(count++) + ".png"))
          .string();
  WriteRgb8File(tmp, image.width, image.height, image.rgb);
  const std::string bytes = ReadTextFile(tmp);
  fs::remove(tmp);
  static const char kTable[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out = "data:image/png;base64,";
  for (size_t k = 0; k < bytes.size(); k += 3) {
    const uint32_t b0 = uint8_t(bytes[k]), b1 = k + 1 < bytes.size() ? uint8_t(bytes[k + 1]) : 0,
                   b2 = k + 2 < bytes.size() ? uint8_t(bytes[k + 2]) : 0;
    const uint32_t triple = (b0 << 16) | (b1 << 8) | b2;
    out += kTable[(triple >> 18) & 63];
    out += kTable[(triple >> 12) & 63];
    out += k + 1 < bytes.size() ? kTable[(triple >> 6) & 63] : '=';
    out += k + 2 < bytes.size() ? kTable[triple & 63] : '=';
  }
  return out;
}

}  // namespace lumislab
