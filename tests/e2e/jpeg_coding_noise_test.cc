// The JPEG coding model of the noise floor (tests/e2e/jpeg_coding_model.h) against
// the coding itself: a known picture with known noise is written as JPEG (libjpeg through
// OpenCV, as the synthetic camera writes its photos) at several qualities and decoded by
// lumislab's decoder (lib/photo/jpeg_decode.h); the measured error of the decoded codes against
// the noise-free picture, per pixel and in 4 x 4 means (a texel of the real-camera test), is
// compared with the model's prediction. The model is derived, not fitted: nothing here feeds
// back into it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "lib/photo/jpeg_decode.h"
#include "lib/photo/photo_io.h"
#include "noise_floor.h"
#include "test_util.h"

namespace lumislab {
namespace {

// A smooth picture with the features of a slide photo: gradients, a bright lobe with a steep
// flank, a soft-edged window; codes 10 - 245, colours differing.
ImageF Picture(int w, int h) {
  ImageF codes(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double u = double(x) / w, v = double(y) / h;
      const double lobe = std::exp(-((u - 0.45) * (u - 0.45) + (v - 0.5) * (v - 0.5)) / 0.02);
      const double window = 1 / (1 + std::exp(-(0.3 - std::abs(u - 0.5)) * 60));
      const double ripple = 0.5 + 0.5 * std::sin(2 * M_PI * (3 * u + 2 * v));
      const double base[3] = {0.9, 0.75, 0.55};
      for (int c = 0; c < 3; ++c)
        codes.at(x, y, c) = float(std::clamp(
            10 + 235 * base[c] * window * (0.35 * lobe + 0.35 * (1 - v) + 0.2 * ripple + 0.1), 0.0,
            255.0));
    }
  return codes;
}

struct Measured {
  double pixel[3] = {0, 0, 0}, box[3] = {0, 0, 0};  // mean squared error, code^2
};

// Encodes round(codes + noise) at `quality`, decodes it, and measures the error against codes.
Measured EncodeDecode(const ImageF& codes, double sigma, int quality, const std::string& path) {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0, sigma);
  cv::Mat bgr(codes.height, codes.width, CV_8UC3);
  for (int y = 0; y < codes.height; ++y)
    for (int x = 0; x < codes.width; ++x)
      for (int c = 0; c < 3; ++c)
        bgr.at<cv::Vec3b>(y, x)[2 - c] = cv::saturate_cast<uint8_t>(
            std::lround(codes.at(x, y, c) + (sigma > 0 ? normal(rng) : 0.0)));
  EXPECT_TRUE(cv::imwrite(path, bgr, {cv::IMWRITE_JPEG_QUALITY, quality}));
  const cv::Mat decoded = DecodeJpeg(path).pixels;  // RGB, code x 256
  Measured m;
  ImageF error(codes.width, codes.height, 3);
  for (int y = 0; y < codes.height; ++y)
    for (int x = 0; x < codes.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const double e =
            decoded.at<cv::Vec3w>(y, x)[c] / double(kFractionalCodeOne) - codes.at(x, y, c);
        error.at(x, y, c) = float(e);
        m.pixel[c] += e * e;
      }
  const size_t pixels = size_t(codes.width) * codes.height;
  // 4 x 4 means every 3 pixels (3 and 8 coprime): all alignments with JPEG's 8 x 8 blocks,
  // as texels fall.
  const int n = 4;
  size_t boxes = 0;
  for (int by = 0; by + n <= codes.height; by += 3)
    for (int bx = 0; bx + n <= codes.width; bx += 3, ++boxes)
      for (int c = 0; c < 3; ++c) {
        double sum = 0;
        for (int y = by; y < by + n; ++y)
          for (int x = bx; x < bx + n; ++x) sum += error.at(x, y, c) / (n * n);
        m.box[c] += sum * sum;
      }
  for (int c = 0; c < 3; ++c) m.pixel[c] /= double(pixels), m.box[c] /= double(boxes);
  return m;
}

TEST(JpegCodingNoise, ModelPredictsTheCodingErrorOfAKnownPicture) {
  const int w = 320, h = 240;
  const ImageF codes = Picture(w, h);
  const std::string dir = testing::FreshDir("jpeg_coding_noise");
  // A pixel alone and a 4 x 4 mean, each at every alignment (JpegSpectrumOf averages over the
  // block grid's alignments).
  testing::PixelWeights pixel{{{0, 0}, 1.0}}, box;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) box[{x, y}] = 1.0 / 16;
  const testing::JpegSpectrum pixel_spectrum = testing::JpegSpectrumOf({pixel});
  const testing::JpegSpectrum box_spectrum = testing::JpegSpectrumOf({box});
  EXPECT_NEAR(box_spectrum.luma_sum, 1.0 / 16, 1e-12);
  double sum_k = 0;
  for (double k : box_spectrum.luma) sum_k += k;
  EXPECT_NEAR(sum_k, box_spectrum.luma_sum, 1e-9);  // Parseval
  std::printf(
      "JPEG coding error of a %dx%d picture, mean squared error in code^2 (R, G, B): measured, "
      "predicted (JpegCodingModel), ratio; and the white-noise model without coding\n",
      w, h);
  for (const double sigma : {0.0, 1.0, 2.5})
    for (const int quality : {50, 75, 90, 95, 100}) {
      const Measured m = EncodeDecode(codes, sigma, quality, dir + "/p.jpg");
      // The JPEG's input: the noise and the rounding to 8-bit codes.
      const ImageF variance(w, h, 3, float(sigma * sigma + 1.0 / 12));
      const testing::JpegCodingModel model(codes, variance, quality);
      double pixel_pred[3] = {0, 0, 0}, box_pred[3] = {0, 0, 0};
      int count = 0;
      for (int y = 0; y + 4 <= h; y += 3)
        for (int x = 0; x + 4 <= w; x += 3, ++count) {
          const auto p = model.WhiteEquivalentVariance(x, y, pixel_spectrum);
          const auto b = model.WhiteEquivalentVariance(x, y, box_spectrum);
          for (int c = 0; c < 3; ++c)
            pixel_pred[c] += p[c] * pixel_spectrum.luma_sum,
                box_pred[c] += b[c] * box_spectrum.luma_sum;
        }
      for (int c = 0; c < 3; ++c) pixel_pred[c] /= count, box_pred[c] /= count;
      std::printf("  sigma %.1f q %3d  pixel:", sigma, quality);
      for (int c = 0; c < 3; ++c)
        std::printf(" %.3f/%.3f=%.2f", m.pixel[c], pixel_pred[c], m.pixel[c] / pixel_pred[c]);
      std::printf("  4x4 mean:");
      for (int c = 0; c < 3; ++c)
        std::printf(" %.4f/%.4f=%.2f", m.box[c], box_pred[c], m.box[c] / box_pred[c]);
      std::printf("  (white %.4f)\n", (sigma * sigma + 1.0 / 12) / 16);
      // With noise (the real-camera test's photos carry 0.5 - 1.5 codes), within 25 % (measured
      // 0.78 - 1.10; quality 100 lowest: the decoder's rounding after the inverse DCT puts back
      // most of the whole codes that quality 100 nearly keeps, which the model counts as an
      // independent rounding). Without noise the roundings are not dithered and their errors
      // are structured: within a factor 2 (0.55 - 1.31).
      const double tolerance = sigma > 0 ? 0.25 : 0.5;
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(m.box[c] / box_pred[c], 1, tolerance) << "sigma " << sigma << " q " << quality;
        EXPECT_NEAR(m.pixel[c] / pixel_pred[c], 1, tolerance)
            << "sigma " << sigma << " q " << quality;
        // The white-noise model without coding (the floor before) is further off at quality
        // <= 95 unless the noise is strong (2.5 codes: the coding then removes about as much
        // noise as it adds).
        if (quality <= 95 && sigma <= 1) {
          const double white = (sigma * sigma + 1.0 / 12) / 16;
          EXPECT_LT(std::abs(std::log(m.box[c] / box_pred[c])),
                    std::abs(std::log(m.box[c] / white)))
              << "sigma " << sigma << " q " << quality;
        }
      }
    }
}

}  // namespace
}  // namespace lumislab
