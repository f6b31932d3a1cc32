// EULUMDAT files (lib/photometry/eulumdat.h ParseEulumdat): every symmetry indicator, decimal
// commas, several lamp sets. An accepted distribution must have a finite total flux and finite
// intensities >= 0 in any direction, and one with light must survive FormatEulumdat +
// ParseEulumdat with its grid and its flux.
#include "fuzz/fuzz_photometry.h"
#include "lib/photometry/eulumdat.h"

using namespace lumislab;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  FUZZ_BEGIN
  const IntensityDistribution d = ParseEulumdat(text, "fuzz.ldt");
  fuzz::CheckDistribution(d, "EULUMDAT");
  // EULUMDAT stores intensities per 1000 lm of the flux: a distribution without light has no
  // EULUMDAT form (FormatEulumdat refuses it by name).
  if (!(d.TotalFlux() > 0)) return 0;
  std::string written;
  try {
    written = FormatEulumdat(d, "fuzz-out.ldt");
  } catch (const Error& e) {
    fuzz::Finding(std::string("EULUMDAT: FormatEulumdat refuses what ParseEulumdat accepted: ") +
                  e.what());
  }
  IntensityDistribution back;
  try {
    back = ParseEulumdat(written, "fuzz-out.ldt");
  } catch (const Error& e) {
    fuzz::Finding(std::string("EULUMDAT: ParseEulumdat refuses what FormatEulumdat wrote: ") +
                  e.what());
  }
  fuzz::CheckSameDistribution(d, back, "EULUMDAT");
  FUZZ_END
}
