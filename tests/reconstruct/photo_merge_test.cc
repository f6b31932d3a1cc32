// The bracket merge (reconstruct/photo_merge.h) on hand-made photos whose radiance is known:
// the noise-model weights against hand-computed values, clipped and near-black pixels, one
// exposure, 8-bit against float brackets, the dynamic range, and exposure ratios estimated from
// the pixels when the recorded exposures are off.
#include "reconstruct/photo_merge.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "core/error.h"
#include "lib/photo/radiometric_calibration.h"

namespace lumislab {
namespace {

// A photo of one slide: `value(x, y, c)` is the curve value as stored (float: the value,
// 8-bit: code / 255), already clipped by the caller; float photos are RGB, 8-bit ones BGR.
DecodedPhoto MakePhoto(int w, int h, bool positive, double exposure, int depth, Transfer transfer,
                       const std::function<double(int, int, int)>& value) {
  DecodedPhoto d;
  d.entry.positive = positive;
  d.entry.exposure = exposure;
  d.photo.spec.exposure = exposure;
  d.photo.transfer = transfer;
  d.photo.rgb_order = depth == CV_32F;
  d.photo.pixels.create(h, w, CV_MAKETYPE(depth, 3));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        const double v = value(x, y, c);
        if (depth == CV_32F)
          d.photo.pixels.at<cv::Vec3f>(y, x)[c] = float(v);
        else
          d.photo.pixels.at<cv::Vec3b>(y, x)[2 - c] = uint8_t(std::lround(v * 255));
      }
  return d;
}
DecodedPhoto Constant(bool positive, double exposure, double value, int w = 4, int h = 4) {
  return MakePhoto(w, h, positive, exposure, CV_32F, Transfer::kLinear,
                   [&](int, int, int) { return value; });
}

cv::Vec4f At(const MergedPosition& m, int x, int y) { return m.signal.at<cv::Vec4f>(y, x); }

double Srgb(double l) {  // linear -> sRGB-encoded, as a camera stores it
  return l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1 / 2.4) - 0.055;
}
double SrgbInverse(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// Under shot noise alone the inverse-variance weights are the exposures: sum u / sum e. With
// read noise the weights e^2 / (e x / FW + (read / FW)^2) favour the longer exposure.
TEST(BracketMerge, NoiseModelWeights) {
  // Deliberately inconsistent exposures (0.1 at 1, 0.5 at 4): the weights decide the result.
  const std::vector<DecodedPhoto> photos = {Constant(true, 1, 0.1), Constant(true, 4, 0.5),
                                            Constant(false, 1, 0.07)};
  MergeOptions shot;
  shot.noise = {1000, 0};
  EXPECT_NEAR(At(MergeFullResolution(photos, 1.0, 1, shot), 1, 2)[0], 0.6 / 5 - 0.07, 1e-7);
  MergeOptions read = shot;
  read.noise.read_noise_e = 20;
  const double x = 0.12, r2 = 0.02 * 0.02;
  const double w1 = 1 / (x / 1000 + r2), w2 = 16 / (4 * x / 1000 + r2);
  const double expected = (w1 * 0.1 + w2 * 0.125) / (w1 + w2) - 0.07;  // 0.05261
  const MergedPosition m = MergeFullResolution(photos, 1.0, 1, read);
  EXPECT_NEAR(At(m, 3, 3)[0], expected, 1e-6);
  EXPECT_GT(At(m, 3, 3)[0], 0.6 / 5 - 0.07 + 0.002);
  EXPECT_EQ(m.exposures, 2);
  EXPECT_EQ(m.saturated_pixels, 0);
}

// A region (what Rectify reads) merges only its blocks: the same numbers bit for bit there, 0
// elsewhere, and the counts over its pixels only. 8-bit sRGB brackets with clipped pixels, rows
// longer than a chunk of the row kernels and a region starting inside one.
TEST(BracketMerge, RegionMergesOnlyItsBlocks) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> radiance(0.0, 4.4);  // > 4: clipped at 0.25
  const int w = 620, h = 20, f = 3;
  std::vector<double> scene(size_t(w) * h * 3);
  for (double& v : scene) v = radiance(rng);
  std::vector<DecodedPhoto> photos;
  for (bool positive : {true, false})
    for (double e : {0.25, 1.0, 4.0})
      photos.push_back(
          MakePhoto(w, h, positive, e, CV_8U, Transfer::kSrgb, [&](int x, int y, int c) {
            const double v = scene[(size_t(y) * w + x) * 3 + c] * (positive ? 1.0 : 0.3);
            return Srgb(std::min(1.0, e * v));
          }));
  const MergedPosition whole = MergeFullResolution(photos, 2.0, f);
  const MergedPosition pixels = MergeFullResolution(photos, 2.0, 1);  // A: saturated per pixel
  const cv::Rect region(90, 2, 101, 3);  // averaged pixels; photo x 270 .. 572, y 6 .. 14
  const MergedPosition m = MergePosition(photos, 2.0, f, {}, region);
  ASSERT_EQ(m.signal.size(), whole.signal.size());
  ASSERT_GT(whole.saturated_pixels, 0);
  for (int y = 0; y < m.signal.rows; ++y)
    for (int x = 0; x < m.signal.cols; ++x) {
      const cv::Vec4f expected = region.contains({x, y}) ? At(whole, x, y) : cv::Vec4f();
      for (int c = 0; c < 4; ++c) ASSERT_EQ(At(m, x, y)[c], expected[c]) << x << "," << y;
    }
  int saturated = 0;
  for (int y = region.y * f; y < region.br().y * f; ++y)
    for (int x = region.x * f; x < region.br().x * f; ++x) saturated += At(pixels, x, y)[3] > 0;
  EXPECT_GT(saturated, 0);
  EXPECT_LT(saturated, whole.saturated_pixels);
  EXPECT_EQ(m.saturated_pixels, saturated);
  EXPECT_GT(m.dynamic_range_stops, 0);
  EXPECT_LE(m.dynamic_range_stops, whole.dynamic_range_stops);
  EXPECT_EQ(m.ratios.size(), whole.ratios.size());  // the ratios: from the whole photo
}

