// The consistency checks of the radiometric calibration products (issue 28; the list a lab
// reads is docs/verifies.md, "Calibration"): each product against its own frames and against
// physics, recorded in the dataset's checks.json (core/checks.h). A check that finds what no
// capture can mean fails (exit 2, naming the file and the measured number); one that finds what
// a lab could mean warns.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calibrate/radiometric/calibration_frames.h"
#include "core/checks.h"

namespace lumislab {

// response.exposure_order: for the frames in the order of their stated exposures, each
// consecutive pair's pixels must say the same: at the unclipped pixels whose value changes
// between the two frames, the frame of the larger exposure is the brighter one (a response is
// monotonic). Fails naming both files, their stated exposures and the order the pixels imply.
void CheckExposureOrder(const std::vector<CalibrationFrame>& frames, CheckLog* checks);

// response.fit_explains_frames: the fitted curve against its own frames, per consecutive pair
// (report["pairs"] of CalibrateResponse): the exposure ratio the linearised frames imply against
// the stated one.
void CheckResponseFit(const nlohmann::json& report, CheckLog* checks);

// dark.is_dark: each dark frame's level (median over the frame, fraction of full scale) and its
// structure of light (how far the brightest regions stand above the median, after a median
// filter that removes hot pixels): a capped lens gives a low, even level.
void CheckDarkFrames(const std::vector<CalibrationFrame>& frames, CheckLog* checks);

// flat.has_signal: the flat frames' mean level on the screen (fraction of full scale at their
// exposures); `file` is the first frame's. Called by CalibrateFlat before it divides by it.
void CheckFlatSignal(const std::string& file, double mean_level, CheckLog* checks);
// flat.is_flat: CalibrateFlat's structured fraction (report of flat_calibrator.h).
void CheckFlat(const nlohmann::json& report, CheckLog* checks);

// scale.point_lit, scale.brackets_agree and scale.matches_dataset: the reference point's signal
// against the position's peak, the agreement of the slide's brackets at the point, and the scale
// against dataset.json's radiometry.scale_w_m2 when it has one (report of scale_calibrator.h).
void CheckScale(const nlohmann::json& report, double scale, CheckLog* checks);

// The value below which a share q of `v` lies (nth_element's, at index q * size): 0 when empty.
double Percentile(std::vector<float> v, double q);

}  // namespace lumislab
