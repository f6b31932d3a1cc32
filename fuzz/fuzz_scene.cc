// Scene files of lumislab-acquire synth --scene (lib/synthetic/scene.h ParseScene), and what
// acquire does with an accepted scene before rendering: the dataset skeleton, the photo list and
// the camera effects on a tiny photo.
#include "fuzz/fuzz_util.h"
#include "lib/synthetic/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  FUZZ_BEGIN
  const lumislab::SynthScene scene = lumislab::ParseScene(text, "fuzz-scene.json");
  const lumislab::Dataset skeleton = lumislab::DatasetSkeleton(scene);
  // The photo list is 2 entries per position and bracket stop (up to 1.8e7 for a 1000 x 1000
  // grid and 9 stops, which the format allows): listed for grids that keep one run fast.
  if (scene.grid.count() <= 10000) {
    const auto photos = lumislab::PhotoList(scene);
    if (photos.size() != size_t(2 * scene.grid.count()) * scene.Stops().size())
      lumislab::fuzz::Finding("PhotoList: wrong number of photos");
  }
  lumislab::ImageF rgb(4, 3, 3, 0.5f);
  for (size_t k = 0; k < scene.effects.size(); ++k)
    scene.effects[k]->Apply(rgb, lumislab::PhotoContext{int(k)});
  (void)skeleton;
  FUZZ_END
}
