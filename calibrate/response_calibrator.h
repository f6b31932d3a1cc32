// lumislab-calibrate response: a bracketed series of one still scene -> the camera's response
// curve (8-bit frames, calib/response.json) or a linearity report (16-bit, float, RAW frames,
// calib/linearity.json); docs/design.md §5.14.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "calibrate/calibration_frames.h"
#include "lib/photo/radiometric_calibration.h"

namespace lumislab {

struct ResponseOptions {
  int samples = 200;   // sample pixels per channel handed to the solver (dense SVD: ~n^3)
  double lambda = 50;  // smoothness of the curve (CalibrateDebevec's lambda; JPEG data is noisy)
  void Check() const;  // BadInput naming the option
};

// Debevec and Malik's least squares (OpenCV's CalibrateDebevec) on sample pixels chosen here:
// pixels spread over the code range whose codes stay unclipped (1 .. 254) in every frame.
// Frames must be 8-bit with known exposures, at least two of them different (BadInput naming
// the frame and field). The curve is normalised to 1 at code 255 and made strictly increasing;
// `report` gets how consistent the frames become after linearisation (and with the sRGB curve,
// for comparison).
ResponseCurve CalibrateResponse(const std::vector<CalibrationFrame>& frames,
                                const ResponseOptions& options, nlohmann::json* report);

// Linear frames (16-bit, float, RAW): value / exposure of each frame against the frame of the
// middle exposure over pixels unclipped and above 2 % of full scale in both; the report lists
// each frame's mean ratio and its deviation from 1.
nlohmann::json CheckLinearity(const std::vector<CalibrationFrame>& frames);

}  // namespace lumislab
