// IES LM-63 photometric files (docs/formats.md §17): the reader takes the 1986, 1991, 1995,
// 2002 and 2019 editions, type C photometry, every symmetry of the horizontal angles,
// TILT=NONE and TILT=INCLUDE (read, recorded as the keyword "TILT", not applied: it describes
// other mounting angles); TILT=<file>, type B and type A are refused by name. The writer writes
// LM-63-2019.
#pragma once

#include <string>

#include "lib/photometry/intensity_distribution.h"

namespace lumislab {

// Parses the text of an IES file; `name` (the path) is what errors name. The candela values
// are multiplied by the candela multiplier and the ballast factor (and, in 1995 and older
// files, the ballast-lamp photometric factor), so the distribution holds the luminaire's
// intensity. Bad or truncated input: BadInput naming the file, the line and the field.
IntensityDistribution ParseIes(const std::string& text, const std::string& name);
IntensityDistribution ReadIes(const std::string& path);

// The keywords LM-63-2019 requires (§5.2 of the standard); WriteIes refuses a distribution
// without them.
extern const char* const kIesRequiredKeywords[4];  // TEST, TESTLAB, ISSUEDATE, MANUFAC

struct IesWriteOptions {
  // LM-63-2019's file generation type (line 11, second value), written as given. The default
  // 1.00010 is "computer simulation" in the standard's table (Table 1), not "test at an
  // unaccredited lab, interpolated angle set" (that is 1.01000); which one a distribution
  // computed from a slab should carry is issue 29's to settle.
  std::string file_generation_type = "1.00010";
};

// LM-63-2019 text: the keywords of `d` (the required ones first), TILT=NONE, absolute
// photometry (lumens per lamp -1), metres, the luminous opening, the angles and values as
// stored. A radiometric distribution is written in W/sr with the keyword [_UNITS] saying so
// (LM-63 has no radiometric mode; ParseIes reads it back as radiometric).
std::string FormatIes(const IntensityDistribution& d, const IesWriteOptions& options,
                      const std::string& name);
void WriteIes(const IntensityDistribution& d, const std::string& path,
              const IesWriteOptions& options = {});

}  // namespace lumislab
