#include "preview/image_files.h"

#include <filesystem>
#include <opencv2/core.hpp>

#include "core/error.h"
#include "core/exr_io.h"
#include "lib/lightfield/tone_map.h"
#include "lib/photo/photo_io.h"

namespace lumislab {

void WritePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
  if (rgb.size() != size_t(width) * height * 3) throw Failure(path + ": PNG buffer size mismatch");
  cv::Mat bgr(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const uint8_t* p = &rgb[(size_t(y) * width + x) * 3];
      bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(p[2], p[1], p[0]);
    }
  }
  WriteImageFile(path, bgr);
}

void WriteImage(const std::string& path, const ImageF& image, const ToneMapping& tone) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".exr") {
    WriteExr(path, image, {"R", "G", "B"});
  } else if (ext == ".png") {
    WritePng(path, image.width, image.height, ToneMapToSrgb8(image, tone));
  } else {
    throw BadInput(path + ": output must end in .exr or .png");
  }
}

}  // namespace lumislab
