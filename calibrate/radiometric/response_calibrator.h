// lumislab-calibrate response: a bracketed series of one still scene -> the camera's response
// curve (8-bit frames, calib/response.json) or a linearity report (16-bit, float, RAW frames,
// calib/linearity.json); docs/formats.md §14.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "calibrate/radiometric/calibration_frames.h"
#include "core/checks.h"
#include "lib/photo/radiometric_calibration.h"

namespace lumislab {

struct ResponseOptions {
  int samples = 30000;       // sample pixels per channel (the solve is 256 x 256 whatever their
                             // number; the time goes into choosing them)
  double lambda = 30;        // smoothness of the curve (response_fit.h `smoothness`)
  bool per_channel = false;  // a curve per channel instead of one for R, G, B
  void Check() const;        // BadInput naming the option
};

// The code from which a pair of the report's "pairs" also gives its "bright_mean_log_ratio":
// values whose code in the darker frame is this or more, far above any dark offset (cameras
// whose black sits at code 33 or 66 were measured), where only the exposures and the curve's
// shape decide the ratio.
constexpr int kResponseBrightCode = 128;

// Debevec and Malik's least squares on continuous codes (response_fit.h) over sample
// pixels chosen here: 3 x 3 means in smooth regions, in the frames where their neighbourhood is
// neither clipped nor black; one curve for R, G, B unless `per_channel`. Frames must be 8-bit with
// known exposures, at least two of them different (BadInput naming the frame and field). The curve
// is normalised to 1 at code 255 and made strictly increasing; `report` gets how consistent the
// frames become after linearisation (and with the sRGB curve, for comparison), overall and per
// consecutive pair ("pairs": the exposure ratio the linearised frames imply against the stated).
// Too few sample pixels to fit is recorded in `checks` (response.samples) when given.
ResponseCurve CalibrateResponse(const std::vector<CalibrationFrame>& frames,
                                const ResponseOptions& options, nlohmann::json* report,
                                CheckLog* checks = nullptr);

// Linear frames (16-bit, float, RAW): value / exposure of each frame against the frame of the
// middle exposure over pixels unclipped and above 2 % of full scale in both; the report lists
// each frame's mean ratio and its deviation from 1.
nlohmann::json CheckLinearity(const std::vector<CalibrationFrame>& frames);

}  // namespace lumislab
