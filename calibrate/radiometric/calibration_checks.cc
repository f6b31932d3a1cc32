#include "calibrate/radiometric/calibration_checks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "calibrate/radiometric/response_calibrator.h"
#include "core/log.h"
#include "lib/photo/photo_io.h"

namespace lumislab {

namespace {

using nlohmann::json;

// ---- response.exposure_order --------------------------------------------------------------

// Every kOrderStep-th pixel in x and y: a frame's pixels say the same about its exposure
// everywhere, and the pairs are read once per frame, not once per pair.
constexpr int kOrderStep = 2;
// A pixel-channel counts when it is unclipped in both frames, above the dark level
// (kOrderMinLevel of full scale in the brighter one) and changes between them by more than
// kOrderMinChange of its larger value (a third of a stop's 26 %: sensor noise and JPEG's error
// stay below it, any bracket step above).
constexpr double kOrderMinLevel = 0.02, kOrderMinChange = 0.1;
constexpr long long kOrderMinPixels = 100;
// The fraction of those pixels at which the frame of the larger stated exposure is the brighter.
// Measured: 1.000 on every pair of the legitimate series (the JPEG and RAW cameras of
// tests/e2e/real_camera_test.cc, half and whole stops; the synthetic response series with
// noise); 0.000 on the pairs a shell glob swaps (ev+2 before ev-1). A monotonic response
// allows no pixel to go the other way; below 0.5 the pixels say the opposite of the stated
// order, which no capture means.
constexpr double kOrderFail = 0.5, kOrderWarn = 0.95;

// A frame's linear values (decoder units, before the exposure division) on the sampled grid,
// NaN where clipped.
cv::Mat SampledValues(const Photo& photo) {
  const LinearReader reader(photo);
  const int w = (photo.pixels.cols + kOrderStep - 1) / kOrderStep;
  const int h = (photo.pixels.rows + kOrderStep - 1) / kOrderStep;
  cv::Mat out(h, w, CV_32FC3);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float v[3];
      bool clipped[3];
      reader.Read(y * kOrderStep, x * kOrderStep, v, clipped);
      cv::Vec3f& o = out.at<cv::Vec3f>(y, x);
      for (int c = 0; c < 3; ++c) o[c] = clipped[c] || !std::isfinite(v[c]) ? nan : v[c];
    }
  return out;
}

// At the changing pixel-channels of frames a and b: how many are brighter in b, and in a.
struct PairOrder {
  long long brighter_b = 0, brighter_a = 0;
  long long changing() const { return brighter_a + brighter_b; }
  double b_brighter() const { return changing() ? double(brighter_b) / double(changing()) : 1.0; }
};

PairOrder ComparePair(const cv::Mat& a, const cv::Mat& b) {
  PairOrder out;
  const float* pa = a.ptr<float>();
  const float* pb = b.ptr<float>();
  for (size_t k = 0; k < a.total() * 3; ++k) {
    const float va = pa[k], vb = pb[k];
    if (std::isnan(va) || std::isnan(vb)) continue;
    const float hi = std::max(va, vb);
    if (hi < kOrderMinLevel || std::abs(vb - va) <= kOrderMinChange * hi) continue;
    ++(vb > va ? out.brighter_b : out.brighter_a);
  }
  return out;
}

// ---- response.fit_explains_frames ---------------------------------------------------------

// |mean log ratio| of a consecutive pair: the curve-linearised frames against the stated
// exposure ratio. Measured on legitimate series: 0.0015 on the real-camera JPEG series (11 frames
// in half stops), 0.0008 - 0.0061 on the synthetic series of whole, half and third stops with and
// without sensor noise (960 x 720). The last exposure of a five-frame whole-stop series stated a
// stop too long (the order kept): 0.49 at its pair, 0.09 - 0.16 at the others (the fit spreads
// the error). A camera's shutter and aperture may be off by a few percent, so from 3 % the fit
// is reported as doubtful, not refused; beyond 0.35 (half of a stop's 0.69) no curve explains
// the frames with their exposures.
constexpr double kFitWarn = 0.03, kFitFail = 0.35;
// A pair is refused on its bright values only (kResponseBrightCode and above in the darker
// frame), and only where they are this many: the dark ones also carry the camera's dark offset,
// which the curve absorbs as best it can. Measured on legitimate series (stops -3 .. +3, JPEG
// q 95): cameras whose black sits at code 33 (gamma 2.6, black 0.5 % of full scale) or 66
// (black 3 %) give 0.38 - 0.49 over all values at every pair, and at most 0.0083 over the bright
// ones (15 000 - 69 000 of them a pair); the test's legitimate series 0.0021 and 0.0045; its
// last exposure stated a stop too long 0.50 and 0.47 (45 000 bright values), refused.
constexpr long long kFitMinBrightSamples = 1000;

// ---- dark.is_dark -------------------------------------------------------------------------

// Level: the frame's median of 16 x 16 block means after a 5 x 5 median filter (fraction of
// full scale, decoder linear units). Measured: 0.0001 - 0.002 on the real-camera JPEG dark frames
// (-2 .. +2 stops), 0.011 - 0.026 on the RAW camera's (its sensor black level 0.01 is in the
// data; dark current at +2 stops), 0.11 on the exaggerated dark current of
// tests/e2e/radiometry_test.cc (0.05 per unit exposure, at exposure 2); an all-white frame 1.0, a
// mid-gray one 0.16 (warned). A capped lens past 5 % is suspicious (a long exposure, a warm
// sensor), past 20 % it is a photo of light. Slide photos and flat frames have a dark median
// (0.0002 - 0.002: the screen fills less than half the photo) and are told by their structure:
// the 99th percentile of the block means above the median. Measured: at most 0.00015 on the
// dark frames above (hot pixels are gone in the median filter, the per-pixel dark current
// averages out); slide photos 0.055 (the darkest bracket of an edge position) to 0.97, a flat
// frame 0.51.
constexpr double kDarkLevelWarn = 0.05, kDarkLevelFail = 0.2;
constexpr double kDarkStructureFail = 0.01;
constexpr int kDarkBlockPx = 16;

// ---- flat ---------------------------------------------------------------------------------

// Mean level of the flat frames on the screen (fraction of full scale at each frame's own
// exposure). Measured: 0.3 - 0.5 on the synthetic and real-camera flats (flat_level 0.5 with
// vignetting and screen gain); a dark frame given as a flat: below 0.002 (after the dark map:
// about 0). A flat below 1 % of full scale is all noise.
constexpr double kFlatMinLevel = 0.01;
// The gain's spread over the screen, 99th over 1st percentile (flat_calibrator.cc). Measured:
// 1.63 - 1.66 on the real-camera JPEG and RAW flats (vignetting k1 -0.1, screen gain +-15 %); a
// slide photo given as a flat: 8.8 - 41 (the luminaire's pattern, with the room's light under
// it). A lens's vignetting and a screen's non-uniformity together rarely pass 1.6 stops (3):
// warned; beyond 2.6 stops (6) the frames show a pattern of light, not a screen's gain.
constexpr double kFlatSpreadWarn = 3, kFlatSpreadFail = 6;
// Structured fraction (flat_calibrator.cc): at most 0.001 on legitimate flats (synthetic float,
// real-camera JPEG and RAW); slide photos given as flats: 0.010 - 0.044. Up to 1 % can be dust
// and a screen's texture.
constexpr double kFlatStructureWarn = 0.01;

// ---- scale --------------------------------------------------------------------------------

// The reference point's signal (Y+ - Y-) against the position's peak luminance through T+.
// Measured: 0.5 - 1 at the synthetic and real-camera reference points (the centre of the
// luminaire's pattern); a point in the pattern's dark surround (500, 500 mm on the real-camera
// JPEG capture): 0.0003, a scale 1000 times too large. Under 2 % of the peak the photos' noise
// and ambient light weigh in the difference (warned); under 0.2 % the difference is noise.
constexpr double kPointWarnFraction = 0.02, kPointFailFraction = 0.002;
// The brackets of one slide at the point (per unit exposure, those above kBracketMinLevel of full
// scale at capture): largest over smallest. Measured: 1.00 - 1.02 on the real-camera JPEG and
// RAW chains. A response curve or dark map that does not fit the photos shows here first.
constexpr double kBracketWarn = 1.1, kBracketMinLevel = 0.05;
// Against dataset.json's radiometry.scale_w_m2 (an estimate from the camera's settings, or a
// previous calibration): the synthetic chains agree to 0.2 %; a factor of 2 is not an
// estimate's error.
constexpr double kDatasetScaleWarn = 2;

}  // namespace

