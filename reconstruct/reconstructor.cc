#include "reconstruct/reconstructor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>

#include "core/error.h"
#include "core/log.h"
#include "lib/photo/dataset_photo.h"

namespace lumislab {

namespace {
double SecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Where every photo is an integer one read through a linear transfer (so that a code step is the
// near-black floor's unit, docs/method.md §3.5.1): the brightest stored code of the photos above
// their black level, in code steps, if it lies below `floor`; else the first row maximum met at
// or above `floor` (the scan stops there: a lit position is told after a row or a few, where
// the whole scan reads every sample, 864 MB for six 16-bit RGB 6000 x 4000 photos). -1 for other
// photos.
double BrightestCodesBelow(const std::vector<DecodedPhoto>& photos, double floor) {
  for (const auto& p : photos) {
    const int depth = p.photo.pixels.depth();
    if ((depth != CV_8U && depth != CV_16U) || p.photo.fractional_codes ||
        p.photo.transfer != Transfer::kLinear)
      return -1;
  }
  double brightest = -1;
  for (const auto& p : photos) {
    const cv::Mat& m = p.photo.pixels;
    const double black = p.photo.spec.black_level * p.photo.CodeMax();
    for (int y = 0; y < m.rows; ++y) {
      double hi = 0;
      cv::minMaxLoc(m.row(y).reshape(1), nullptr, &hi);
      brightest = std::max(brightest, hi - black);
      if (brightest >= floor) return brightest;
    }
  }
  return brightest;
}
}  // namespace

void ReconstructOptions::Check() const {
  if (resolution < 4 || resolution > 8192)
    throw BadInput("--resolution: expected an integer in [4, 8192], got " +
                   std::to_string(resolution));
  if (!(lambda >= 0 && lambda <= 1))
    throw BadInput("--lambda: expected a number in [0, 1], got " + std::to_string(lambda));
  if (samples_per_texel < 0 || samples_per_texel > 64)
    throw BadInput("--samples-per-texel: expected 0 (auto) .. 64, got " +
                   std::to_string(samples_per_texel));
  merge.Check();
}

std::vector<DecodedPhoto> DecodePosition(
    const Dataset& dataset, const ScreenCalibration& calibration, int i, int j,
    const std::shared_ptr<const PhotoCorrections>& corrections) {
  const std::vector<PhotoEntry> entries = dataset.PhotosOf(i, j);
  bool has_p = false, has_n = false;
  for (const auto& e : entries) (e.positive ? has_p : has_n) = true;
  if (!has_p || !has_n)
    throw InputError(dataset.Path("dataset.json"), "photos",
                     "photos of both slides (p and n) for every grid position",
                     "position " + std::to_string(i) + "," + std::to_string(j) + " lacks " +
                         (has_p ? "n" : "p"));
  std::vector<DecodedPhoto> photos;
  for (const auto& e : entries) photos.push_back(DecodeDatasetPhoto(dataset, e, corrections));
  CheckPhotoSizes(photos, calibration.image_width, calibration.image_height,
                  dataset.Path("calib/screen.json"));
  // One camera writes one kind of photo: an 8-bit photo among 16-bit ones (or the other way)
  // would be linearised differently and merged as if it were the same measurement.
  for (const auto& p : photos)
    if (p.photo.CodeBits() != photos[0].photo.CodeBits())
      throw InputError(
          p.photo.path, "bit depth",
          std::to_string(photos[0].photo.CodeBits()) + " bits like " + photos[0].photo.path,
          std::to_string(p.photo.CodeBits()) + " bits");
  if (photos[0].photo.transfer == Transfer::kSrgb && dataset.photo_transfer == "auto") {
    static std::once_flag said;
    std::call_once(said, [&] {
      LogWarning("sRGB curve: no calib/response.json; 8-bit photos (", photos[0].photo.path,
                 ", ...) are linearised through the sRGB curve (run lumislab-calibrate response, "
                 "or set radiometry.transfer in dataset.json if the camera wrote them otherwise)");
    });
  }
  return photos;
}

SlabPosition ReconstructDecoded(const Dataset& dataset, const ScreenCalibration& calibration,
                                const SlabInfo& info, int i, int j,
                                const std::vector<DecodedPhoto>& photos,
                                const ReconstructOptions& options, PositionReport* report) {
  PositionReport local;
  PositionReport& r = report ? *report : local;
  r.i = i, r.j = j;
  auto t0 = std::chrono::steady_clock::now();
  // 1. Geometry: where each texel's samples fall in the photo (and how much to pre-average).
  const SlabLayout& layout = info.layout;
  const RectifyMap map =
      BuildRectifyMap(calibration, layout, dataset.grid.Centre(i, j), dataset.screen_w_mm,
                      dataset.screen_h_mm, options.samples_per_texel);
  r.samples_per_texel = map.samples_per_texel;
  r.downsample = map.downsample;
  r.map_s = SecondsSince(t0);
  auto t1 = std::chrono::steady_clock::now();
  // 2. Linear, merged, E = peak * scale * (E+ - E-) in photo space, saturation flagged.
  // calib/scale.json when calibrated, else dataset.json's scale (LoadReconstructRadiometry).
  const std::optional<double> scale =
      options.radiometry ? options.radiometry->scale : dataset.radiometric_scale;
  const double gain = dataset.filter.peak * scale.value_or(1.0);
  // Only the photo pixels that reach the slab (the map's read region) are merged and counted.
  const MergedPosition merged =
      MergePosition(photos, gain, map.downsample, options.merge, map.read_region);
  r.saturated_pixels = merged.saturated_pixels;
  r.exposures = merged.exposures;
  r.near_black_pixels = merged.near_black_pixels;
  r.brightest = merged.brightest, r.faintest = merged.faintest;
  r.dynamic_range_stops = merged.dynamic_range_stops;
  r.bracket_ratios = merged.ratios;
  r.merge_s = SecondsSince(t1);
  t1 = std::chrono::steady_clock::now();
  // 3. Into the luminaire frame, area-averaged per texel.
  const cv::Mat texels = Rectify(merged.signal, map);
  const int tc = texels.channels();
  r.remap_s = SecondsSince(t1);
  const size_t n = size_t(layout.res_x) * layout.res_y;
  std::vector<unsigned char> seen(n, 0);
  std::vector<double> data(n * 3, 0.0);
  r.seen_texels = 0;
  r.saturated_texels = 0;
  for (int row = 0; row < layout.res_y; ++row) {
    const float* t = texels.ptr<float>(row);
    for (int col = 0; col < layout.res_x; ++col, t += tc) {
      const size_t k = size_t(row) * layout.res_x + col;
      if (!map.inside[k]) continue;
      if (tc == 4 && t[3] > 0) {
        ++r.saturated_texels;
        continue;
      }
      seen[k] = 1;
      ++r.seen_texels;
      for (int c = 0; c < 3; ++c) data[k * 3 + c] = t[c];
    }
  }
  r.rectify_s = SecondsSince(t0);
  if (r.seen_texels == 0)
    throw InputError(dataset.Path("calib/screen.json"),
                     "position " + std::to_string(i) + "," + std::to_string(j),
                     "a view of the position's slab window",
                     r.saturated_texels > 0 ? "only saturated texels (every photo clipped)"
                                            : "no texel inside the photo and the screen");
  // 3. Deconvolution onto the bell basis.
  t0 = std::chrono::steady_clock::now();
  BellFitOptions fit_options;
  fit_options.lambda = options.lambda;
  BellFitReport fit_report;
  std::vector<double> c;
  try {
    c = FitBell(data, seen, layout.res_x, layout.res_y, 3, fit_options, &fit_report);
  } catch (const Error& e) {
    throw Failure("position " + std::to_string(i) + "," + std::to_string(j) +
                  ": the fit onto the bell basis failed (" + e.what() + ")");
  }
  r.fit_iterations = fit_report.iterations;
  r.fit_residual = fit_report.relative_residual;
  double moved = 0, total = 0;
  for (size_t k = 0; k < n; ++k)
    if (seen[k])
      for (int ch = 0; ch < 3; ++ch)
        moved += std::abs(c[k * 3 + ch] - data[k * 3 + ch]), total += std::abs(data[k * 3 + ch]);
  r.bell_correction = total > 0 ? moved / total : 0;
  r.brightest_codes = BrightestCodesBelow(photos, options.merge.near_black_codes);
  r.no_light =
      total == 0 || (r.brightest_codes >= 0 && r.brightest_codes < options.merge.near_black_codes);
  SlabPosition out;
  out.i = i, out.j = j;
  out.irradiance = ImageF(layout.res_x, layout.res_y, 3);
  out.mask = ImageF(layout.res_x, layout.res_y, 1);
  for (size_t k = 0; k < n; ++k) {
    if (!seen[k]) continue;
    out.mask.data[k] = 1.f;
    for (int ch = 0; ch < 3; ++ch) {
      const float v = float(c[k * 3 + ch]);
      if (!std::isfinite(v))
        throw Failure("position " + std::to_string(i) + "," + std::to_string(j) +
                      ": non-finite value after the fit");
      out.irradiance.data[k * 3 + ch] = v;
    }
  }
  r.fit_s = SecondsSince(t0);
  return out;
}

SlabPosition ReconstructPosition(const Dataset& dataset, const ScreenCalibration& calibration,
                                 const SlabInfo& info, int i, int j,
                                 const ReconstructOptions& options, PositionReport* report) {
  PositionReport local;
  PositionReport& r = report ? *report : local;
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<DecodedPhoto> photos = DecodePosition(
      dataset, calibration, i, j, options.radiometry ? options.radiometry->corrections : nullptr);
  const double decode_s = SecondsSince(t0);
  SlabPosition out = ReconstructDecoded(dataset, calibration, info, i, j, photos, options, &r);
  r.decode_s = decode_s;
  return out;
}

}  // namespace lumislab
