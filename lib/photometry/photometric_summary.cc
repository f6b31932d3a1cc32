#include "lib/photometry/photometric_summary.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace lumislab {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

bool Seen(const std::vector<uint8_t>& seen, size_t k) { return seen.empty() || seen[k] != 0; }

// A pair's profile along one signed angle: -gamma in plane C + 180, gamma = 0 (one direction,
// read from plane C), +gamma in plane C.
struct Profile {
  std::vector<double> angle, value;
  std::vector<uint8_t> seen;
};

Profile PairProfile(const IntensityDistribution& d, const std::vector<uint8_t>& seen, int plus,
                    int minus) {
  Profile p;
  const size_t ng = d.gamma_deg.size();
  auto add = [&](int plane, size_t ig, double sign) {
    p.angle.push_back(sign * d.gamma_deg[ig]);
    p.value.push_back(d.At(plane, ig));
    p.seen.push_back(Seen(seen, plane * ng + ig));
  };
  for (size_t ig = ng; ig-- > 1;) add(minus, ig, -1);
  for (size_t ig = 0; ig < ng; ++ig) add(plus, ig, 1);
  return p;
}

// The signed angle where the profile first falls below `level` walking from `start` in steps
// of `dir` (+1, -1), linear between grid angles; NaN when it does not within the seen data, with
// *reached the last seen angle.
double Edge(const Profile& p, size_t start, int dir, double level, double* reached) {
  *reached = p.angle[start];
  for (std::ptrdiff_t k = std::ptrdiff_t(start) + dir; k >= 0 && k < std::ptrdiff_t(p.angle.size());
       k += dir) {
    if (!p.seen[k]) return kNan;
    if (p.value[k] < level) {
      const double a = p.value[k - dir], b = p.value[k];
      return p.angle[k - dir] + (a - level) / (a - b) * (p.angle[k] - p.angle[k - dir]);
    }
    *reached = p.angle[k];
  }
  return kNan;
}

// The full angle between the crossings of `fraction` x the peak on either side of it.
void Spread(const Profile& p, size_t peak, double fraction, double* angle, double* at_least,
            double* lo_out, double* hi_out) {
  const double level = fraction * p.value[peak];
  double reached_lo, reached_hi;
  const double lo = Edge(p, peak, -1, level, &reached_lo);
  const double hi = Edge(p, peak, +1, level, &reached_hi);
  *lo_out = lo;
  *hi_out = hi;
  *angle = std::isnan(lo) || std::isnan(hi) ? kNan : hi - lo;
  *at_least = (std::isnan(hi) ? reached_hi : hi) - (std::isnan(lo) ? reached_lo : lo);
}

}  // namespace

bool BeamSpreadOfPair(const IntensityDistribution& d, const std::vector<uint8_t>& seen,
                      double c_deg, BeamSpread* out) {
  const int p_plus = d.StoredPlane(c_deg), p_minus = d.StoredPlane(c_deg + 180);
  if (p_plus < 0 || p_minus < 0 || d.gamma_deg.front() > 1e-6) return false;
  const Profile p = PairProfile(d, seen, p_plus, p_minus);
  BeamSpread s;
  s.c_deg = c_deg;
  size_t peak = 0;
  for (size_t k = 0; k < p.value.size(); ++k)
    if (p.seen[k] && (!p.seen[peak] || p.value[k] > p.value[peak])) peak = k;
  if (!p.seen[peak] || !(p.value[peak] > 0)) return false;
  s.peak = p.value[peak];
  Spread(p, peak, 0.5, &s.beam_deg, &s.beam_at_least_deg, &s.beam_lo_deg, &s.beam_hi_deg);
  Spread(p, peak, 0.1, &s.field_deg, &s.field_at_least_deg, &s.field_lo_deg, &s.field_hi_deg);
  *out = s;
  return true;
}

int NemaBeamType(double field) {
  // NEMA FL 11 (floodlight beam classification), as the IES Lighting Handbook tabulates it:
  // the beam spread between the 10 %-of-peak directions.
  static const double kUpper[] = {18, 29, 46, 70, 100, 130};
  if (!(field >= 10)) return 0;
  for (int k = 0; k < 6; ++k)
    if (field <= kUpper[k]) return k + 1;
  return 7;
}

double SeenConeDeg(const IntensityDistribution& d, const std::vector<uint8_t>& seen) {
  const size_t ng = d.gamma_deg.size();
  double cone = 0;
  for (size_t ig = 0; ig < ng; ++ig) {
    for (size_t ic = 0; ic < d.c_deg.size(); ++ic)
      if (!Seen(seen, ic * ng + ig)) return cone;
    cone = d.gamma_deg[ig];
  }
  return cone;
}

std::string CieFluxCodeText(const std::array<double, 5>& code) {
  std::string text;
  for (double v : code) {
    if (!text.empty()) text += ' ';
    text += std::to_string(int(std::lround(v)));
  }
  return text;
}

PhotometricSummary SummarisePhotometry(const IntensityDistribution& d,
                                       const std::vector<uint8_t>& seen) {
  PhotometricSummary s;
  s.photometric = d.photometric;
  s.total_flux = d.TotalFlux();
  const size_t ng = d.gamma_deg.size();
  for (size_t ic = 0; ic < d.c_deg.size(); ++ic)
    for (size_t ig = 0; ig < ng; ++ig)
      if (Seen(seen, ic * ng + ig) && d.At(ic, ig) > s.peak) {
        s.peak = d.At(ic, ig);
        s.peak_c_deg = d.c_deg[ic];
        s.peak_gamma_deg = d.gamma_deg[ig];
      }
  for (double c : {0.0, 90.0, 45.0, 135.0}) {
    BeamSpread spread;
    if (BeamSpreadOfPair(d, seen, c, &spread)) s.spreads.push_back(spread);
  }
  const double top = d.gamma_deg.back();
  for (double lo = 0; lo < top - 1e-9; lo += 10) {
    ZonalFlux z;
    z.gamma_lo_deg = lo;
    z.gamma_hi_deg = std::min(lo + 10, 180.0);
    z.flux = d.FluxWithin(z.gamma_hi_deg) - d.FluxWithin(lo);
    z.percent = s.total_flux > 0 ? 100 * z.flux / s.total_flux : 0;
    s.zones.push_back(z);
  }
  // CIE 52 cones: solid angles pi/2, pi, 3 pi/2, 2 pi about gamma = 0, i.e. cos(half-angle) =
  // 3/4, 1/2, 1/4, 0.
  const double rad = 180 / 3.14159265358979323846;
  const double lower = d.FluxWithin(90);
  if (lower > 0) {
    s.cie_flux_code[0] = 100 * d.FluxWithin(std::acos(0.75) * rad) / lower;
    s.cie_flux_code[1] = 100 * d.FluxWithin(60) / lower;
    s.cie_flux_code[2] = 100 * d.FluxWithin(std::acos(0.25) * rad) / lower;
  }
  s.cie_flux_code[3] = s.total_flux > 0 ? 100 * lower / s.total_flux : 0;
  s.cie_flux_code[4] = 100;
  s.input_watts = d.input_watts;
  if (d.photometric && d.input_watts > 0) s.efficacy = s.total_flux / d.input_watts;
  return s;
}

}  // namespace lumislab
