// ANSI/IES TM-25 ray files (lib/photometry/tm25.h ReadTm25): the bytes are <tmp>/in/rays.ray.
// Every accepted ray has finite values, a unit direction and a flux >= 0; the ray set survives
// WriteTm25 + ReadTm25 (the rays, their flux and the header's flux kind).
#include <cmath>

#include "fuzz/fuzz_util.h"
#include "lib/photometry/tm25.h"

using namespace lumislab;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string in = fuzz::SubDir("in") + "/rays.ray",
                           out = fuzz::SubDir("out") + "/rays.ray";
  fuzz::WriteFile(in, data, size);
  FUZZ_BEGIN
  const Tm25RaySet set = ReadTm25(in);
  for (const Tm25Ray& r : set.rays) {
    const double norm = std::sqrt(double(r.kx) * r.kx + double(r.ky) * r.ky + double(r.kz) * r.kz);
    if (!std::isfinite(r.x) || !std::isfinite(r.y) || !std::isfinite(r.z) ||
        std::abs(norm - 1) > 1e-5 || !(r.flux >= 0) || !std::isfinite(r.flux))
      fuzz::Finding("TM-25: an accepted ray is not finite, unit and >= 0");
  }
  if (!std::isfinite(set.FluxSum())) fuzz::Finding("TM-25: the rays' flux sum is not finite");
  WriteTm25(set, out);
  Tm25RaySet back;
  try {
    back = ReadTm25(out);
  } catch (const Error& e) {
    fuzz::Finding(std::string("TM-25: ReadTm25 refuses what WriteTm25 wrote: ") + e.what());
  }
  if (back.rays.size() != set.rays.size() || back.photometric != set.photometric ||
      back.FluxSum() != set.FluxSum() || back.name != set.name)
    fuzz::Finding("TM-25: WriteTm25 + ReadTm25 changed the ray set");
  FUZZ_END
}
