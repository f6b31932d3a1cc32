#include "preview/image_files.h"

#include <filesystem>

#include "core/error.h"
#include "core/exr_io.h"
#include "lib/lightfield/tone_map.h"
#include "lib/photo/photo_write.h"

namespace lumislab {

void WritePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
  WriteRgb8File(path, width, height, rgb);
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

void WriteImageOrPicture(const std::string& path, const ImageF& image, const Rgb8Image& picture) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".exr") {
    WriteExr(path, image, {"R", "G", "B"});
  } else if (ext == ".png") {
    WriteRgb8File(path, picture.width, picture.height, picture.rgb);
  } else {
    throw BadInput(path + ": output must end in .exr or .png");
  }
}

}  // namespace lumislab
