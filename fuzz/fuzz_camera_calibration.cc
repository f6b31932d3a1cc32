// calib/camera.json (core/camera_calibration.h CameraCalibration::Load): the bytes are
// <tmp>/in/camera.json. An accepted calibration is used the way a reader of the camera would
// (projection and undistortion over the photo) and must survive Save + Load.
#include "core/camera_calibration.h"
#include "fuzz/fuzz_util.h"

using namespace lumislab;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string in = fuzz::SubDir("in"), out = fuzz::SubDir("out");
  fuzz::WriteFile(in + "/camera.json", data, size);
  FUZZ_BEGIN
  const CameraCalibration c = CameraCalibration::Load(in + "/camera.json");
  const double w = c.image_width - 1, h = c.image_height - 1;
  for (const Eigen::Vector2d& px :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0), Eigen::Vector2d(0, h), Eigen::Vector2d(w, h),
        Eigen::Vector2d(0.5 * w, 0.5 * h)}) {
    const Eigen::Vector2d n = c.UndistortToNormalised(px);
    (void)c.Project(Eigen::Vector3d(n.x(), n.y(), 1.0));
  }
  c.Save(out + "/camera.json");
  try {
    const CameraCalibration back = CameraCalibration::Load(out + "/camera.json");
    if (back.image_width != c.image_width || back.views.size() != c.views.size())
      fuzz::Finding("camera.json: Save + Load changed the calibration");
  } catch (const Error& e) {
    fuzz::Finding(std::string("camera.json: Load refuses what Save wrote: ") + e.what());
  }
  FUZZ_END
}
