// slab.json (core/slab.h SlabInfo::Load): the bytes are <tmp>/in/slab.json. An accepted slab.json
// must survive Save + Load.
#include "core/slab.h"
#include "fuzz/fuzz_util.h"

using namespace lumislab;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string in = fuzz::SubDir("in"), out = fuzz::SubDir("out");
  fuzz::WriteFile(in + "/slab.json", data, size);
  FUZZ_BEGIN
  const SlabInfo info = SlabInfo::Load(in);
  for (const auto& [i, j] : info.present)
    if (!info.IsPresent(i, j)) fuzz::Finding("slab.json: a listed position is not present");
  (void)info.Complete();
  (void)info.layout.TexelCentre(0, 0);
  (void)SlabPositionPath(in, info.grid.nu - 1, info.grid.nv - 1);
  info.Save(out);
  try {
    const SlabInfo back = SlabInfo::Load(out);
    if (back.present != info.present || back.layout.res_x != info.layout.res_x ||
        back.layout.res_y != info.layout.res_y)
      fuzz::Finding("slab.json: Save + Load changed the slab info");
  } catch (const Error& e) {
    fuzz::Finding(std::string("slab.json: Load refuses what Save wrote: ") + e.what());
  }
  FUZZ_END
}
