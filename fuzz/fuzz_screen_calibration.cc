// calib/screen.json (core/screen_calibration.h ScreenCalibration::Load): the bytes are
// <tmp>/in/screen.json. An accepted calibration is used the way reconstruct uses it (pixel ->
// screen and back) and must survive Save + Load.
#include "core/screen_calibration.h"
#include "fuzz/fuzz_util.h"

using namespace lumislab;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string in = fuzz::SubDir("in"), out = fuzz::SubDir("out");
  fuzz::WriteFile(in + "/screen.json", data, size);
  FUZZ_BEGIN
  const ScreenCalibration c = ScreenCalibration::Load(in + "/screen.json");
  const double w = c.image_width - 1, h = c.image_height - 1;
  for (const Eigen::Vector2d& px :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0), Eigen::Vector2d(0, h), Eigen::Vector2d(w, h),
        Eigen::Vector2d(0.5 * w, 0.5 * h)}) {
    const Eigen::Vector2d mm = c.ScreenFromImage(px);
    (void)c.ImageFromScreen(mm);
    (void)c.Distort(c.Undistort(px));
  }
  c.Save(out + "/screen.json");
  try {
    const ScreenCalibration back = ScreenCalibration::Load(out + "/screen.json");
    if (back.image_width != c.image_width || back.image_height != c.image_height)
      fuzz::Finding("screen.json: Save + Load changed the calibration");
  } catch (const Error& e) {
    fuzz::Finding(std::string("screen.json: Load refuses what Save wrote: ") + e.what());
  }
  FUZZ_END
}
