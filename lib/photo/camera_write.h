// Files as a real camera writes them, for the synthetic capture: a DNG of the raw Bayer mosaic,
// a JPEG or TIFF with EXIF, so that every correction (black level, white level, white balance,
// demosaic, exposure from EXIF) is tested against known truth. Each is written under a
// temporary name and renamed into place (core/atomic_file.h); a failure is IoError.
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <string>

#include "lib/photo/exif.h"

namespace lumislab {

struct DngInfo {
  int black_level = 0;      // code of no light, every pixel (BlackLevel)
  int white_level = 65535;  // code of a clipped pixel (WhiteLevel)
  // The camera neutral in raw RGB (AsShotNeutral): the as-shot white balance multipliers are
  // 1 / neutral (green = 1 gives multipliers normalised to green).
  std::array<double, 3> as_shot_neutral = {1, 1, 1};
  PhotoExif exif;  // fields present are written (make and model in IFD0, the rest in EXIF)
};

// Writes `mosaic` (CV_16UC1 codes, RGGB: row 0 = R G R G ..., row 1 = G B G B ...; even width
// and height) as an uncompressed DNG 1.4 with CFA tags, BlackLevel, WhiteLevel, an identity
// ColorMatrix1 (raw RGB taken as XYZ: no colour science, only so readers accept the file),
// AsShotNeutral and the EXIF.
void WriteDng(const std::string& path, const cv::Mat& mosaic, const DngInfo& info);

// Writes an 8-bit or 16-bit image (1, 3 or 4 channels, OpenCV's B, G, R (A) order; the fourth as
// unassociated alpha) as an uncompressed TIFF with make, model and date-time in IFD0 and the rest
// of `exif` in an EXIF directory, as a camera's TIFF output.
void WriteTiff(const std::string& path, const cv::Mat& image, const PhotoExif& exif);

// Writes an 8-bit BGR image (CV_8UC3) as a JPEG at `quality` (1 .. 100) through libjpeg, with an
// EXIF APP1 segment (exposure time, f-number, ISO, make, model, lens, focal length, orientation,
// date-time; the fields present) built with libexif and placed right after SOI, where cameras put
// it; no EXIF block when no field is present.
void WriteJpeg(const std::string& path, const cv::Mat& bgr8, int quality, const PhotoExif& exif);

}  // namespace lumislab
