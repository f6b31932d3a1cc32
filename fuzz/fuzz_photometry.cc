#include "fuzz/fuzz_photometry.h"

#include <algorithm>
#include <cmath>

#include "core/log.h"

namespace lumislab::fuzz {

void CheckDistribution(const IntensityDistribution& d, const std::string& format) {
  const double flux = d.TotalFlux();
  if (!std::isfinite(flux) || flux < 0)
    Finding(format + ": an accepted distribution's total flux is " + Num(flux, 8));
  const double peak = *std::max_element(d.values.begin(), d.values.end());
  for (double c = -30; c <= 390; c += 7.5)
    for (double gamma = 0; gamma <= 180; gamma += 2.5) {
      const double v = d.Intensity(c, gamma);
      if (!std::isfinite(v) || v < 0 || v > peak * (1 + 1e-12))
        Finding(format + ": Intensity(C " + Num(c, 6) + ", gamma " + Num(gamma, 6) + ") is " +
                Num(v, 8) + ", outside [0, " + Num(peak, 8) + "]");
    }
}

void CheckSameDistribution(const IntensityDistribution& d, const IntensityDistribution& back,
                           const std::string& format) {
  auto same_angles = [](const std::vector<double>& a, const std::vector<double>& b, size_t n) {
    for (size_t k = 0; k < n; ++k)
      if (std::abs(a[k] - b[k]) > 1e-5) return false;
    return true;
  };
  const bool closed = d.Symmetry() == CSymmetry::kNone && std::abs(d.c_deg.back() - 360) <= 1e-6;
  const size_t nc = back.c_deg.size();
  if (back.gamma_deg.size() != d.gamma_deg.size() ||
      !same_angles(d.gamma_deg, back.gamma_deg, d.gamma_deg.size()) ||
      !(nc == d.c_deg.size() || (closed && nc + 1 == d.c_deg.size())) ||
      !same_angles(d.c_deg, back.c_deg, nc))
    Finding(format + ": writing and reading back changed the grid: " +
            std::to_string(d.c_deg.size()) + " x " + std::to_string(d.gamma_deg.size()) + " -> " +
            std::to_string(nc) + " x " + std::to_string(back.gamma_deg.size()));
  if (nc != d.c_deg.size()) return;  // the 360 plane left out: the flux may differ
  const double a = d.TotalFlux(), b = back.TotalFlux();
  if (std::abs(a - b) > 1e-5 * std::max(std::abs(a), std::abs(b)))
    Finding(format + ": writing and reading back changed the flux: " + Num(a, 10) + " -> " +
            Num(b, 10));
}

}  // namespace lumislab::fuzz
