// Slab positions (core/slab.h ReadSlabPosition, through core/exr_io.h ReadExr): the bytes are
// <tmp>/in/pos_0_0.exr of a 1 x 1 slab of 8 x 6 texels (the corpus's size; other sizes are bad
// input), also checked the way watchers and resumed runs do (ExrComplete) and listed
// (ExrChannelNames).
#include "core/exr_io.h"
#include "core/slab.h"
#include "fuzz/fuzz_util.h"

using namespace lumislab;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string dir = fuzz::SubDir("in");
  static const SlabInfo info = [] {
    SlabInfo s;
    s.distance_mm = 500;
    s.grid = {1, 1, 5.0};
    s.layout = {100.0, 75.0, 8, 6};
    return s;
  }();
  const std::string path = SlabPositionPath(dir, 0, 0);
  fuzz::WriteFile(path, data, size);
  (void)ExrComplete(path, info.layout.res_x, info.layout.res_y);  // never throws
  FUZZ_BEGIN(void) ExrChannelNames(path);
  const SlabPosition p = ReadSlabPosition(dir, info, 0, 0);
  if (p.irradiance.width != 8 || p.irradiance.height != 6 || p.mask.channels != 1)
    fuzz::Finding("ReadSlabPosition: accepted a position of another size");
  FUZZ_END
}
