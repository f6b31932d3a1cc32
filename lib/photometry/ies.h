// IES LM-63 photometric files (docs/formats.md §17): the reader takes the 1986, 1991, 1995,
// 2002 and 2019 editions, type C photometry, every symmetry of the horizontal angles,
// TILT=NONE and TILT=INCLUDE (read, recorded as the keyword "TILT", not applied: it describes
// other mounting angles); TILT=<file>, type B and type A are refused by name. The writer writes
// LM-63-2019.
#pragma once

#include <string>
#include <utility>
#include <vector>

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
// BadInput naming `name` and the first required keyword without a value in `keywords`.
void CheckIesRequiredKeywords(const std::vector<std::pair<std::string, std::string>>& keywords,
                              const std::string& name);

// LM-63-2019's file generation type (line 11, second value; the standard's Table 2): "1." and
// five digits, each a yes/no, read left to right: tested at an accredited lab, interpolated
// angle set, lumen scaled, computer simulation, undefined. So 1.00000 is a test at an
// unaccredited lab, 1.01000 the same with an interpolated angle set, 1.10100 an accredited lab's
// lumen-scaled test, 1.00010 a computer simulation and 1.00001 undefined.
struct FileGenerationType {
  bool accredited = false;    // the photometry lab is accredited (for this test)
  bool interpolated = false;  // the angle set was interpolated from other measured angles
  bool lumen_scaled = false;  // the candela were scaled to another lumen rating
  bool simulation = false;    // computed, not measured (the other digits are then 0)

  std::string Code() const;  // "1.01000", ...
};
// What a line-11 value says in words ("test at an unaccredited lab, interpolated angle set");
// a value outside the table: "not in LM-63-2019's table".
std::string FileGenerationTypeName(const std::string& code);

struct IesWriteOptions {
  // Written on line 11 as given. The default, 1.00001, is "undefined": a writer that knows
  // passes FileGenerationType::Code() (lumislab-export ies does, docs/formats.md §17).
  std::string file_generation_type = "1.00001";
};

// LM-63-2019 text, lines ending in CR LF: the keywords of `d` (the required ones first), TILT=NONE,
// absolute photometry (lumens per lamp -1), metres, the luminous opening, the angles and values as
// stored. A radiometric distribution is written in W/sr with the keyword [_UNITS] saying so
// (LM-63 has no radiometric mode; ParseIes reads it back as radiometric).
std::string FormatIes(const IntensityDistribution& d, const IesWriteOptions& options,
                      const std::string& name);
void WriteIes(const IntensityDistribution& d, const std::string& path,
              const IesWriteOptions& options = {});

}  // namespace lumislab