void CheckExposureOrder(const std::vector<CalibrationFrame>& frames, CheckLog* checks) {
  std::vector<size_t> order(frames.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return frames[a].exposure < frames[b].exposure; });
  std::vector<cv::Mat> values(frames.size());
  for (size_t k = 0; k < frames.size(); ++k) values[k] = SampledValues(frames[k].photo);
  json pairs = json::array();
  double worst = 1;
  size_t worst_pair = 0;
  for (size_t p = 0; p + 1 < order.size(); ++p) {
    const CalibrationFrame& a = frames[order[p]];
    const CalibrationFrame& b = frames[order[p + 1]];
    if (a.exposure == b.exposure) continue;
    const PairOrder o = ComparePair(values[order[p]], values[order[p + 1]]);
    pairs.push_back({{"darker", a.photo.path},
                     {"brighter", b.photo.path},
                     {"changing_pixels", o.changing()},
                     {"brighter_fraction", o.b_brighter()}});
    if (o.changing() >= kOrderMinPixels && o.b_brighter() < worst)
      worst = o.b_brighter(), worst_pair = p;
  }
  json values_json = {{"pairs", pairs},
                      {"worst_fraction", worst},
                      {"fail_below", kOrderFail},
                      {"warn_below", kOrderWarn}};
  if (worst >= kOrderWarn) {
    checks->Pass("response.exposure_order",
                 "the frames' pixels get brighter in the order of the stated exposures (worst "
                 "pair: " +
                     Num(100 * worst, 3) + " % of the changing pixels)",
                 values_json);
    return;
  }
  const CalibrationFrame& a = frames[order[worst_pair]];
  const CalibrationFrame& b = frames[order[worst_pair + 1]];
  std::string message = b.photo.path + ": exposure: stated " + Num(b.exposure) + " (above " +
                        a.photo.path + "'s " + Num(a.exposure) + "), but it is the brighter of " +
                        "the two at only " + Num(100 * worst, 3) +
                        " % of the unclipped pixels that change between them";
  if (worst >= kOrderFail) {
    checks->Warn("response.exposure_order",
                 message + " (a monotonic response makes it 100 %: is the scene still?)",
                 values_json);
    return;
  }
  // The order the pixels imply: each frame ranked by how many others it is brighter than.
  std::vector<int> wins(frames.size(), 0);
  for (size_t i = 0; i < frames.size(); ++i)
    for (size_t j = i + 1; j < frames.size(); ++j) {
      const PairOrder o = ComparePair(values[i], values[j]);
      if (o.changing() < kOrderMinPixels) continue;
      ++(o.b_brighter() > 0.5 ? wins[j] : wins[i]);
    }
  std::vector<size_t> implied = order;
  std::stable_sort(implied.begin(), implied.end(),
                   [&](size_t x, size_t y) { return wins[x] < wins[y]; });
  std::string implied_text;
  json implied_json = json::array();
  for (size_t k : implied) {
    implied_text += (implied_text.empty() ? "" : ", ") + frames[k].photo.path;
    implied_json.push_back(frames[k].photo.path);
  }
  values_json["implied_order"] = implied_json;
  checks->Fail("response.exposure_order",
               message +
                   ": the stated exposures contradict the pixels, which put the frames in "
                   "the order (darkest first) " +
                   implied_text +
                   " (were --exposures given in another order than --frames, e.g. a shell "
                   "glob's ev+1 before ev-1?)",
               values_json);
}

