// The numbers a photometric report leads with, computed from an IntensityDistribution (type C,
// intensity_distribution.h): flux, peak, beam and field angles per C-plane pair, the NEMA beam
// type, zonal lumens, the CIE flux code, efficacy. The report and `lumislab-export info` take
// them from here. Directions are the distribution's own (C, gamma): nothing here assumes which
// way C = 90 points.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "lib/photometry/intensity_distribution.h"

namespace lumislab {

// Beam (50 % of the pair's peak) and field (10 %) angles across one C-plane pair: the profile
// runs from gamma in plane C + 180 through gamma = 0 to gamma in plane C. Each edge is the first
// crossing going outwards from the pair's peak, linear in gamma between grid angles. An edge the
// data does not reach (the stored gamma range ends, or a direction the capture did not see comes
// first) leaves the angle NaN and `*_at_least_deg` the spread to the last seen angle.
struct BeamSpread {
  double c_deg = 0;     // the pair: planes C and C + 180
  double peak = 0;      // the pair's largest intensity (cd or W/sr)
  double beam_deg = 0;  // full angle between the 50 % edges; NaN: not reached
  double field_deg = 0;
  double beam_at_least_deg = 0;  // when beam_deg is NaN: the spread the data covers
  double field_at_least_deg = 0;
  // The edges as signed angles (degrees: + in plane C, - in plane C + 180); an edge not reached
  // is NaN.
  double beam_lo_deg = 0, beam_hi_deg = 0, field_lo_deg = 0, field_hi_deg = 0;
};

// One gamma zone [lo, hi): its flux (lm or W) and share of the total (%).
struct ZonalFlux {
  double gamma_lo_deg = 0, gamma_hi_deg = 0;
  double flux = 0;
  double percent = 0;
};

struct PhotometricSummary {
  bool photometric = true;  // lm, cd (else W, W/sr)
  double total_flux = 0;    // the zonal sum over every stored direction (TotalFlux)
  double peak = 0;          // largest intensity and its direction
  double peak_c_deg = 0, peak_gamma_deg = 0;
  std::vector<BeamSpread> spreads;  // C0-C180, C90-C270, then C45-C225, C135-C315 if stored
  std::vector<ZonalFlux> zones;     // 10-degree gamma zones over the stored gamma range
  // CIE 52 flux code N1..N5 (%, rounded to integers when printed): N1, N2, N3 the flux in the
  // cones of pi/2, pi, 3 pi/2 sr about gamma = 0 (half-angles 41.4, 60, 75.5 degrees) per the
  // flux in gamma < 90; N4 that hemisphere's share of the total; N5 the total per the lamps' flux,
  // 100 in absolute photometry (the luminaire is measured as a whole, no lamp flux).
  std::array<double, 5> cie_flux_code{};
  double input_watts = 0;  // from the distribution (0: unknown)
  double efficacy = 0;     // lm/W (photometric, input_watts > 0), else 0

  // cd per 1000 lm of the total (photometric): the "cd/klm" scale of relative photometry.
  double PerKlm(double intensity) const {
    return total_flux > 0 ? intensity * 1000 / total_flux : 0;
  }
};

// `seen`: empty (every direction seen) or one flag per value of `d` (FarField::seen, the same
// layout): an unseen direction is unknown, not dark. Peak and edges look at seen directions only;
// the fluxes sum what is stored (0 for an unseen direction: the caller states coverage).
PhotometricSummary SummarisePhotometry(const IntensityDistribution& d,
                                       const std::vector<uint8_t>& seen = {});

// The beam spread across the pair (C, C + 180), or false when either plane (under the
// distribution's symmetry) is not a stored plane.
bool BeamSpreadOfPair(const IntensityDistribution& d, const std::vector<uint8_t>& seen,
                      double c_deg, BeamSpread* out);

// NEMA FL 11 floodlight beam type from the field angle (10 % of peak; degrees): 1 for 10 to 18,
// 2 for 18 to 29, 3 for 29 to 46, 4 for 46 to 70, 5 for 70 to 100, 6 for 100 to 130, 7 above
// 130 (each class's upper edge included); 0 below 10 degrees or for NaN (no class).
int NemaBeamType(double field_angle_deg);

// The largest gamma (degrees) up to which every stored direction was seen: the measured cone.
// 180 (or the last stored gamma) when `seen` is empty; 0 when gamma = 0 itself was not seen.
double SeenConeDeg(const IntensityDistribution& d, const std::vector<uint8_t>& seen);

// "N1 N2 N3 N4 N5" as CIE 52 prints it: five integers separated by spaces.
std::string CieFluxCodeText(const std::array<double, 5>& code);

}  // namespace lumislab
