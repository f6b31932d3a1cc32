// Photos of one grid position -> one image of E = peak * scale * (E+ - E-) in photo pixel space.
// Decoding and linearisation are lib/photo's (one decoder for every stage). Brackets (several
// exposures of a slide) are merged per slide, pixel and channel into one linear radiance value
// (docs/method.md §3.5 step 2): clipped values are left out, near-black values are left out when
// a longer exposure measured the pixel, and the rest are averaged with the inverse-variance
// weights of a sensor noise model (NoiseModel). The exposure ratios between brackets are
// estimated from the pixels and reported against the recorded ones; optionally used.
// The parts: merge_exposure.h (one photo's noise terms and readers), bracket_ratios.h (the ratio
// estimate), merge_kernels.h (the row kernels, one copy per instruction set); the photos are
// decoded by lib/photo/dataset_photo.h.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "lib/photo/dataset_photo.h"

namespace lumislab {

// Noise of a recorded value u (linear, above black, in units of the white level: u = 1 at the
// white level), the same for every photo of a slide:
//   var(u) = u / full_well_e  +  (read_noise_e / full_well_e)^2  +  q(u)^2 / 12
// shot noise (Poisson: the electron count's variance is the count), read noise (constant) and
// the quantisation of the stored codes (q: the step between neighbouring codes at u, in u units;
// 1/255 or 1/65535 of the range for linear photos, the sRGB curve's slope for sRGB-encoded 8-bit
// photos, 0 for float photos). Only the ratio of the terms matters for the weights.
struct NoiseModel {
  double full_well_e = 20000;  // electrons at u = 1
  double read_noise_e = 3;     // rms electrons
};

// How the exposures of a bracket are known: as recorded (dataset.json, from EXIF or the
// manifest), or from the pixels: the ratio between consecutive exposures of a slide estimated
// from the pixels well exposed in both, chained from the middle exposure, which keeps its
// recorded value.
enum class BracketRatios { kRecorded, kEstimated };

struct MergeOptions {
  NoiseModel noise;
  // A value is near-black when it lies less than this many code steps above the black level
  // (at the photo's bit depth, through its transfer curve), or less than 3 read-noise sigmas
  // above it, whichever is larger. Near-black values are not used where a longer exposure of
  // the slide measured the pixel; where every exposure is near-black the longest is used.
  double near_black_codes = 4;
  BracketRatios bracket_ratios = BracketRatios::kRecorded;
  void Check() const;  // BadInput naming the field
};

// Consecutive exposures (shorter, longer) of one slide and their ratio.
struct BracketRatio {
  bool positive = true;                          // slide
  double recorded_short = 1, recorded_long = 1;  // recorded exposures
  double estimated = 1;   // longer / shorter from the pixels (the recorded ratio when samples = 0)
  long long samples = 0;  // pixel channels well exposed in both that the estimate used
  // The same estimate over the dimmer and the brighter half of those samples (by the shorter
  // exposure's value). An exposure that is off changes the ratio at every brightness alike;
  // noise above the noise model's floor, a dark offset or a response curve that does not fit
  // change it more in the dimmer half.
  double estimated_dim = 1, estimated_bright = 1;
  double Recorded() const { return recorded_long / recorded_short; }
  double Deviation() const { return estimated / Recorded() - 1; }  // relative
  // The deviation is the exposures' own: the two halves agree to within a third of it (or 1 %),
  // so that following it (--bracket-ratios estimated) corrects the exposure, not the noise.
  bool DeviationIsTheExposures() const;
};
// A bracket step whose estimate deviates more than this from the recorded ratio, alike at every
// brightness, is warned with the advice to use the estimate: EXIF shutter times are nominal,
// 1/30 s may be 1/32 s (6.7 %).
constexpr double kRatioAdviceAbove = 0.05;
// Too few pixels well exposed in both: the ratio is not estimated (the recorded one is used).
constexpr long long kMinRatioSamples = 200;
// The least value (above black, in units of the white level) a pixel needs in both photos to
// count in a bracket ratio's estimate: 1 % of full scale: 2.6 8-bit codes in linear units, code 25
// through the sRGB curve.
constexpr float kMinRatioValue = 0.01f;

struct MergedPosition {
  // R, G, B = gain * (E+ - E-) at the photo pixels box-averaged `downsample` x `downsample`
  // (exact INTER_AREA on the top-left multiple of the factor). CV_32FC3 when no pixel is
  // saturated; otherwise CV_32FC4 with A > 0 wherever a saturated pixel contributed.
  cv::Mat signal;
  // Of the pixels merged (all, or the region's; the fast path counts none):
  int saturated_pixels = 0;   // pixels with a channel clipped in every exposure of a slide
  int near_black_pixels = 0;  // pixels with a channel near-black in every exposure of a slide
  int exposures = 1;          // most photos of one slide
  // Merged exposure-normalised slide values (both slides, all channels) that a well-exposed
  // value measured: the brightest, the faintest > 0, and log2(brightest / faintest). 0 when
  // not computed (fast path) or nothing was well exposed.
  double brightest = 0, faintest = 0, dynamic_range_stops = 0;
  std::vector<BracketRatio> ratios;  // consecutive exposures of each slide, shortest first
  bool fast_path = false;  // one exposure per slide, nothing saturated: merged after averaging
};

// gain = filter peak * radiometric scale. Needs at least one photo of each slide.
// region: the output (box-averaged) pixels that are needed (RectifyMap::read_region), inside
// the averaged image; empty: all. The general path merges only the photo pixels of the
// region's blocks (the rest of the signal is 0), and its counts and dynamic range are over
// those pixels; the fast path computes the whole image (as cheap) and counts nothing.
MergedPosition MergePosition(const std::vector<DecodedPhoto>& photos, double gain,
                             int downsample = 1, const MergeOptions& options = {},
                             const cv::Rect& region = {});
// The general path (brackets, saturation, 8-bit sRGB, black level), per pixel at full
// resolution, box-averaged `downsample` x `downsample` in the same pass; the signal is
// CV_32FC4 with A = the fraction of saturated pixels.
MergedPosition MergeFullResolution(const std::vector<DecodedPhoto>& photos, double gain,
                                   int downsample = 1, const MergeOptions& options = {},
                                   const cv::Rect& region = {});

// The exposure ratios of each slide's consecutive exposures, estimated from the pixels
// (median of the ratio of values well exposed in both, on a grid of at most ~2^18 pixels).
std::vector<BracketRatio> EstimateBracketRatios(const std::vector<DecodedPhoto>& photos,
                                                const MergeOptions& options = {});

}  // namespace lumislab