void CheckResponseFit(const nlohmann::json& report, CheckLog* checks) {
  // The worst pair over all its values (warned), and over its bright values where they are
  // enough to judge (refused).
  double worst = 0, worst_bright = 0;
  const json *worst_pair = nullptr, *worst_bright_pair = nullptr;
  for (const json& p : report["pairs"]) {
    if (p["samples"].get<long long>() > 0 && std::abs(p["mean_log_ratio"].get<double>()) >= worst)
      worst = std::abs(p["mean_log_ratio"].get<double>()), worst_pair = &p;
    if (p.value("bright_samples", 0LL) >= kFitMinBrightSamples &&
        std::abs(p.value("bright_mean_log_ratio", 0.0)) >= worst_bright)
      worst_bright = std::abs(p.value("bright_mean_log_ratio", 0.0)), worst_bright_pair = &p;
  }
  const json values = {{"worst_abs_mean_log_ratio", worst},
                       {"worst_abs_bright_mean_log_ratio", worst_bright},
                       {"warn_above", kFitWarn},
                       {"fail_above", kFitFail},
                       {"min_bright_samples", kFitMinBrightSamples},
                       {"pairs", report["pairs"]}};
  const auto message = [](const json& p, const char* mean) {
    const double implied = p["stated_ratio"].get<double>() * std::exp(p[mean].get<double>());
    return p["brighter"].get<std::string>() +
           ": exposure: the frames linearised by the fitted curve give it " + Num(implied) +
           " times the exposure of " + p["darker"].get<std::string>() + ", stated " +
           Num(p["stated_ratio"].get<double>()) +
           " (report.pairs of calib/response.json lists every pair)";
  };
  if (worst_bright_pair && worst_bright > kFitFail)
    checks->Fail("response.fit_explains_frames",
                 message(*worst_bright_pair, "bright_mean_log_ratio") + ", at codes " +
                     std::to_string(kResponseBrightCode) +
                     " and above: no curve explains these frames with these exposures",
                 values);
  if (!worst_pair || worst <= kFitWarn) {
    checks->Pass("response.fit_explains_frames",
                 "the curve-linearised frames agree with the stated exposure ratios to " +
                     Num(100 * worst, 2) + " % (worst consecutive pair)",
                 values);
    return;
  }
  // The bright values agree where the dark ones do not: the curve cannot hold the camera's dark
  // offset (a black level the curve absorbs), not an exposure's error.
  const bool dark_only = worst_bright_pair && worst_bright <= kFitWarn;
  checks->Warn("response.fit_explains_frames",
               message(*worst_pair, "mean_log_ratio") +
                   (dark_only ? ", but at codes " + std::to_string(kResponseBrightCode) +
                                    " and above the frames agree to " + Num(100 * worst_bright, 2) +
                                    " %: the curve cannot hold the camera's dark offset; take "
                                    "dark frames (calibrate dark) and mind the darkest codes"
                              : std::string(": the curve sits off its own data; check the "
                                            "stated exposures")),
               values);
}

