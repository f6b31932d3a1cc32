#include "lib/photometry/eulumdat.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/input_file.h"
#include "core/log.h"

namespace lumislab {
namespace {

constexpr int kMaxLdtAngles = 100000;
constexpr char kRadiometricLamp[] = "radiometric: W/sr per 1000 W";
constexpr char kAbsoluteLamp[] = "luminaire (absolute photometry)";
constexpr char kUnknown[] = "-";  // a lamp text field that is not known

std::string TrimField(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

// A number as EULUMDAT files print it: a decimal comma is common (European software).
bool ParseNumber(std::string text, double* v) {
  text = TrimField(text);
  std::replace(text.begin(), text.end(), ',', '.');
  char* end = nullptr;
  *v = std::strtod(text.c_str(), &end);
  return !text.empty() && end != text.c_str() && *end == '\0' && std::isfinite(*v);
}

class Lines {
 public:
  Lines(const std::string& text, std::string name) : name_(std::move(name)) {
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      lines_.push_back(line);
    }
  }
  std::string Text(const std::string& field) {
    if (next_ >= lines_.size()) Truncated(field);
    return TrimField(lines_[next_++]);
  }
  double Number(const std::string& field) {
    const size_t line = next_ + 1;
    const std::string t = Text(field);
    double v;
    if (!ParseNumber(t, &v))
      throw BadInput(name_ + ": line " + std::to_string(line) + ": " + field +
                     ": expected a finite number, got \"" + t.substr(0, 40) + "\"");
    return v;
  }
  int Int(const std::string& field, int lo, int hi) {
    const size_t line = next_ + 1;
    const double v = Number(field);
    if (v != std::floor(v) || v < lo || v > hi)
      throw BadInput(name_ + ": line " + std::to_string(line) + ": " + field +
                     ": expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                     "], got " + Num(v, 8));
    return int(v);
  }
  // The rest of the file as whitespace-separated numbers (some writers put several on a line).
  void StartTokens() {
    for (size_t l = next_; l < lines_.size(); ++l) {
      std::istringstream in(lines_[l]);
      std::string token;
      while (in >> token) tokens_.push_back({token, l + 1});
    }
  }
  double Token(const std::string& field) {
    if (token_ >= tokens_.size()) Truncated(field);
    const auto& [text, line] = tokens_[token_++];
    double v;
    if (!ParseNumber(text, &v))
      throw BadInput(name_ + ": line " + std::to_string(line) + ": " + field +
                     ": expected a finite number, got \"" + text.substr(0, 40) + "\"");
    return v;
  }
  size_t TokensLeft() const { return tokens_.size() - token_; }
  size_t TokenLine() const { return token_ < tokens_.size() ? tokens_[token_].second : 0; }

 private:
  [[noreturn]] void Truncated(const std::string& field) const {
    throw BadInput(name_ + ": " + field + ": the file ends before it (truncated, or fewer " +
                   "values than its counts say)");
  }
  std::vector<std::string> lines_;
  std::vector<std::pair<std::string, size_t>> tokens_;
  size_t next_ = 0, token_ = 0;
  std::string name_;
};

// Every C plane over 360 degrees that the stored planes stand for under the symmetry.
std::vector<double> FullCircle(const std::vector<double>& c, CSymmetry symmetry) {
  std::set<long long> seen;
  std::vector<double> out;
  auto add = [&](double v) {
    v = std::fmod(v + 720.0, 360.0);
    const long long key = std::llround(v * 1e6);
    if (key == 360000000LL || !seen.insert(key).second) return;
    out.push_back(v);
  };
  for (double v : c) {
    add(v);
    if (symmetry == CSymmetry::kC0C180 || symmetry == CSymmetry::kQuadrant) add(360 - v);
    if (symmetry == CSymmetry::kC90C270 || symmetry == CSymmetry::kQuadrant) add(180 - v);
    if (symmetry == CSymmetry::kQuadrant) add(180 + v);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The step of an evenly spaced grid, or 0 when it is not.
double EvenStep(const std::vector<double>& v) {
  if (v.size() < 2) return 0;
  const double step = v[1] - v[0];
  for (size_t k = 2; k < v.size(); ++k)
    if (std::abs(v[k] - v[k - 1] - step) > 1e-6) return 0;
  return step;
}

}  // namespace

IntensityDistribution ParseEulumdat(const std::string& text, const std::string& name) {
  if (text.find('\0') != std::string::npos)
    throw BadInput(name + ": not an EULUMDAT file (binary content)");
  Lines in(text, name);
  IntensityDistribution d;
  d.format = "EULUMDAT";
  d.keywords.push_back({"MANUFAC", in.Text("line 1 (company)")});
  const int ityp = in.Int("line 2 (type indicator Ityp)", 0, 3);
  const int isym = in.Int("line 3 (symmetry indicator Isym)", 0, 4);
  const int mc = in.Int("line 4 (number of C planes Mc)", 1, kMaxLdtAngles);
  in.Number("line 5 (distance between C planes Dc)");
  const int ng = in.Int("line 6 (number of gamma angles Ng)", 2, kMaxLdtAngles);
  in.Number("line 7 (distance between gamma angles Dg)");
  d.keywords.push_back({"TEST", in.Text("line 8 (measurement report number)")});
  d.keywords.push_back({"LUMINAIRE", in.Text("line 9 (luminaire name)")});
  d.keywords.push_back({"LUMCAT", in.Text("line 10 (luminaire number)")});
  d.keywords.push_back({"_LDT_FILE_NAME", in.Text("line 11 (file name)")});
  d.keywords.push_back({"_LDT_DATE_USER", in.Text("line 12 (date, user)")});
  const double length = in.Number("line 13 (length or diameter of the luminaire)");
  const double width = in.Number("line 14 (width of the luminaire)");
  in.Number("line 15 (height of the luminaire)");
  const double area_length = in.Number("line 16 (length or diameter of the luminous area)");
  const double area_width = in.Number("line 17 (width of the luminous area)");
  const double area_height = in.Number("line 18 (height of the luminous area, C0)");
  for (int k = 19; k <= 21; ++k)
    in.Number("line " + std::to_string(k) + " (height of the luminous area)");
  in.Number("line 22 (downward flux fraction)");
  const double lorl = in.Number("line 23 (light output ratio)");
  const double conversion = in.Number("line 24 (conversion factor for luminous intensities)");
  in.Number("line 25 (tilt during measurement)");
  const int sets = in.Int("line 26 (number of standard sets of lamps)", 1, 100);
  double lamp_flux = 0;
  std::string lamp_type, colour_temperature, colour_rendering;
  for (int s = 0; s < sets; ++s) {
    const std::string set = " of lamp set " + std::to_string(s + 1);
    in.Number("line 26a (number of lamps" + set + ")");
    const std::string type = in.Text("line 26b (type of lamps" + set + ")");
    const double flux = in.Number("line 26c (total flux of lamps" + set + ")");
    const std::string cct = in.Text("line 26d (colour temperature" + set + ")");
    const std::string cri = in.Text("line 26e (colour rendering" + set + ")");
    const double watts = in.Number("line 26f (wattage" + set + ")");
    if (s == 0) {
      lamp_flux = flux;
      lamp_type = type;
      colour_temperature = cct;
      colour_rendering = cri;
      d.input_watts = watts;
    }
  }
  if (!(lamp_flux > 0))
    throw BadInput(name + ": line 26c (total flux of lamp set 1): expected a number > 0 (the " +
                   "intensities are per 1000 lm of it), got " + Num(lamp_flux, 8));
  d.keywords.push_back({"LAMP", lamp_type});
  if (!colour_temperature.empty() && colour_temperature != kUnknown)
    d.keywords.push_back({"COLORTEMP", colour_temperature});
  if (!colour_rendering.empty() && colour_rendering != kUnknown)
    d.keywords.push_back({"CRI", colour_rendering});
  d.keywords.push_back({"_LDT_LORL", Num(lorl, 6) + " %"});
  d.keywords.push_back({"_LDT_CONVERSION_FACTOR", Num(conversion, 6)});
  d.keywords.push_back({"_LDT_ITYP", std::to_string(ityp)});
  d.photometric = lamp_type != kRadiometricLamp;
  in.StartTokens();
  for (int k = 0; k < 10; ++k) in.Token("line 27 (direct ratio " + std::to_string(k + 1) + ")");
  std::vector<double> all_c(mc);
  for (int k = 0; k < mc; ++k) all_c[k] = in.Token("C angle " + std::to_string(k + 1));
  d.gamma_deg.resize(ng);
  for (int k = 0; k < ng; ++k) d.gamma_deg[k] = in.Token("gamma angle " + std::to_string(k + 1));
  // The planes the symmetry stores (EULUMDAT's Mc2 planes from the first one listed).
  double lo = 0, hi = 360;
  size_t expected = mc;
  switch (isym) {
    case 1:
      lo = hi = all_c[0];
      expected = 1;
      break;
    case 2:
      lo = 0;
      hi = 180;
      expected = mc / 2 + 1;
      break;
    case 3:
      lo = 90;
      hi = 270;
      expected = mc / 2 + 1;
      break;
    case 4:
      lo = 0;
      hi = 90;
      expected = mc / 4 + 1;
      break;
    default:
      break;
  }
  for (double c : all_c)
    if (isym == 0 || isym == 1 ? (isym == 0 || d.c_deg.empty())
                               : (c >= lo - 1e-6 && c <= hi + 1e-6))
      d.c_deg.push_back(c);
  if (d.c_deg.size() != expected)
    throw BadInput(name + ": line 28 (C angles): Isym " + std::to_string(isym) + " with Mc " +
                   std::to_string(mc) + " stores " + std::to_string(expected) +
                   " planes, but the C angles list " + std::to_string(d.c_deg.size()) +
                   " in its range");
  if (d.c_deg.size() * ng > in.TokensLeft())
    throw BadInput(name + ": the intensities: " + std::to_string(d.c_deg.size()) + " planes x " +
                   std::to_string(ng) + " angles, the file has " + std::to_string(in.TokensLeft()) +
                   " values left (truncated, or wrong counts)");
  d.values.resize(d.c_deg.size() * ng);
  for (size_t c = 0; c < d.c_deg.size(); ++c)
    for (int g = 0; g < ng; ++g)
      d.values[c * ng + g] =
          in.Token("intensity " + std::to_string(g + 1) + " of C plane " + Num(d.c_deg[c], 6)) *
          (lamp_flux / 1000.0);  // not (value * flux) / 1000: that overflows 1000 times sooner
  if (in.TokensLeft() > 0)
    throw BadInput(name + ": line " + std::to_string(in.TokenLine()) + ": " +
                   std::to_string(in.TokensLeft()) + " value(s) after the last intensity (the " +
                   "counts Mc, Ng or Isym do not match the data)");
  // Luminous area: width 0 is a round area of diameter `length` (LM-63: negative sizes).
  const double l = area_length > 0 ? area_length : length, w = area_length > 0 ? area_width : width;
  d.opening.length_mm = w == 0 ? -l : l;
  d.opening.width_mm = w == 0 ? -l : w;
  d.opening.height_mm = area_height;
  d.Check(name);
  return d;
}

IntensityDistribution ReadEulumdat(const std::string& path) {
  CheckInputFile(path, "EULUMDAT file");
  return ParseEulumdat(ReadTextFile(path), path);
}

std::array<double, 10> LdtDirectRatios(const IntensityDistribution& d) {
  // Luminaires spread evenly over the ceiling of a square room of side a (heights in units of h,
  // the luminaires' height above the work plane: a = 2k): a luminaire at p sends I(C, gamma)
  // sin(gamma) dgamma dC towards the work plane point p + tan(gamma) (cos C, sin C), and the
  // fraction of ceiling points p for which that point lies in the room is the overlap of two
  // squares shifted by (x, y): (1 - |x|/a)(1 - |y|/a). So the direct flux is the downward flux
  // weighed by that overlap. The definition (the part of the luminaires' downward flux falling
  // directly on the work plane, DIN 5040 / CIE 52's direct ratio) with no zonal
  // approximation: the zonal coefficients of holg/eulumdat-rs (calculations.rs
  // calculate_direct_ratios) give 0.50-0.53 at k = 0.6 for three files that publish 0.22-0.27,
  // this gives 0.21-0.26 (docs/formats.md §17). Midpoint sums, 1 degree in C, 0.25 in gamma.
  constexpr int kC = 360, kGamma = 360;
  constexpr double kDeg = kPi / 180;
  std::array<double, 10> direct{};
  // Intensities over the peak: a ratio, and sums of values near the largest double overflow.
  const double peak = *std::max_element(d.values.begin(), d.values.end());
  if (!(peak > 0)) return direct;
  double down = 0;
  for (int ig = 0; ig < kGamma; ++ig) {
    const double gamma = (ig + 0.5) * 90.0 / kGamma;
    const double t = std::tan(gamma * kDeg), s = std::sin(gamma * kDeg);
    for (int ic = 0; ic < kC; ++ic) {
      const double c = (ic + 0.5) * 360.0 / kC;
      const double flux = d.Intensity(c, gamma) / peak * s;
      if (flux == 0) continue;
      down += flux;
      const double x = std::abs(t * std::cos(c * kDeg)), y = std::abs(t * std::sin(c * kDeg));
      for (size_t k = 0; k < kLdtRoomIndices.size(); ++k) {
        const double a = 2 * kLdtRoomIndices[k];
        if (x < a && y < a) direct[k] += flux * (1 - x / a) * (1 - y / a);
      }
    }
  }
  if (down > 0)
    for (double& r : direct) r /= down;
  return direct;
}

std::string FormatEulumdat(const IntensityDistribution& d, const std::string& name,
                           const EulumdatWriteOptions& options) {
  d.Check(name);
  const double flux = d.TotalFlux();
  if (!(flux > 0))
    throw BadInput(name + ": the distribution has no flux (EULUMDAT stores intensities per " +
                   "1000 lm of it)");
  const CSymmetry symmetry = d.Symmetry();
  // Ityp: 1 a point source symmetric about the vertical axis, 2 linear, 3 a point source with
  // any other symmetry (holg/eulumdat-rs: eulumdat.rs TypeIndicator, whose parser refuses
  // anything but 1-3, and writer.rs, which writes 1 for Isym 1 and 3 otherwise). A slab does
  // not tell whether the luminaire is linear, so never 2.
  const int ityp = symmetry == CSymmetry::kAxial ? 1 : 3;
  int isym = 0;
  switch (symmetry) {
    case CSymmetry::kAxial:
      isym = 1;
      break;
    case CSymmetry::kC0C180:
      isym = 2;
      break;
    case CSymmetry::kC90C270:
      isym = 3;
      break;
    case CSymmetry::kQuadrant:
      isym = 4;
      break;
    case CSymmetry::kNone:
      isym = 0;
      break;
  }
  // The ends of the C range within the angle tolerance of a symmetry plane (a multiple of 90
  // degrees) are on it: their mirror images are themselves, where FullCircle would add a second
  // plane a hair away that the reader counts too, and C -1e-7 is 0, not 359.9999999 (both
  // found by fuzz_eulumdat: files the reader refused).
  std::vector<double> planes = d.c_deg;
  if (symmetry != CSymmetry::kAxial)
    for (double* end : {&planes.front(), &planes.back()}) {
      const double plane = 90 * std::round(*end / 90);
      if (std::abs(*end - plane) <= 1e-6) *end = plane;
    }
  std::vector<double> full = symmetry == CSymmetry::kAxial ? planes : FullCircle(planes, symmetry);
  std::vector<double> stored = planes;
  if (symmetry == CSymmetry::kNone && std::abs(stored.back() - 360) < 1e-6) stored.pop_back();
  // A text field: its first line, at most 78 bytes (the format's field width), no UTF-8
  // character split.
  auto field = [](const std::string& s) {
    return Utf8Head(s.substr(0, s.find_first_of("\r\n")), 78);
  };
  auto keyword_or = [&](const char* key, const std::string& fallback) {
    const std::string v = field(d.Keyword(key));
    return v.empty() ? fallback : v;
  };
  std::vector<LdtLampSet> sets = options.lamp_sets;
  if (sets.empty())
    sets.push_back({-1, d.photometric ? keyword_or("LAMP", kAbsoluteLamp) : kRadiometricLamp, flux,
                    keyword_or("COLORTEMP", kUnknown), keyword_or("CRI", kUnknown), d.input_watts});
  if (sets.size() > 100)
    throw BadInput(name + ": lamp sets: expected at most 100 (EULUMDAT line 26), got " +
                   std::to_string(sets.size()));
  for (size_t s = 0; s < sets.size(); ++s) {
    const std::string set = name + ": lamp set " + std::to_string(s + 1) + ": ";
    if (sets[s].count == 0)
      throw BadInput(set + "number of lamps: expected a count other than 0 (negative: absolute " +
                     "photometry), got 0");
    if (!(sets[s].flux_lm > 0) || !std::isfinite(sets[s].flux_lm))
      throw BadInput(set + "flux: expected a finite number > 0 (lm), got " +
                     Num(sets[s].flux_lm, 8));
    if (!(sets[s].watts >= 0) || !std::isfinite(sets[s].watts))
      throw BadInput(set + "wattage: expected a finite number >= 0 (W), got " +
                     Num(sets[s].watts, 8));
  }
  const double lamp_flux = sets[0].flux_lm;  // the intensities are per 1000 lm of it
  // One shape in IES and LDT alike: what EULUMDAT cannot hold (an ellipse, mixed signs) is
  // refused, not turned into a circle (issue 29 red team: -40,-30,0 became a 30 mm circle).
  CheckPortableOpening(d.opening, name, "luminous opening");
  const bool round = d.opening.width_mm < 0;  // then length = width: the diameter
  const double length = std::abs(d.opening.length_mm);
  const double width = round ? 0.0 : std::abs(d.opening.width_mm);
  const double height = std::abs(d.opening.height_mm);
  std::ostringstream os;
  os << keyword_or("MANUFAC", "lumislab") << "\n"
     << ityp << "\n"
     << isym << "\n"
     << full.size() << "\n"
     << Num(EvenStep(full), 8) << "\n"
     << d.gamma_deg.size() << "\n"
     << Num(EvenStep(d.gamma_deg), 8) << "\n"
     << keyword_or("TEST", "") << "\n"
     << keyword_or("LUMINAIRE", "") << "\n"
     << keyword_or("LUMCAT", "") << "\n";
  const std::string base = name.substr(name.find_last_of('/') + 1);
  os << field(base) << "\n"
     << field(TrimField(d.Keyword("ISSUEDATE") + " " + d.Keyword("TESTLAB"))) << "\n";
  for (double v : {length, width, height, length, width, height, height, height, height})
    os << Num(v, 8) << "\n";
  // Ratios first, then the scale (here and for the intensities below): with values near the
  // largest double, 100 * flux or value * 1000 overflowed to "inf", which the reader refuses
  // (found by fuzz_eulumdat).
  os << Num(d.FluxWithin(90) / flux * 100.0, 8) << "\n"  // DFF: gamma < 90 is downward
     << Num(flux / lamp_flux * 100.0, 8) << "\n"         // LORL
     << "1\n0\n"  // conversion factor 1 (cd/klm as written), tilt 0
     << sets.size() << "\n";
  for (const LdtLampSet& s : sets)
    os << s.count << "\n"
       << field(s.type) << "\n"
       << Num(s.flux_lm, 10) << "\n"
       << (field(s.colour_temperature).empty() ? kUnknown : field(s.colour_temperature)) << "\n"
       << (field(s.colour_rendering).empty() ? kUnknown : field(s.colour_rendering)) << "\n"
       << Num(s.watts, 8) << "\n";
  for (double r : LdtDirectRatios(d)) os << Num(r, 4) << "\n";
  // Angles with 15 digits: what was read is written back (Check wants them 1e-6 deg apart).
  for (double c : full) os << Num(c, 15) << "\n";
  for (double g : d.gamma_deg) os << Num(g, 15) << "\n";
  for (size_t c = 0; c < stored.size(); ++c)
    for (size_t g = 0; g < d.gamma_deg.size(); ++g)
      os << Num(d.At(c, g) / lamp_flux * 1000.0, 8) << "\n";
  // CR LF: the line ending of the format's DOS origins and of LM-63's text (the reader takes
  // both).
  std::string text;
  for (char ch : os.str()) {
    if (ch == '\n') text += '\r';
    text += ch;
  }
  return text;
}

void WriteEulumdat(const IntensityDistribution& d, const std::string& path,
                   const EulumdatWriteOptions& options) {
  WriteTextAtomically(path, FormatEulumdat(d, path, options));
}

}  // namespace lumislab
