// What a camera records about a shot (EXIF), read from a photo: the exposure that makes photos of
// different exposures comparable (docs/formats.md §3, relative exposure t ISO / N^2) and who
// took it with what. JPEG through libexif, camera RAW and DNG through LibRaw, TIFF through
// libtiff; PNG and OpenEXR carry none here.
#pragma once

#include <optional>
#include <string>

namespace lumislab {

// A tag the file does not hold is std::nullopt. Also what the synthetic camera writes
// (lib/photo/camera_write.h): the fields present are written.
struct PhotoExif {
  std::optional<double> exposure_time;  // s
  std::optional<double> f_number;       // N
  std::optional<double> iso;            // ISO speed rating
  std::optional<std::string> make, model, lens_model;
  // The camera's geometry, which the screen calibration assumes the same in every photo:
  std::optional<double> focal_length;  // mm (FocalLength): a zoom lens touched changes it
  // Orientation 1 .. 8 (1 as stored, 3 turned 180 degrees, 6 and 8 turned 90 degrees): the JPEG
  // and TIFF decoders turn the pixels by it; LibRaw's flip for camera RAW.
  std::optional<int> orientation;
  // "YYYY:MM:DD HH:MM:SS" as EXIF stores it (DateTimeOriginal, else DateTime): the camera's
  // clock, no time zone.
  std::optional<std::string> date_time;

  // t ISO / N^2 (s), the relative exposure of dataset.json; nullopt unless all three are known.
  std::optional<double> RelativeExposure() const;
};

// Reads the EXIF of a photo of any format DecodePhoto reads (detected from its content). Missing
// tags are nullopt; a file that is not a photo, or EXIF that is present but corrupt, is BadInput
// naming the file.
PhotoExif ReadPhotoExif(const std::string& path);

}  // namespace lumislab
