// What an IES, EULUMDAT or TM-25 file holds: `lumislab-export info` (docs/architecture.md §7.8) and
// the fuzz target fuzz_photometry_info share this, the format detection included.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace lumislab {

// True when the file starts with TM-25's file type "TM25" (4.7.1.1).
bool IsTm25File(const std::string& path);

// Reads the file (TM-25 by its first bytes, else ReadIntensityFile: IES by its first line or a
// TILT= line, anything else EULUMDAT) and describes it: format, photometric, flux_unit, flux
// (the rays' sum, or the distribution's total flux) and for a ray file rays and the header's
// totals and text, for a distribution the symmetry, the C and gamma grids, the peak, the
// opening, input_watts and efficacy (flux / input_watts, null without), the IES lamp line and
// file generation type (with its meaning), and the keywords; `coverage` when lumislab stated it
// (IES [_COVERAGE], EULUMDAT's report field after "partial: ", TM-25 additional_info after
// "coverage: "). Bad input: BadInput naming the file and the field.
nlohmann::json PhotometricFileInfo(const std::string& path);

// The description as `info` prints it: JSON (`json`; text from the file that is not UTF-8 is
// replaced, not refused) or lines of text ending with the flux.
std::string FormatPhotometricFileInfo(const nlohmann::json& info, bool json);

}  // namespace lumislab
