#include "noise_floor.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "core/dataset.h"
#include "core/exr_io.h"
#include "core/screen_calibration.h"
#include "core/slab.h"

namespace lumislab::testing {

double SensorNoiseModel::Variance(double s) const {
  const double q = code_step(s);
  return (std::max(0.0, s) * full_well_e + read_noise_e * read_noise_e) /
             (full_well_e * full_well_e) +
         q * q / 12;
}

namespace {

// The photos of one position, read once: each slide's exposures and sensor values.
struct SlidePhotos {
  std::vector<double> exposure;
  std::vector<ImageF> image;
  std::vector<JpegCodingModel> jpeg;  // per exposure, for a JPEG camera
};

// Merged variance of one slide's channel at pixel (x, y), exposure-normalised (exposure 1):
// the inverse-variance merge of the unclipped exposures. Where every exposure is clipped the
// merge has nothing (the pixel is masked as saturated): 0.
// For a JPEG camera (`spectrum` given), the merge keeps its weights (reconstruct knows the
// sensor's noise and one code's rounding, not the coding), and each exposure's variance is what
// JpegCodingModel predicts for the texel's mean, as a per-pixel variance in sensor values:
// var = sum_k w_k^2 var_k / (sum_k w_k t_k)^2 with w_k = t_k / V_k.
double MergedVariance(const SlidePhotos& slide, int x, int y, int ch,
                      const SensorNoiseModel& sensor, const JpegSpectrum* spectrum = nullptr) {
  double information = 0, jpeg = 0;
  for (size_t k = 0; k < slide.image.size(); ++k) {
    const double s = slide.image[k].at(x, y, ch);
    if (s >= sensor.saturation) continue;
    const double t = slide.exposure[k], model = sensor.Variance(s);
    information += t * t / model;
    if (spectrum) {
      const double step = sensor.code_step(s);  // sensor value per code
      const double coded = slide.jpeg[k].WhiteEquivalentVariance(x, y, *spectrum)[ch] * step * step;
      jpeg += t * t * coded / (model * model);
    }
  }
  if (information <= 0) return 0;
  return spectrum ? jpeg / (information * information) : 1 / information;
}

// Channel of the RGGB mosaic's sample at pixel (x, y): R at even x and y, B at odd ones.
int BayerChannel(int x, int y) { return (y & 1) ? ((x & 1) ? 2 : 1) : ((x & 1) ? 1 : 0); }

// For a weighted sum of the photo's pixels (channel ch), the sum of the squared weights of the
// sensor's samples behind it: each sample's noise is independent, so this is the sum's variance
// per unit sample variance. With a mosaic, a pixel's value of a channel it does not sample is
// the mean of that channel's samples in its 3 x 3 (lib/photo's demosaic).
double SampleWeightSquares(const PixelWeights& pixels, int ch, bool bayer) {
  PixelWeights samples;
  for (const auto& [p, w] : pixels) {
    const auto [x, y] = p;
    if (!bayer || BayerChannel(x, y) == ch) {
      samples[p] += w;
      continue;
    }
    std::vector<std::pair<int, int>> own;
    for (int yy = y - 1; yy <= y + 1; ++yy)
      for (int xx = x - 1; xx <= x + 1; ++xx)
        if (BayerChannel(xx, yy) == ch) own.emplace_back(xx, yy);
    for (const auto& q : own) samples[q] += w / double(own.size());
  }
  double sum = 0;
  for (const auto& [p, w] : samples) sum += w * w;
  return sum;
}

// The variance of a texel's value per unit sample variance (SampleWeightSquares) for a square
// texel of side `side` photo pixels, as reconstruct forms it: F x F pixel means (F = round(side
// / 3), at least 1), K x K bilinear samples at ((a + 0.5) / K, (b + 0.5) / K) of the texel
// (K = ceil(side / F), in [2, 12]), averaged; over 16 sub-pixel offsets of the texel and, with
// a mosaic, its 4 phases. Cached per side (to 1/20 px) and channel.
// The pixel weights of such a texel (side to 1/20 px) at each of the 16 offsets and, with a
// mosaic, 4 phases.
std::vector<PixelWeights> TexelPixelWeights(double side, bool bayer) {
  std::vector<PixelWeights> patterns;
  const int f = std::max(1, int(std::lround(side / 3)));
  const int k = std::clamp(int(std::ceil(side / f)), 2, 12);
  for (int phase = 0; phase < (bayer ? 4 : 1); ++phase)
    for (int oy = 0; oy < 4; ++oy)
      for (int ox = 0; ox < 4; ++ox) {
        // A texel corner at an even coarse pixel (64 F), shifted by a quarter-pixel offset and the
        // mosaic's phase.
        const double x0 = 64 * f + (phase & 1) + 0.25 * ox * f;
        const double y0 = 64 * f + (phase >> 1) + 0.25 * oy * f;
        PixelWeights coarse, pixels;
        for (int b = 0; b < k; ++b)
          for (int a = 0; a < k; ++a) {
            // The sample in photo pixels, then in the F x F mean's pixels (centre of pixel q at
            // q F + (F - 1) / 2).
            const double u = (x0 + (a + 0.5) * side / k - 0.5 * (f - 1)) / f;
            const double v = (y0 + (b + 0.5) * side / k - 0.5 * (f - 1)) / f;
            const int qx = int(std::floor(u)), qy = int(std::floor(v));
            const double fx = u - qx, fy = v - qy, w = 1.0 / (k * k);
            coarse[{qx, qy}] += w * (1 - fx) * (1 - fy);
            coarse[{qx + 1, qy}] += w * fx * (1 - fy);
            coarse[{qx, qy + 1}] += w * (1 - fx) * fy;
            coarse[{qx + 1, qy + 1}] += w * fx * fy;
          }
        for (const auto& [q, w] : coarse)
          for (int dy = 0; dy < f; ++dy)
            for (int dx = 0; dx < f; ++dx)
              pixels[{q.first * f + dx, q.second * f + dy}] += w / (f * f);
        patterns.push_back(std::move(pixels));
      }
  return patterns;
}

double TexelVarianceFactor(double side, int ch, bool bayer) {
  static std::map<std::tuple<long, int, bool>, double> cache;
  const auto key = std::make_tuple(std::lround(side * 20), ch, bayer);
  if (const auto it = cache.find(key); it != cache.end()) return it->second;
  double total = 0;
  const std::vector<PixelWeights> patterns = TexelPixelWeights(std::get<0>(key) / 20.0, bayer);
  for (const PixelWeights& p : patterns) total += SampleWeightSquares(p, ch, bayer);
  return cache[key] = total / double(patterns.size());
}

// The JPEG spectrum of such a texel (no mosaic), cached per side.
const JpegSpectrum& TexelJpegSpectrum(double side) {
  static std::map<long, JpegSpectrum> cache;
  const long key = std::lround(side * 20);
  if (const auto it = cache.find(key); it != cache.end()) return it->second;
  return cache[key] = JpegSpectrumOf(TexelPixelWeights(key / 20.0, false));
}

// Relative variance of calibrate scale's Y+ - Y- (docs/formats.md §16): per slide, the
// photos unclipped over the fit's disc, their exposure-weighted mean of the quadratic fit's
// constant term, whose variance is [(A^T A)^-1]_00 x a pixel's over the disc's pixels.
double ScaleRelativeVariance(const ScreenCalibration& cal,
                             const std::map<bool, SlidePhotos>& slides, const ImageF* gain,
                             const ImageF* dark, const SensorNoiseModel& sensor,
                             const ChainNoiseModel& chain) {
  const Eigen::Vector2d at = cal.ImageFromScreen(chain.reference_mm);
  const int r = chain.reference_radius_px;
  const int x0 = int(std::round(at.x())), y0 = int(std::round(at.y()));
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  std::vector<std::pair<int, int>> disc;
  std::vector<Eigen::Matrix<double, 6, 1>> rows;
  for (int y = y0 - r - 1; y <= y0 + r + 1; ++y)
    for (int x = x0 - r - 1; x <= x0 + r + 1; ++x) {
      const double dx = x - at.x(), dy = y - at.y();
      if (dx * dx + dy * dy > double(r) * r + 0.5) continue;
      Eigen::Matrix<double, 6, 1> row;
      row << 1, dx, dy, dx * dx, dx * dy, dy * dy;
      ata += row * row.transpose();
      disc.emplace_back(x, y);
      rows.push_back(row);
    }
  // The fit's constant term is sum_p w_p value_p with w = first row of (A^T A)^-1 A^T.
  const Eigen::Matrix<double, 6, 6> inverse = ata.inverse();
  PixelWeights fit_weights;
  for (size_t p = 0; p < disc.size(); ++p) fit_weights[disc[p]] = inverse.row(0).dot(rows[p]);
  double fit[3];
  for (int c = 0; c < 3; ++c) fit[c] = SampleWeightSquares(fit_weights, c, sensor.bayer_rggb);
  const double luminance[3] = {0.2126, 0.7152, 0.0722};
  const double g = gain ? gain->at(x0, y0, 0) : 1.0;
  double value[2] = {0, 0}, variance[2] = {0, 0};
  for (const auto& [positive, slide] : slides) {
    double t_sum = 0, sum[3] = {0, 0, 0}, var[3] = {0, 0, 0};
    for (size_t k = 0; k < slide.image.size(); ++k) {
      const ImageF& im = slide.image[k];
      bool clipped = false;
      for (const auto& [x, y] : disc)
        for (int c = 0; c < 3; ++c) clipped = clipped || im.at(x, y, c) >= sensor.saturation;
      if (clipped) continue;
      const double t = slide.exposure[k];
      const double d = dark ? dark->at(x0, y0, 0) + dark->at(x0, y0, 1) * t : 0.0;
      t_sum += t;
      for (int c = 0; c < 3; ++c) {
        const double s = im.at(x0, y0, c);
        sum[c] += s - d;
        var[c] += sensor.Variance(s);
      }
    }
    if (t_sum == 0) return 0;  // calibrate scale refuses it
    const int k = positive ? 0 : 1;
    for (int c = 0; c < 3; ++c) {
      value[k] += luminance[c] * sum[c] / t_sum / g;
      variance[k] += luminance[c] * luminance[c] * fit[c] * var[c] / (t_sum * t_sum * g * g);
    }
  }
  const double difference = value[0] - value[1];
  return (variance[0] + variance[1]) / (difference * difference);
}

}  // namespace

NoiseFloor PredictNoiseFloor(const std::string& slab_dir, const std::string& clean,
                             const std::string& screen_json, const std::string& truth_dir,
                             const SensorNoiseModel& sensor, const ChainNoiseModel& chain) {
  const Dataset ds = Dataset::Load(clean);
  const ScreenCalibration cal = ScreenCalibration::Load(screen_json);
  const SlabInfo truth_info = SlabInfo::Load(truth_dir);
  const SlabInfo info = SlabInfo::Load(slab_dir);
  const double a = 5.0 / 6, b = 1.0 / 12;
  const double gain_1d = a / std::pow(a * a - 4 * b * b, 1.5);
  const double deconv_gain = gain_1d * gain_1d;
  const double scale = *ds.radiometric_scale, peak = ds.filter.peak;
  const double texel_area = info.layout.TexelW() * info.layout.TexelH();
  ImageF gain, dark;
  if (!chain.gain_exr.empty()) gain = ReadExr(chain.gain_exr, {"Y"});
  if (!chain.dark_exr.empty()) dark = ReadExr(chain.dark_exr, {"black", "current", "hot"});
  const ImageF* gain_map = chain.gain_exr.empty() ? nullptr : &gain;
  const ImageF* dark_map = chain.dark_exr.empty() ? nullptr : &dark;
  auto read_position = [&](int i, int j) {
    std::map<bool, SlidePhotos> slides;
    for (const PhotoEntry& e : ds.PhotosOf(i, j)) {
      SlidePhotos& slide = slides[e.positive];
      slide.exposure.push_back(e.exposure);
      slide.image.push_back(ReadExr(clean + "/" + e.file, {"R", "G", "B"}));
      if (sensor.jpeg_quality > 0) {
        // The photo's expected codes and their noise in codes (one code: code_step).
        const ImageF& im = slide.image.back();
        ImageF codes(im.width, im.height, 3), variance(im.width, im.height, 3);
        for (size_t p = 0; p < im.data.size(); ++p) {
          const double sv = im.data[p], step = sensor.code_step(sv);
          codes.data[p] = float(std::clamp(sensor.code_of(sv), 0.0, 255.0));
          variance.data[p] = float(sensor.Variance(sv) / (step * step));
        }
        slide.jpeg.emplace_back(codes, variance, sensor.jpeg_quality);
      }
    }
    return slides;
  };
  NoiseFloor out;
  double scale_var = 0;
  if (chain.reference_radius_px > 0)
    scale_var = ScaleRelativeVariance(cal, read_position(chain.reference_i, chain.reference_j),
                                      gain_map, dark_map, sensor, chain);
  out.scale_relative = std::sqrt(scale_var);
  double var_sum = 0, ref2 = 0;
  for (const auto& [i, j] : info.present) {
    const SlabPosition truth = ReadSlabPosition(truth_dir, truth_info, i, j);
    const SlabPosition slab = ReadSlabPosition(slab_dir, info, i, j);
    const std::map<bool, SlidePhotos> slides = read_position(i, j);
    const int w = slides.begin()->second.image[0].width;
    const int h = slides.begin()->second.image[0].height;
    float max_ref = 0;
    for (float v : truth.irradiance.data) max_ref = std::max(max_ref, std::abs(v));
    const Eigen::Vector2d c = ds.grid.Centre(i, j);
    double position_var = 0, position_ref2 = 0;
    for (int row = 0; row < info.layout.res_y; ++row)
      for (int col = 0; col < info.layout.res_x; ++col) {
        const size_t k = size_t(row) * info.layout.res_x + col;
        float mag = 0;
        for (int ch = 0; ch < 3; ++ch)
          mag = std::max(mag, std::abs(truth.irradiance.data[k * 3 + ch]));
        if (mag < 0.01 * max_ref || slab.mask.data[k] < 0.5f) continue;
        const Eigen::Vector2d lab = info.layout.TexelCentre(col, row) - c;
        const Eigen::Vector2d px = cal.ImageFromScreen(lab);
        // Pixel footprint on the screen (mm^2) from the calibration's Jacobian.
        const Eigen::Vector2d dx = cal.ScreenFromImage(px + Eigen::Vector2d(0.5, 0)) -
                                   cal.ScreenFromImage(px - Eigen::Vector2d(0.5, 0));
        const Eigen::Vector2d dy = cal.ScreenFromImage(px + Eigen::Vector2d(0, 0.5)) -
                                   cal.ScreenFromImage(px - Eigen::Vector2d(0, 0.5));
        const double pixel_area = std::abs(dx.x() * dy.y() - dx.y() * dy.x());
        const double side = std::sqrt(texel_area / pixel_area);
        int x = std::clamp(int(std::lround(px.x())), 0, w - 1);
        int y = std::clamp(int(std::lround(px.y())), 0, h - 1);
        // A hot pixel reads as the mean of its nearest pixels that are not hot (lib/photo's
        // defect correction): the noise there is theirs, taken here as that of the nearest one.
        if (dark_map && dark.at(x, y, 2) > 0.5f) {
          int best = -1, bx = x, by = y;
          for (int dy = -2; dy <= 2; ++dy)
            for (int dx = -2; dx <= 2; ++dx) {
              const int xx = x + dx, yy = y + dy, d2 = dx * dx + dy * dy;
              if (xx < 0 || yy < 0 || xx >= w || yy >= h || dark.at(xx, yy, 2) > 0.5f) continue;
              if (best < 0 || d2 < best) best = d2, bx = xx, by = yy;
            }
          x = bx, y = by;
        }
        const double g = gain_map ? gain.at(x, y, 0) : 1.0;
        // The flat's relative variance at this pixel: the mean of its frames.
        double flat_var = 0;
        if (chain.flat_frames > 0) {
          const double t = chain.flat_exposure;
          const double d = dark_map ? dark.at(x, y, 0) + dark.at(x, y, 1) * t : 0.0;
          const double u = chain.flat_level * g * t;
          flat_var = sensor.Variance(u + d) / (u * u) / chain.flat_frames;
        }
        for (int ch = 0; ch < 3; ++ch) {
          double var = 0;
          const JpegSpectrum* spectrum =
              sensor.jpeg_quality > 0 ? &TexelJpegSpectrum(side) : nullptr;
          for (const auto& [positive, slide] : slides)
            var += MergedVariance(slide, x, y, ch, sensor, spectrum);
          const double t = truth.irradiance.data[k * 3 + ch];
          const double averaged = TexelVarianceFactor(side, ch, sensor.bayer_rggb);
          const double v = (peak * peak * scale * scale * var / (g * g) + t * t * flat_var) *
                               averaged * deconv_gain +
                           t * t * scale_var;
          position_var += v;
          position_ref2 += t * t;
        }
      }
    out.positions.push_back({i, j, std::sqrt(position_var / position_ref2)});
    var_sum += position_var;
    ref2 += position_ref2;
  }
  out.overall = std::sqrt(var_sum / ref2);
  return out;
}

}  // namespace lumislab::testing
