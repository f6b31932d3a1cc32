// EULUMDAT (.ldt) photometric files (docs/formats.md §17): the reader takes every symmetry
// indicator Isym 0-4 and converts the intensities from cd/klm to cd with the flux of the first
// lamp set; the writer writes the same layout from a distribution.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "lib/photometry/intensity_distribution.h"

namespace lumislab {

// Parses the text of an EULUMDAT file; `name` (the path) is what errors name. Text fields are
// kept as keywords under the IES names where one exists (company -> MANUFAC, measurement
// report -> TEST, luminaire name -> LUMINAIRE, luminaire number -> LUMCAT, lamp type -> LAMP),
// others as _LDT_<FIELD>; lamp set 1's colour temperature and rendering as COLORTEMP and CRI
// unless empty or "-". Ityp 0-3 is read (old files write 0). The conversion factor (line 24) and
// the light output ratio are recorded, not applied: the intensities are the luminaire's, per 1000
// lm of its lamps.
IntensityDistribution ParseEulumdat(const std::string& text, const std::string& name);
IntensityDistribution ReadEulumdat(const std::string& path);

// One standard set of lamps, EULUMDAT lines 26a-26f.
struct LdtLampSet {
  int count = -1;                  // 26a number of lamps; negative: absolute photometry
  std::string type;                // 26b type of lamps
  double flux_lm = 0;              // 26c total flux of the set's lamps, lm (W when radiometric)
  std::string colour_temperature;  // 26d colour temperature / appearance, e.g. "3000 K"
  std::string colour_rendering;    // 26e colour rendering index or group, e.g. "Ra 90", "1B"
  double watts = 0;                // 26f wattage including ballast, W
};

struct EulumdatWriteOptions {
  // The standard sets of lamps (at most 100). Empty: one set for absolute photometry (the
  // luminaire measured as a whole, as lumislab measures it): number of lamps -1, type the
  // LAMP keyword (else "luminaire (absolute photometry)"), flux the distribution's total flux (so
  // LORL = 100 %), colour temperature and rendering the COLORTEMP and CRI keywords (else "-"),
  // wattage the input watts (0: unknown). Given: the intensities are written per 1000 lm of the
  // first set's flux (relative photometry) and LORL = the distribution's flux / that flux.
  std::vector<LdtLampSet> lamp_sets;
};

// The room indices k = a b / (h (a + b)) of EULUMDAT line 27's direct ratios.
inline constexpr std::array<double, 10> kLdtRoomIndices = {0.6, 0.8, 1.0, 1.25, 1.5,
                                                           2.0, 2.5, 3.0, 4.0,  5.0};

// EULUMDAT line 27: for each room index, the fraction of the luminaires' downward flux that falls
// directly on the work plane of a square room whose ceiling they cover evenly (0 without
// downward flux). docs/formats.md §17 gives the method and its check against published files.
std::array<double, 10> LdtDirectRatios(const IntensityDistribution& d);

// EULUMDAT text, lines ending in CR LF: Ityp 1 (axially symmetric) or 3 (any other point
// source), Isym from the distribution's symmetry, the lamp sets of `options`, intensities in
// cd/klm, DFF and the direct ratios computed. Radiometric distributions are written per 1000 W
// with the lamp type saying so. BadInput naming `name` and the field for a bad lamp set.
std::string FormatEulumdat(const IntensityDistribution& d, const std::string& name,
                           const EulumdatWriteOptions& options = {});
void WriteEulumdat(const IntensityDistribution& d, const std::string& path,
                   const EulumdatWriteOptions& options = {});

}  // namespace lumislab
