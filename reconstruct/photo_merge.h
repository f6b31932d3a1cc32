// Photos of one grid position -> one image of E = peak * scale * (E+ - E-) in photo pixel space.
// Decoding and linearisation are lib/photo's (one decoder for every stage). Brackets: per slide
// and channel, sum of values / sum of exposures over the exposures that are not saturated (an
// exposure-weighted average of value / exposure).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/dataset.h"
#include "lib/photo/photo_io.h"

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

struct MergedPosition {
  // R, G, B = gain * (E+ - E-) at the photo pixels box-averaged `downsample` x `downsample`
  // (exact INTER_AREA on the top-left multiple of the factor). CV_32FC3 when no pixel is
  // saturated; otherwise CV_32FC4 with A > 0 wherever a saturated pixel contributed.
  cv::Mat signal;
  int saturated_pixels = 0;  // pixels with a channel saturated in every exposure of a slide
  bool fast_path = false;    // one exposure per slide, nothing saturated: merged after averaging
};

// gain = filter peak * radiometric scale. Needs at least one photo of each slide.
MergedPosition MergePosition(const std::vector<DecodedPhoto>& photos, double gain,
                             int downsample = 1);
// The general path (brackets, saturation, 8-bit sRGB, black level), per pixel at full
// resolution; the signal is CV_32FC4 with A = 1 where saturated.
MergedPosition MergeFullResolution(const std::vector<DecodedPhoto>& photos, double gain);

}  // namespace lumislab