// A pixel clipped in every exposure of a slide is masked (A = 1, RGB 0) and counted; one clipped
// (or NaN) only in the long exposure takes the short one's value exactly.
TEST(BracketMerge, ClippedInEveryExposureIsMaskedAndCounted) {
  auto scene = [](int x, int y) { return x == 2 && y == 3 ? 5.0 : x == 1 && y == 1 ? 0.6 : 0.1; };
  std::vector<DecodedPhoto> photos;
  for (double e : {1.0, 4.0})
    photos.push_back(MakePhoto(8, 8, true, e, CV_32F, Transfer::kLinear, [&](int x, int y, int) {
      // A NaN (a float photo's broken pixel) counts as clipped.
      return x == 6 && y == 6 && e == 4 ? std::nan("") : std::min(1.0, e * scene(x, y));
    }));
  photos.push_back(Constant(false, 1, 0.0, 8, 8));
  const MergedPosition m = MergeFullResolution(photos, 2.0);
  EXPECT_EQ(m.saturated_pixels, 1);
  EXPECT_EQ(At(m, 2, 3), cv::Vec4f(0, 0, 0, 1));
  EXPECT_FLOAT_EQ(At(m, 1, 1)[0], 2 * 0.6f);  // 2.4 clipped at exposure 4
  EXPECT_NEAR(At(m, 5, 5)[1], 2 * 0.1f, 1e-7);
  EXPECT_EQ(At(m, 5, 5)[3], 0.f);
  EXPECT_NEAR(At(m, 6, 6)[2], 2 * 0.1f, 1e-7);  // the NaN left out
  // F x F averaging in the same pass: A is the fraction of saturated pixels of the block.
  const MergedPosition d = MergeFullResolution(photos, 2.0, 2);
  ASSERT_EQ(d.signal.cols, 4);
  EXPECT_FLOAT_EQ(At(d, 1, 1)[3], 0.25f);
  EXPECT_NEAR(At(d, 1, 1)[0], 2 * 0.1f * 3 / 4, 1e-7);
  EXPECT_EQ(d.saturated_pixels, 1);
}

