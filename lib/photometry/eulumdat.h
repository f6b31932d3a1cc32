// EULUMDAT (.ldt) photometric files (docs/formats.md §17): the reader takes every symmetry
// indicator Isym 0-4 and converts the intensities from cd/klm to cd with the flux of the first
// lamp set; the writer writes the same layout from a distribution.
#pragma once

#include <string>

#include "lib/photometry/intensity_distribution.h"

namespace lumislab {

// Parses the text of an EULUMDAT file; `name` (the path) is what errors name. Text fields are
// kept as keywords under the IES names where one exists (company -> MANUFAC, measurement
// report -> TEST, luminaire name -> LUMINAIRE, luminaire number -> LUMCAT, lamp type -> LAMP),
// others as _LDT_<FIELD>. The conversion factor (line 24) and the light output ratio are
// recorded, not applied: the intensities are the luminaire's, per 1000 lm of its lamps.
IntensityDistribution ParseEulumdat(const std::string& text, const std::string& name);
IntensityDistribution ReadEulumdat(const std::string& path);

// EULUMDAT text: Isym from the distribution's symmetry, one lamp set whose flux is the total
// flux (so LORL = 100 %), intensities in cd/klm, DFF computed, the direct ratios (line 27) 0
// (not computed). Radiometric distributions are written per 1000 W with the lamp type saying so.
std::string FormatEulumdat(const IntensityDistribution& d, const std::string& name);
void WriteEulumdat(const IntensityDistribution& d, const std::string& path);

}  // namespace lumislab
