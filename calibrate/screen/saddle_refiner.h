// Sub-pixel checkerboard corners as saddle points of the blurred photo. An X-junction of two
// straight edges is point-symmetric about the corner, so after any isotropic blur the corner is
// a saddle point; a quadratic fitted with weights centred at the current estimate moves it there.
// cv::cornerSubPix locks onto pixel centres on sharp edges (errors up to ~0.1 px here); this
// stays within ~0.01 px on rendered boards.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace lumislab {

// Refines `corners` (pixels, OpenCV centres) in place on `gray` (CV_8UC1 or CV_32FC1);
// `square_px`, the board square size in pixels, sets the blur and the window so that no
// neighbouring corner or the dot enters it. Corners whose fit fails keep their position;
// returns how many were refined.
int RefineSaddlePoints(const cv::Mat& gray, double square_px, std::vector<cv::Point2f>* corners);

}  // namespace lumislab