void CheckDarkFrames(const std::vector<CalibrationFrame>& frames, CheckLog* checks) {
  json per_frame = json::array();
  double worst_level = 0, worst_structure = 0;
  const CalibrationFrame* worst_frame = nullptr;
  for (const CalibrationFrame& f : frames) {
    cv::Mat gray = LinearGray(f.photo), filtered, blocks;
    cv::medianBlur(gray, filtered, 5);
    cv::resize(
        filtered, blocks,
        cv::Size(std::max(1, gray.cols / kDarkBlockPx), std::max(1, gray.rows / kDarkBlockPx)), 0,
        0, cv::INTER_AREA);
    const std::vector<float> b(blocks.begin<float>(), blocks.end<float>());
    const double level = Percentile(b, 0.5), structure = Percentile(b, 0.99) - level;
    per_frame.push_back({{"file", f.photo.path}, {"level", level}, {"structure", structure}});
    if (!worst_frame || level > worst_level || structure > worst_structure) worst_frame = &f;
    worst_level = std::max(worst_level, level);
    worst_structure = std::max(worst_structure, structure);
  }
  const json values = {{"frames", per_frame},
                       {"level_warn_above", kDarkLevelWarn},
                       {"level_fail_above", kDarkLevelFail},
                       {"structure_fail_above", kDarkStructureFail}};
  for (const json& f : per_frame) {
    const std::string file = f["file"];
    const double level = f["level"], structure = f["structure"];
    if (level > kDarkLevelFail)
      checks->Fail("dark.is_dark",
                   file + ": dark level: expected a capped lens's (below " +
                       Num(100 * kDarkLevelFail, 2) + " % of full scale), got " +
                       Num(100 * level, 3) + " %: a photo of light, not a dark frame",
                   values);
    if (structure > kDarkStructureFail)
      checks->Fail("dark.is_dark",
                   file + ": pixel data: expected an even dark frame, got regions " +
                       Num(100 * structure, 3) + " % of full scale above its median level " +
                       Num(100 * level, 3) + " %: a pattern of light (a lit screen, a slide), " +
                       "not a capped lens",
                   values);
  }
  if (worst_level > kDarkLevelWarn) {
    checks->Warn("dark.is_dark",
                 "dark level up to " + Num(100 * worst_level, 3) +
                     " % of full scale (a capped lens gives well under " +
                     Num(100 * kDarkLevelWarn, 2) +
                     " % at ordinary exposures): is the lens capped and the frame long-exposed?",
                 values);
    return;
  }
  checks->Pass("dark.is_dark",
               "dark frames even and dark: level at most " + Num(100 * worst_level, 3) +
                   " % of full scale, structure at most " + Num(100 * worst_structure, 3) + " %",
               values);
}

