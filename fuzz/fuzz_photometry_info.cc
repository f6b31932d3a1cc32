// lumislab-export info (lib/photometry/file_info.h): the format detection (TM-25 by its first
// bytes, IES by its first line or a TILT= line, anything else EULUMDAT) and the description in
// both forms; the bytes are <tmp>/in/file. The JSON form must parse back with a finite flux.
#include <cmath>

#include "fuzz/fuzz_util.h"
#include "lib/photometry/file_info.h"

using namespace lumislab;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string in = fuzz::SubDir("in") + "/file";
  fuzz::WriteFile(in, data, size);
  FUZZ_BEGIN
  const nlohmann::json info = PhotometricFileInfo(in);
  (void)FormatPhotometricFileInfo(info, false);
  const nlohmann::json back = nlohmann::json::parse(FormatPhotometricFileInfo(info, true));
  if (!back["flux"].is_number() || !std::isfinite(back["flux"].get<double>()))
    fuzz::Finding("info: the flux is not a finite number");
  FUZZ_END
}
