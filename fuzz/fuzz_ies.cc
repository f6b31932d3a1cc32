// IES LM-63 files (lib/photometry/ies.h ParseIes): every edition, TILT=INCLUDE, the keywords.
// An accepted distribution must have a finite total flux and finite intensities >= 0 in any
// direction, and survive FormatIes + ParseIes (with the keywords LM-63-2019 requires) with its
// grid and its flux.
#include <algorithm>

#include "fuzz/fuzz_photometry.h"
#include "lib/photometry/ies.h"

using namespace lumislab;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  FUZZ_BEGIN
  IntensityDistribution d = ParseIes(text, "fuzz.ies");
  fuzz::CheckDistribution(d, "IES");
  // The keywords LM-63-2019 requires, whatever the file had (FormatIes refuses empty ones).
  for (const char* key : kIesRequiredKeywords) {
    d.keywords.erase(std::remove_if(d.keywords.begin(), d.keywords.end(),
                                    [&](const auto& k) { return k.first == key; }),
                     d.keywords.end());
    d.keywords.push_back({key, "fuzz"});
  }
  std::string written;
  try {
    written = FormatIes(d, {}, "fuzz-out.ies");
  } catch (const Error& e) {
    fuzz::Finding(std::string("IES: FormatIes refuses what ParseIes accepted: ") + e.what());
  }
  IntensityDistribution back;
  try {
    back = ParseIes(written, "fuzz-out.ies");
  } catch (const Error& e) {
    fuzz::Finding(std::string("IES: ParseIes refuses what FormatIes wrote: ") + e.what());
  }
  fuzz::CheckSameDistribution(d, back, "IES");
  FUZZ_END
}