// 8-bit sRGB: a value 3 codes above black in the short exposure is near-black and left out; the
// long exposure alone gives the pixel (the short one, 13 % off by quantisation, would pull it).
TEST(BracketMerge, NearBlackLeftOutWhereALongerExposureMeasured) {
  const double x = SrgbInverse(100 / 255.0) / 128;  // code 100 at exposure 128, 3.3 at 1
  auto photo = [&](double e) {
    return MakePhoto(4, 4, true, e, CV_8U, Transfer::kSrgb,
                     [&](int, int, int) { return std::round(Srgb(e * x) * 255) / 255; });
  };
  const std::vector<DecodedPhoto> photos = {photo(1), photo(128), Constant(false, 1, 0.002)};
  ASSERT_EQ(photos[0].photo.pixels.at<cv::Vec3b>(0, 0)[0], 3);
  const MergedPosition m = MergeFullResolution(photos, 1.0);
  // With its inverse-variance weight (~0.5 %) the short exposure would move the pixel by 4e-4.
  EXPECT_NEAR(At(m, 0, 0)[0] + 0.002, x, 2e-5 * x);
  EXPECT_EQ(m.near_black_pixels, 0);  // the positive slide had a well-exposed value
}

// Near-black in every exposure: the longest exposure is used (no hole), and the pixel counted.
TEST(BracketMerge, NearBlackEverywhereUsesTheLongest) {
  // Default noise model: floor 3 * 3 / 20000 = 4.5e-4 for float photos.
  const std::vector<DecodedPhoto> photos = {Constant(true, 1, 1e-4), Constant(true, 4, 4.4e-4),
                                            Constant(false, 1, 0.2)};
  const MergedPosition m = MergeFullResolution(photos, 1.0);
  EXPECT_NEAR(At(m, 0, 0)[2], 1.1e-4 - 0.2, 1e-7);
  EXPECT_EQ(At(m, 0, 0)[3], 0.f);
  EXPECT_EQ(m.near_black_pixels, 16);
  EXPECT_EQ(m.saturated_pixels, 0);
}

// One 8-bit exposure per slide takes the general path: the values are the decoder's, and the
// dynamic range is that of the well-exposed values (250 / 5 codes, linear transfer).
TEST(BracketMerge, OneExposurePerSlideAndItsDynamicRange) {
  const std::vector<DecodedPhoto> photos = {
      MakePhoto(16, 16, true, 2, CV_8U, Transfer::kLinear,
                [](int x, int y, int) { return (10 + 15 * x) / 255.0; }),
      MakePhoto(16, 16, false, 2, CV_8U, Transfer::kLinear,
                [](int x, int, int) { return (x == 0 ? 2 : 5) / 255.0; })};
  const MergedPosition m = MergeFullResolution(photos, 1.0);
  EXPECT_EQ(m.exposures, 1);
  EXPECT_TRUE(m.ratios.empty());
  EXPECT_NEAR(At(m, 3, 7)[1], (55 - 5) / 255.0 / 2, 1e-7);
  // Column 0 of the negative slide is 2 codes: near-black, but the only exposure (used).
  EXPECT_NEAR(At(m, 0, 0)[1], (10 - 2) / 255.0 / 2, 1e-7);
  EXPECT_EQ(m.near_black_pixels, 16);
  EXPECT_NEAR(m.brightest, 235 / 255.0 / 2, 1e-7);
  EXPECT_NEAR(m.faintest, 5 / 255.0 / 2, 1e-7);
  EXPECT_NEAR(m.dynamic_range_stops, std::log2(235 / 5.0), 1e-5);
  // The fast path (16-bit or float) is unchanged by any of this: one exposure per slide.
  const std::vector<DecodedPhoto> fast = {Constant(true, 1, 0.3), Constant(false, 1, 0.1)};
  EXPECT_TRUE(MergePosition(fast, 1.0).fast_path);
}

