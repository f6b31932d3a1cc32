// The calibration photo (linear luminance from lib/photo's decoder) stretched to 8 bits for
// corner detection.
#pragma once

#include <opencv2/core.hpp>

namespace lumislab {

// Stretches `gray` (CV_32FC1) to CV_8UC1 between its 0.5 % and 99.5 % quantiles. `contrast`
// (optional) receives that quantile span; 0 for a blank image.
cv::Mat StretchToGray8(const cv::Mat& gray, double* contrast = nullptr);

}  // namespace lumislab
