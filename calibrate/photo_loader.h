// The calibration photo as one gray channel: 8/16-bit PNG (and anything else cv::imread reads)
// or float EXR (core/exr_io.h, channels R, G, B), then stretched to 8 bits for detection.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace lumislab {

// CV_32FC1 with the stored values (8-bit: 0..255, 16-bit: 0..65535, EXR: linear floats).
// Missing, unreadable or corrupt files are BadInput (exit 2) naming the file.
cv::Mat LoadGrayPhoto(const std::string& path);

// Stretches `gray` (CV_32FC1) to CV_8UC1 between its 0.5 % and 99.5 % quantiles. `contrast`
// (optional) receives that quantile span; 0 for a blank image.
cv::Mat StretchToGray8(const cv::Mat& gray, double* contrast = nullptr);

}  // namespace lumislab