void CheckFlatSignal(const std::string& file, double level, CheckLog* checks) {
  const json values = {{"mean_level", level}, {"fail_below", kFlatMinLevel}};
  if (!(level >= kFlatMinLevel))
    checks->Fail("flat.has_signal",
                 file + ": pixel data: expected a lit screen (mean level at least " +
                     Num(100 * kFlatMinLevel, 2) + " % of full scale), got " + Num(100 * level, 3) +
                     " %: a dark frame, not a flat",
                 values);
  checks->Pass("flat.has_signal",
               "flat frames at " + Num(100 * level, 3) + " % of full scale on the screen", values);
}

void CheckFlat(const nlohmann::json& report, CheckLog* checks) {
  const std::string first = report["frames"][0]["file"];
  const double structured = report["structured_fraction"];
  const double p01 = report["gain_percentiles_1_99"][0], p99 = report["gain_percentiles_1_99"][1];
  const double spread = p01 > 0 ? p99 / p01 : std::numeric_limits<double>::infinity();
  const json values = {{"structured_fraction", structured},
                       {"gain_percentiles_1_99", {p01, p99}},
                       {"spread", spread},
                       {"structure_warn_above", kFlatStructureWarn},
                       {"spread_warn_above", kFlatSpreadWarn},
                       {"spread_fail_above", kFlatSpreadFail}};
  const std::string found = "the gain spans " + Num(spread, 3) +
                            " times over the screen (99th / 1st percentile) and " +
                            Num(100 * structured, 3) +
                            " % of the screen's pixels differ from the smooth gain around them by "
                            "more than 20 %";
  if (!(spread <= kFlatSpreadFail))
    checks->Fail("flat.is_flat",
                 first + ": pixel data: expected a uniformly lit screen, got a gain that spans " +
                     Num(spread, 3) +
                     " times over the screen (vignetting and a screen's "
                     "non-uniformity stay within " +
                     Num(kFlatSpreadFail) + "): a pattern of light (a slide photo?), not a flat",
                 values);
  if (spread > kFlatSpreadWarn || structured > kFlatStructureWarn) {
    checks->Warn("flat.is_flat",
                 first + ", ...: " + found +
                     ": vignetting and a screen's non-uniformity are smooth, so these frames may "
                     "not show the uniformly lit screen (a light pattern, a shadow, an object in "
                     "view)",
                 values);
    return;
  }
  checks->Pass("flat.is_flat", found, values);
}