// The same radiance over 17 stops (5e-5 .. 16) bracketed at 1/8, 1 and 8, as float photos and
// as 8-bit sRGB photos. Float: exact wherever some exposure is well exposed. 8-bit: each value
// is within half a code of its curve value, so the merged one is within the quantisation of
// the exposure that dominates it.
TEST(BracketMerge, EightBitAndFloatBracketsAgreeWithTruth) {
  const int w = 256, h = 64;
  // Log-uniform across x, a little structure across y; channel c scaled by 1, 0.8, 0.6.
  auto truth = [](int x, int y, int c) {
    return 1e-4 * std::pow(2.0, 17.0 * x / 255) * (1 + 0.2 * std::sin(y * 0.3)) * (1 - 0.2 * c);
  };
  const double stops[] = {-3, 0, 3};
  for (int depth : {CV_32F, CV_8U}) {
    std::vector<DecodedPhoto> photos;
    for (double s : stops) {
      const double e = std::pow(2.0, s);
      photos.push_back(MakePhoto(w, h, true, e, depth,
                                 depth == CV_8U ? Transfer::kSrgb : Transfer::kLinear,
                                 [&](int x, int y, int c) {
                                   const double u = std::min(1.0, e * truth(x, y, c));
                                   return depth == CV_8U ? Srgb(u) : u;
                                 }));
    }
    photos.push_back(Constant(false, 1, 0, w, h));
    const MergedPosition m = MergeFullResolution(photos, 1.0);
    double max_rel = 0, sum2 = 0;
    int count = 0, saturated = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        bool clipped = false;
        for (int c = 0; c < 3; ++c) {
          const double u = std::min(1.0, truth(x, y, c) / 8);  // the shortest exposure
          clipped |= depth == CV_8U ? std::lround(Srgb(u) * 255) >= 255 : u >= 1;
        }
        saturated += clipped;
        if (clipped) {
          ASSERT_EQ(At(m, x, y)[3], 1.f);
          continue;
        }
        for (int c = 0; c < 3; ++c) {
          const double t = truth(x, y, c);
          if (8 * t < 0.01) continue;  // below 1 % of full scale in the longest exposure
          const double rel = std::abs(At(m, x, y)[c] - t) / t;
          max_rel = std::max(max_rel, rel);
          sum2 += rel * rel;
          ++count;
        }
      }
    const double rms = std::sqrt(sum2 / count);
    std::printf("%s brackets: %d values, relative error rms %.2e, max %.2e; %.2f stops\n",
                depth == CV_8U ? "8-bit sRGB" : "float", count, rms, max_rel,
                m.dynamic_range_stops);
    EXPECT_EQ(m.saturated_pixels, saturated);
    EXPECT_GT(saturated, 0);
    if (depth == CV_32F) {
      EXPECT_LE(max_rel, 1e-6);
      // Brightest unclipped just under 8 (1 at exposure 1/8), faintest well exposed just above
      // the near-black floor 4.5e-4 at exposure 8 (the grid steps by 0.07 stops).
      EXPECT_NEAR(m.dynamic_range_stops, std::log2(8 / (4.5e-4 / 8)), 0.1);
    } else {
      // Half a code where the longest exposure is at 1 % of full scale (sRGB code 25, one code
      // = 6e-4 linear) is 3 %, and less above; the merge averages such errors down. (Taking the
      // near-black values of the short exposures at face value would give up to 13 %.)
      EXPECT_LE(max_rel, 0.04);
      EXPECT_LE(rms, 0.01);
    }
  }
}

