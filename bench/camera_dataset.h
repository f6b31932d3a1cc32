// A bracketed dataset of full-size camera photos for reconstruct_bench: one grid position,
// 3 exposures per slide, written as a camera writes them (lib/photo/camera_write.h): 8-bit
// sRGB JPEG, 16-bit linear TIFF or a 14-bit RGGB DNG, with EXIF.
#pragma once

#include <string>
#include <vector>

namespace lumislab::bench {

enum class CameraFormat { kJpeg, kTiff16, kDng };
const char* CameraFormatName(CameraFormat format);

// Writes dataset.json, calib/screen.json and the photos into `dir` (replaced). The photos hold
// the reconstruct tests' analytic light (two Gaussians per slide, the bright one clipped at the
// longest exposure) through a perspective view of the screen, plus deterministic noise of
// 0.3 % of full scale so that the encoders see a photo's entropy rather than a smooth field.
void MakeCameraDataset(const std::string& dir, CameraFormat format, int width, int height,
                       const std::vector<double>& exposures = {0.25, 1, 4});

}  // namespace lumislab::bench