void CheckScale(const nlohmann::json& report, double scale, CheckLog* checks) {
  const std::string reference = report["reference"];
  const double value_p = report["value_p"], value_n = report["value_n"];
  const double peak = report["peak_value_p"];
  const double fraction = peak > 0 ? (value_p - value_n) / peak : 0;
  const json lit = {{"signal_fraction_of_peak", fraction},
                    {"value_p", value_p},
                    {"value_n", value_n},
                    {"peak_value_p", peak},
                    {"warn_below", kPointWarnFraction},
                    {"fail_below", kPointFailFraction}};
  const std::string weak = reference + ": point_mm: the photos' signal there (Y+ - Y-) is " +
                           Num(100 * fraction, 3) + " % of the position's peak";
  if (fraction < kPointFailFraction)
    checks->Fail("scale.point_lit",
                 weak +
                     ": the photos see no light of the luminaire there, the scale would be "
                     "their noise; take the reading where the light is strong",
                 lit);
  if (fraction < kPointWarnFraction)
    checks->Warn("scale.point_lit",
                 weak +
                     ": noise and ambient light weigh in the scale; take the reading where "
                     "the light is strong",
                 lit);
  else
    checks->Pass(
        "scale.point_lit",
        "signal at the reference point " + Num(100 * fraction, 3) + " % of the position's peak",
        lit);
  double spread = 1;
  for (const char* slide : {"bracket_values_p", "bracket_values_n"}) {
    double lo = 0, hi = 0;
    for (const json& b : report[slide]) {
      if (b["level"].get<double>() < kBracketMinLevel) continue;
      const double v = b["value"];
      lo = lo == 0 ? v : std::min(lo, v), hi = std::max(hi, v);
    }
    if (lo > 0) spread = std::max(spread, hi / lo);
  }
  const json brackets = {{"largest_over_smallest", spread},
                         {"warn_above", kBracketWarn},
                         {"p", report["bracket_values_p"]},
                         {"n", report["bracket_values_n"]}};
  if (spread > kBracketWarn)
    checks->Warn("scale.brackets_agree",
                 reference +
                     ": the brackets of one slide disagree at the reference point by a "
                     "factor " +
                     Num(spread) +
                     " per unit exposure: the response curve or dark map "
                     "does not fit these photos",
                 brackets);
  else
    checks->Pass("scale.brackets_agree",
                 "the brackets agree at the reference point to a factor " + Num(spread), brackets);
  if (report.contains("dataset_scale_w_m2")) {
    const double expected = report["dataset_scale_w_m2"];
    const double ratio = scale / expected;
    const json v = {{"scale", scale},
                    {"dataset_scale_w_m2", expected},
                    {"ratio", ratio},
                    {"warn_beyond_factor", kDatasetScaleWarn}};
    if (!(ratio <= kDatasetScaleWarn && ratio >= 1 / kDatasetScaleWarn))
      checks->Warn("scale.matches_dataset",
                   reference + ": the scale " + Num(scale) + " is " + Num(ratio) +
                       " times dataset.json's radiometry.scale_w_m2 " + Num(expected) +
                       ": one of the two is wrong (the readings' unit, the photos' corrections)",
                   v);
    else
      checks->Pass("scale.matches_dataset",
                   "scale " + Num(ratio) + " times dataset.json's radiometry.scale_w_m2", v);
  }
}

double Percentile(std::vector<float> v, double q) {
  if (v.empty()) return 0;
  const size_t k = std::min(v.size() - 1, size_t(q * double(v.size())));
  std::nth_element(v.begin(), v.begin() + long(k), v.end());
  return v[k];
}

}  // namespace lumislab