// Slides of more exposures than the merge's unrolled kernels (up to 4) take the same code with a
// run-time count: five deliberately inconsistent float exposures against the hand-computed
// inverse-variance weights, and six 8-bit sRGB exposures (each with its own quantisation term)
// against the truth, as in EightBitAndFloatBracketsAgreeWithTruth.
TEST(BracketMerge, MoreExposuresThanTheUnrolledKernels) {
  const double e[] = {1, 2, 4, 8, 16}, u[] = {0.1, 0.25, 0.42, 0.8, 0.95};
  std::vector<DecodedPhoto> photos;
  for (int k = 0; k < 5; ++k) photos.push_back(Constant(true, e[k], u[k]));
  photos.push_back(Constant(false, 1, 0.07));
  MergeOptions options;
  options.noise = {1000, 20};
  const double pilot = (0.1 + 0.25 + 0.42 + 0.8 + 0.95) / 31, r2 = 0.02 * 0.02;
  double sw = 0, swx = 0;
  for (int k = 0; k < 5; ++k) {
    const double w = e[k] * e[k] / (e[k] * pilot / 1000 + r2);
    sw += w, swx += w * u[k] / e[k];
  }
  const MergedPosition m = MergeFullResolution(photos, 1.0, 1, options);
  EXPECT_EQ(m.exposures, 5);
  EXPECT_NEAR(At(m, 2, 1)[1], swx / sw - 0.07, 1e-6);

  const int w = 256, h = 8;
  auto truth = [](int x, int, int c) {
    return 2e-3 * std::pow(2.0, 9.0 * x / 255) * (1 - 0.2 * c);
  };
  std::vector<DecodedPhoto> srgb;
  for (int k = 0; k < 6; ++k) {
    const double exposure = std::pow(2.0, k - 3);  // 1/8 .. 4
    srgb.push_back(MakePhoto(
        w, h, true, exposure, CV_8U, Transfer::kSrgb,
        [&](int x, int y, int c) { return Srgb(std::min(1.0, exposure * truth(x, y, c))); }));
  }
  srgb.push_back(Constant(false, 1, 0, w, h));
  const MergedPosition s = MergeFullResolution(srgb, 1.0);
  EXPECT_EQ(s.exposures, 6);
  double max_rel = 0;
  int count = 0;
  for (int x = 0; x < w; ++x)
    for (int c = 0; c < 3; ++c) {
      const double t = truth(x, 0, c);
      if (std::lround(Srgb(std::min(1.0, t / 8)) * 255) >= 255 || 4 * t < 0.01) continue;
      max_rel = std::max(max_rel, std::abs(At(s, x, 3)[c] - t) / t);
      ++count;
    }
  EXPECT_GT(count, 500);
  EXPECT_LE(max_rel, 0.04);
}

// A calibrated response curve (calib/response.json) that happens to be the sRGB curve merges
// exactly as sRGB photos do: the same quantisation noise per code, so the same weights. (The
// merge once took the quantisation term of a response curve at black for every value, which
// overweighted the bright codes of the short exposures.)
TEST(BracketMerge, ResponseCurveWeightsLikeTheCurveItIs) {
  const int w = 128, h = 8;
  auto truth = [](int x, int y, int c) {
    return 1e-3 * std::pow(2.0, 13.0 * x / 127) * (1 + 0.1 * y) * (1 - 0.2 * c);
  };
  auto response = std::make_shared<ResponseCurve>();
  for (auto& channel : response->linear_of_code)
    for (int code = 0; code < 256; ++code) channel[size_t(code)] = float(SrgbInverse(code / 255.0));
  auto corrections = std::make_shared<PhotoCorrections>();
  corrections->response = response;
  MergedPosition merged[2];
  for (int k = 0; k < 2; ++k) {
    std::vector<DecodedPhoto> photos;
    for (double s : {-2.0, 0.0, 2.0}) {
      const double e = std::pow(2.0, s);
      photos.push_back(
          MakePhoto(w, h, true, e, CV_8U, k ? Transfer::kResponse : Transfer::kSrgb,
                    [&](int x, int y, int c) { return Srgb(std::min(1.0, e * truth(x, y, c))); }));
      if (k) photos.back().photo.spec.corrections = corrections;
    }
    photos.push_back(Constant(false, 1, 0, w, h));
    merged[k] = MergeFullResolution(photos, 1.0);
  }
  double max_rel = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 4; ++c) {
        const float a = At(merged[0], x, y)[c], b = At(merged[1], x, y)[c];
        max_rel = std::max(max_rel, std::abs(double(b) - a) / std::max(1e-6, std::abs(double(a))));
      }
  std::printf("response curve vs sRGB: max relative difference %.3g\n", max_rel);
  // 5e-5 (the curve's slope from a 256-entry table, not the formula); the merge that took the
  // quantisation term at black differed by 5.4e-4.
  EXPECT_LE(max_rel, 2e-4) << "the response curve's merge differs from sRGB's";
}

