// dataset.json (core/dataset.h Dataset::Load): the bytes are <tmp>/in/dataset.json. What the
// stages do next with an accepted dataset is run too (photo specs, slab layout), and it must
// survive Save + Load: a dataset the project writes is one it reads back.
#include "core/dataset.h"
#include "core/slab.h"
#include "fuzz/fuzz_util.h"
#include "lib/photo/photo_io.h"

using namespace lumislab;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string in = fuzz::SubDir("in"), out = fuzz::SubDir("out");
  fuzz::WriteFile(in + "/dataset.json", data, size);
  FUZZ_BEGIN
  const Dataset ds = Dataset::Load(in);
  const SlabInfo info = SlabInfo::FromDataset(ds, 300);
  (void)info;
  CalibrationPhotoSpec(ds).Check("calibration photo");
  for (const PhotoEntry& e : ds.photos) {
    (void)ds.Path(e.file);
    PhotoSpecOf(ds, e).Check(e.file);
  }
  ds.Save(out);
  try {
    const Dataset back = Dataset::Load(out);
    if (back.photos.size() != ds.photos.size() || back.grid.count() != ds.grid.count())
      fuzz::Finding("dataset.json: Save + Load changed the dataset");
  } catch (const Error& e) {
    fuzz::Finding(std::string("dataset.json: Load refuses what Save wrote: ") + e.what());
  }
  FUZZ_END
}
