#include "lib/photo/dataset_photo.h"

#include <utility>

#include "core/error.h"

namespace lumislab {

DecodedPhoto DecodeDatasetPhoto(const Dataset& dataset, const PhotoEntry& entry,
                                std::shared_ptr<const PhotoCorrections> corrections) {
  PhotoSpec spec = PhotoSpecOf(dataset, entry);
  spec.corrections = std::move(corrections);
  return {entry, DecodePhoto(dataset.PhotoPath(entry.file), spec)};
}

void CheckPhotoSizes(const std::vector<DecodedPhoto>& photos, int width, int height,
                     const std::string& calibration_file) {
  for (const auto& p : photos)
    if (p.photo.pixels.cols != width || p.photo.pixels.rows != height)
      throw InputError(
          p.photo.path, "image size (calib/screen.json image_size)",
          std::to_string(width) + "x" + std::to_string(height) + " as in " + calibration_file,
          std::to_string(p.photo.pixels.cols) + "x" + std::to_string(p.photo.pixels.rows));
}

}  // namespace lumislab