// Recorded exposures off by -3 % (short) and +6 % (long) while the photos were taken at exactly
// 1/4, 1, 4, with noise of 1e-3 rms: the ratios found in the pixels are within 0.2 % of 4, the
// deviation reported is the error put in, and the merge with the estimated ratios is as close
// to the truth as a merge with the true exposures (the noise floor), while the recorded ones
// leave a visible error.
TEST(BracketMerge, ExposureRatiosFromThePixels) {
  const int w = 200, h = 150;
  auto truth = [](int x, int y, int c) {
    return 0.02 + 0.6 * std::exp(-((x - 90.0) * (x - 90.0) + (y - 70.0) * (y - 70.0)) / 3000) *
                      (1 - 0.2 * c);
  };
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0, 1e-3);
  const double true_e[] = {0.25, 1, 4}, recorded_e[] = {0.25 * 0.97, 1, 4 * 1.06};
  std::vector<DecodedPhoto> photos;
  for (int k = 0; k < 3; ++k)
    photos.push_back(
        MakePhoto(w, h, true, recorded_e[k], CV_32F, Transfer::kLinear, [&](int x, int y, int c) {
          return std::min(1.0, true_e[k] * truth(x, y, c) + noise(rng));
        }));
  photos.push_back(Constant(false, 1, 0.01, w, h));
  std::vector<DecodedPhoto> exact = photos;  // the same pixels with the true exposures
  for (int k = 0; k < 3; ++k) exact[k].photo.spec.exposure = exact[k].entry.exposure = true_e[k];
  const std::vector<BracketRatio> ratios = EstimateBracketRatios(photos);
  ASSERT_EQ(ratios.size(), 2u);
  EXPECT_NEAR(ratios[0].estimated, 4, 4 * 0.002);
  EXPECT_NEAR(ratios[1].estimated, 4, 4 * 0.002);
  EXPECT_NEAR(ratios[0].Deviation(), 0.97 - 1, 0.002);
  EXPECT_NEAR(ratios[1].Deviation(), 1 / 1.06 - 1, 0.002);
  EXPECT_GT(ratios[0].samples, 10000);
  std::printf("ratios: %.5f (recorded %.5f), %.5f (recorded %.5f)\n", ratios[0].estimated,
              ratios[0].Recorded(), ratios[1].estimated, ratios[1].Recorded());
  // Relative RMS error of the merged positive slide against the truth.
  auto error = [&](BracketRatios mode, const std::vector<DecodedPhoto>& bracket) {
    MergeOptions o;
    o.bracket_ratios = mode;
    const MergedPosition m = MergeFullResolution(bracket, 1.0, 1, o);
    EXPECT_EQ(m.ratios.size(), 2u);
    double d2 = 0, t2 = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) {
          const double t = truth(x, y, c) - 0.01, d = At(m, x, y)[c] - t;
          d2 += d * d, t2 += t * t;
        }
    return std::sqrt(d2 / t2);
  };
  const double floor = error(BracketRatios::kRecorded, exact);
  const double recorded = error(BracketRatios::kRecorded, photos);
  const double estimated = error(BracketRatios::kEstimated, photos);
  std::printf("merge error: true exposures %.2e, recorded %.2e, estimated ratios %.2e\n", floor,
              recorded, estimated);
  EXPECT_GT(recorded, 5 * floor);
  EXPECT_LE(estimated, 1.05 * floor);
}

TEST(BracketMerge, OptionsChecked) {
  MergeOptions o;
  o.noise.full_well_e = 0;
  EXPECT_THROW(o.Check(), Error);
  o = {};
  o.noise.read_noise_e = -1;
  EXPECT_THROW(o.Check(), Error);
  o = {};
  EXPECT_NO_THROW(o.Check());
}

}  // namespace
}  // namespace lumislab
