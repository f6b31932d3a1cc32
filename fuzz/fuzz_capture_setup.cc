// setup.json of `lumislab-acquire capture` (acquire/lab_setup.h): the bytes are
// <tmp>/in/setup.json, read as capture reads it: the dataset part (Dataset::Parse without photos)
// and the lab block, then the soft-limit check and every grid position's stage targets, which
// must be finite.
#include <cmath>

#include "acquire/lab_setup.h"
#include "core/dataset.h"
#include "core/json.h"
#include "fuzz/fuzz_util.h"

using namespace lumislab;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string in = fuzz::SubDir("in");
  const std::string path = in + "/setup.json";
  fuzz::WriteFile(path, data, size);
  FUZZ_BEGIN
  const Dataset setup = Dataset::Parse(JsonDocument::Load(path), in, false);
  const LabSetup lab = LoadLabSetup(path);
  lab.CheckTravel(setup.grid, path);
  for (int j = 0; j < setup.grid.nv; ++j)
    for (int i = 0; i < setup.grid.nu; ++i)
      for (const auto& [axis, mm] : lab.PositionTargets(setup.grid, i, j))
        if (!std::isfinite(mm)) fuzz::Finding("setup.json: a stage target that is not finite");
  FUZZ_END
}
