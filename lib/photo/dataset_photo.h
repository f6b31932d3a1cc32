// A dataset's photos decoded with the dataset's radiometry (dataset.json) and each photo's
// exposure: what the reconstruct stage merges.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/dataset.h"
#include "lib/photo/photo_io.h"
#include "lib/photo/radiometric_calibration.h"

namespace lumislab {

struct DecodedPhoto {
  PhotoEntry entry;
  Photo photo;  // decoded with the dataset's radiometry and the entry's exposure
};

// Decodes one photo of the dataset, with the radiometric corrections of calib/ when given; a
// missing or undecodable file is bad input naming the photo.
DecodedPhoto DecodeDatasetPhoto(const Dataset& dataset, const PhotoEntry& entry,
                                std::shared_ptr<const PhotoCorrections> corrections = nullptr);

// Checks that every photo has the calibration's image size (bad input naming the photo).
void CheckPhotoSizes(const std::vector<DecodedPhoto>& photos, int width, int height,
                     const std::string& calibration_file);

}  // namespace lumislab
