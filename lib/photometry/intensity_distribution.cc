#include "lib/photometry/intensity_distribution.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/input_file.h"
#include "core/log.h"
#include "lib/photometry/eulumdat.h"
#include "lib/photometry/ies.h"

namespace lumislab {
namespace {

constexpr double kAngleTolerance = 1e-6;  // degrees: files print angles with a few decimals

bool Near(double a, double b) { return std::abs(a - b) <= kAngleTolerance; }

// Linear interpolation position of x in the increasing `grid`: *i0 and fraction *f towards
// i0 + 1. False outside [grid.front(), grid.back()].
bool Locate(const std::vector<double>& grid, double x, size_t* i0, double* f) {
  if (grid.size() == 1) {
    *i0 = 0;
    *f = 0;
    return Near(x, grid[0]);
  }
  if (x < grid.front() - kAngleTolerance || x > grid.back() + kAngleTolerance) return false;
  // The last k with grid[k] < x (or 0), at most size - 2.
  const size_t k = std::min<size_t>(
      grid.size() - 2, size_t(std::max<std::ptrdiff_t>(
                           0, std::lower_bound(grid.begin(), grid.end(), x) - grid.begin() - 1)));
  *i0 = k;
  *f = std::clamp((x - grid[k]) / (grid[k + 1] - grid[k]), 0.0, 1.0);
  return true;
}

// Zone of angle k of `grid` (degrees): halfway to its neighbours, the first and last ending at
// the grid's own ends.
void Zone(const std::vector<double>& grid, size_t k, double* lo, double* hi) {
  *lo = k == 0 ? grid[0] : 0.5 * (grid[k - 1] + grid[k]);
  *hi = k + 1 == grid.size() ? grid.back() : 0.5 * (grid[k] + grid[k + 1]);
}

// Solid-angle weight of each C plane (radians of azimuth), summing to 2 pi over the sphere.
std::vector<double> CWeights(const std::vector<double>& c, CSymmetry symmetry) {
  const size_t n = c.size();
  std::vector<double> w(n, 0.0);
  if (symmetry == CSymmetry::kAxial) {
    w[0] = 2 * kPi;
    return w;
  }
  const bool periodic = symmetry == CSymmetry::kNone && !Near(c.back(), 360);
  for (size_t k = 0; k < n; ++k) {
    double lo, hi;
    if (periodic) {
      lo = 0.5 * (c[k] + (k == 0 ? c[n - 1] - 360 : c[k - 1]));
      hi = 0.5 * (c[k] + (k + 1 == n ? c[0] + 360 : c[k + 1]));
    } else {
      Zone(c, k, &lo, &hi);
    }
    w[k] = (hi - lo) * kPi / 180;
  }
  const double range = periodic ? 360.0 : c.back() - c.front();
  for (double& x : w) x *= 360.0 / range;  // the symmetry repeats the stored range
  return w;
}

std::string Deg(double v) { return Num(v, 15) + " deg"; }
// Angles closer than kAngleTolerance are one angle to Near() and would divide by ~0 in Locate:
// each must exceed the one before by more (the writers print 15 digits, which keeps them apart).
std::string Apart() { return " by over " + Num(kAngleTolerance, 3) + " deg)"; }

}  // namespace

const char* CSymmetryName(CSymmetry s) {
  switch (s) {
    case CSymmetry::kAxial:
      return "axial (one C plane)";
    case CSymmetry::kQuadrant:
      return "quadrant (C 0-90)";
    case CSymmetry::kC0C180:
      return "bilateral about C0-C180 (C 0-180)";
    case CSymmetry::kC90C270:
      return "bilateral about C90-C270 (C 90-270)";
    case CSymmetry::kNone:
      return "none (C 0-360)";
  }
  return "?";
}

CSymmetry IntensityDistribution::Symmetry() const {
  if (c_deg.size() <= 1) return CSymmetry::kAxial;
  const double first = c_deg.front(), last = c_deg.back();
  if (Near(first, 0) && Near(last, 90)) return CSymmetry::kQuadrant;
  if (Near(first, 0) && Near(last, 180)) return CSymmetry::kC0C180;
  if (Near(first, 90) && Near(last, 270)) return CSymmetry::kC90C270;
  return CSymmetry::kNone;
}

void IntensityDistribution::Check(const std::string& file) const {
  if (c_deg.empty()) throw BadInput(file + ": no C plane (horizontal angle)");
  if (gamma_deg.size() < 2)
    throw InputError(file, "vertical angles", "at least 2 gamma angles",
                     std::to_string(gamma_deg.size()));
  if (values.size() != c_deg.size() * gamma_deg.size())
    throw BadInput(file + ": " + std::to_string(values.size()) + " intensity values for " +
                   std::to_string(c_deg.size()) + " C planes x " +
                   std::to_string(gamma_deg.size()) + " gamma angles");
  for (size_t k = 0; k < gamma_deg.size(); ++k) {
    if (!std::isfinite(gamma_deg[k]) || gamma_deg[k] < -kAngleTolerance ||
        gamma_deg[k] > 180 + kAngleTolerance)
      throw InputError(file, "vertical angle " + std::to_string(k + 1), "a number in [0, 180]",
                       Num(gamma_deg[k], 8));
    if (k > 0 && !(gamma_deg[k] > gamma_deg[k - 1] + kAngleTolerance))
      throw InputError(file, "vertical angle " + std::to_string(k + 1),
                       "more than the one before (" + Deg(gamma_deg[k - 1]) + Apart(),
                       Num(gamma_deg[k], 15));
  }
  for (size_t k = 0; k < c_deg.size(); ++k) {
    if (!std::isfinite(c_deg[k]))
      throw InputError(file, "horizontal angle " + std::to_string(k + 1), "a finite number",
                       Num(c_deg[k], 8));
    if (k > 0 && !(c_deg[k] > c_deg[k - 1] + kAngleTolerance))
      throw InputError(file, "horizontal angle " + std::to_string(k + 1),
                       "more than the one before (" + Deg(c_deg[k - 1]) + Apart(),
                       Num(c_deg[k], 15));
  }
  if (c_deg.size() > 1 && Symmetry() == CSymmetry::kNone &&
      !(Near(c_deg.front(), 0) && c_deg.back() > 180 && c_deg.back() <= 360 + kAngleTolerance))
    throw InputError(file, "horizontal angles",
                     "a type C range: 0 (one plane), 0-90, 0-180, 90-270 or 0-360",
                     Num(c_deg.front(), 8) + " to " + Num(c_deg.back(), 8));
  for (size_t ic = 0; ic < c_deg.size(); ++ic)
    for (size_t ig = 0; ig < gamma_deg.size(); ++ig) {
      const double v = At(ic, ig);
      if (!std::isfinite(v) || v < 0)
        throw InputError(file,
                         "intensity at C " + Num(c_deg[ic], 8) + ", gamma " + Num(gamma_deg[ig], 8),
                         "a finite number >= 0", std::isfinite(v) ? Num(v, 8) : "not a number");
    }
  // A size in feet near the largest double overflows in mm, and the writers would print "inf"
  // (fuzz_ies; lumislab-export's --opening-mm nan,1,1 wrote "nan").
  for (const auto& [field, v] : {std::pair<const char*, double>{"luminous width", opening.width_mm},
                                 {"luminous length", opening.length_mm},
                                 {"luminous height", opening.height_mm}})
    if (!std::isfinite(v)) throw InputError(file, field, "a finite size (mm)", Num(v, 8));
  // Values near the largest double pass one by one, and their flux overflows (fuzz_ies).
  if (!std::isfinite(TotalFlux()))
    throw InputError(file, "intensity values", "values whose total flux is a finite number",
                     "values so large that it overflows (largest " +
                         Num(*std::max_element(values.begin(), values.end()), 8) + ")");
}

void CheckPortableOpening(const LuminousOpening& o, const std::string& where,
                          const std::string& field) {
  const double w = o.width_mm, l = o.length_mm, h = o.height_mm;
  const bool finite = std::isfinite(w) && std::isfinite(l) && std::isfinite(h);
  const bool point = w == 0 && l == 0 && h >= 0;  // EULUMDAT: a round area of diameter 0
  const bool box = w > 0 && l > 0 && h >= 0;
  const bool round = w < 0 && l == w && h >= 0;
  if (finite && (point || box || round)) return;
  throw InputError(
      where, field,
      "an opening IES and EULUMDAT both hold (width,length,height mm): 0,0,height "
      ">= 0 (a point), both sides > 0 and height >= 0 (a rectangle or box), or -D,-D,height "
      ">= 0 (a circle or vertical cylinder of diameter D)",
      Num(w, 8) + "," + Num(l, 8) + "," + Num(h, 8) +
          (finite && w < 0 && l < 0 && w != l ? " (an ellipse: EULUMDAT has none)"
           : finite && h < 0                  ? " (a negative height: EULUMDAT has none)"
                                              : ""));
}

double IntensityDistribution::Intensity(double c_in, double gamma) const {
  size_t ig;
  double fg;
  if (!Locate(gamma_deg, gamma, &ig, &fg)) return 0;
  auto along_gamma = [&](size_t ic) {
    const double a = At(ic, ig);
    return fg > 0 ? a + fg * (At(ic, ig + 1) - a) : a;
  };
  const CSymmetry symmetry = Symmetry();
  if (symmetry == CSymmetry::kAxial) return along_gamma(0);
  const double c = StoredC(c_in);
  if (symmetry == CSymmetry::kNone && c > c_deg.back()) {  // periodic gap: last -> 360 (= 0)
    const double f = (c - c_deg.back()) / (360 - c_deg.back());
    const double a = along_gamma(c_deg.size() - 1), b = along_gamma(0);
    return a + f * (b - a);
  }
  size_t ic;
  double fc;
  if (!Locate(c_deg, c, &ic, &fc)) return 0;
  const double a = along_gamma(ic);
  return fc > 0 ? a + fc * (along_gamma(ic + 1) - a) : a;
}

double IntensityDistribution::StoredC(double c_in) const {
  const CSymmetry symmetry = Symmetry();
  if (symmetry == CSymmetry::kAxial) return c_deg.front();
  double c = std::fmod(c_in, 360.0);
  if (c < 0) c += 360;
  switch (symmetry) {
    case CSymmetry::kQuadrant:
      if (c > 180) c = 360 - c;
      if (c > 90) c = 180 - c;
      break;
    case CSymmetry::kC0C180:
      if (c > 180) c = 360 - c;
      break;
    case CSymmetry::kC90C270:
      if (c < 90) c = 180 - c;
      if (c > 270) c = 540 - c;
      break;
    default:
      break;
  }
  return c;
}

int IntensityDistribution::StoredPlane(double c_in) const {
  const double c = StoredC(c_in);
  for (size_t k = 0; k < c_deg.size(); ++k)
    if (Near(c, c_deg[k]) || (Near(c, 0) && Near(c_deg[k], 360))) return int(k);
  return -1;
}

double IntensityDistribution::FluxWithin(double gamma_max_deg) const {
  const std::vector<double> cw = CWeights(c_deg, Symmetry());
  double flux = 0;
  for (size_t ig = 0; ig < gamma_deg.size(); ++ig) {
    double lo, hi;
    Zone(gamma_deg, ig, &lo, &hi);
    hi = std::min(hi, gamma_max_deg);
    if (!(hi > lo)) continue;
    const double zone = std::cos(lo * kPi / 180) - std::cos(hi * kPi / 180);
    for (size_t ic = 0; ic < c_deg.size(); ++ic) flux += At(ic, ig) * cw[ic] * zone;
  }
  return flux;
}

double IntensityDistribution::TotalFlux() const { return FluxWithin(180); }

std::string IntensityDistribution::Keyword(const std::string& name) const {
  for (const auto& [key, value] : keywords)
    if (key == name) return value;
  return "";
}

IntensityDistribution ReadIntensityFile(const std::string& path) {
  CheckInputFile(path, "photometric file");
  const std::string text = ReadTextFile(path);
  std::istringstream in(text);
  std::string first;
  std::getline(in, first);
  if (first.rfind("IES", 0) == 0 || text.find("TILT=") != std::string::npos)
    return ParseIes(text, path);
  return ParseEulumdat(text, path);
}

}  // namespace lumislab
