// The noise floor predicted for a slab reconstructed from noisy photos: what the sensor's noise
// (and the rounding of its codes, dithered by that noise) leaves in the slab when every other
// step is exact. e2e_test (one 16-bit exposure per slide) and real_camera_test (brackets, a
// camera curve or a Bayer RAW, a flat field and a scale reading, each with their own noise)
// compare their slab error with it (issue 8: within 1.5x of the floor).
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "core/image.h"

namespace lumislab::testing {

// The camera's noise, in sensor values (the synthetic capture's normalised value before its
// curve or its RAW codes; 1 = full well).
struct SensorNoiseModel {
  double full_well_e = 20000;  // electrons at 1 (sensor_noise's full_well_e)
  double read_noise_e = 3;     // rms electrons
  // One code of the stored photo, in sensor values, at sensor value s: the rounding adds
  // q(s)^2 / 12 (the noise dithers it). Through a camera curve C: (1 / 255) / C'(s).
  std::function<double(double)> code_step = [](double) { return 1.0 / 65535; };
  // Sensor value at or above which the photo's value is clipped (left out of the merge).
  double saturation = std::numeric_limits<double>::infinity();
  // The photos are Bayer RGGB mosaics (a DNG), demosaiced by lib/photo: a pixel keeps its own
  // sample and takes the mean of the channel's samples in its 3 x 3 for the others. False: every
  // pixel samples every channel.
  bool bayer_rggb = false;
  // A JPEG camera: the quality its photos were written at (libjpeg through OpenCV: 4:2:0 chroma)
  // and its curve, code_of(s) = 255 C(s) before the rounding. 0: not a JPEG; the coding is then
  // only the rounding in code_step. With a quality, JpegCodingModel predicts what the coding
  // leaves instead (the photos' noise as it passes the quantiser, the roundings and chroma).
  int jpeg_quality = 0;
  std::function<double(double)> code_of;
  // Variance of one sensor value s: shot noise, read noise, the code's rounding.
  double Variance(double s) const;
};

// A weighted mean of photo pixels: (x, y) -> weight.
using PixelWeights = std::map<std::pair<int, int>, double>;

// Where a weighted mean of photo pixels (a texel) looks in JPEG's coefficients: for each of the
// 64 DCT coefficients (u + 8 v) of the luma blocks, the sum over the blocks of the squared
// projection of the weights on the coefficient's basis image <w, B_uv>^2; for the chroma
// blocks (4:2:0) the same for the weights carried to the chroma plane by the decoder's
// upsampling (w_C = Up^T w, libjpeg's triangle filter). Averaged over the given weight patterns
// and the block grid's 8 x 8 (chroma: 16 x 16) alignments. luma sums to sum(w^2) (Parseval):
// the variance white noise of variance 1 leaves in the mean.
// luma_coherent, chroma_coherent: the square of the sum over the blocks of <w, B_uv>, for an
// error the same in neighbouring blocks (a quantiser's bias on a smooth picture, whose
// coefficients change little from block to block).
struct JpegSpectrum {
  std::array<double, 64> luma{}, chroma{}, luma_coherent{}, chroma_coherent{};
  double luma_sum = 0, chroma_sum = 0;  // sum(w^2), sum(w_C^2)
};
JpegSpectrum JpegSpectrumOf(const std::vector<PixelWeights>& patterns);

// What JPEG coding at `quality` (libjpeg's encoder with its default tables scaled as
// jpeg_set_quality does, 4:2:0 chroma by box averaging; libjpeg's inverse DCT and triangle
// upsampling, then lumislab's floating-point YCbCr -> RGB) leaves in a weighted mean of a
// photo's codes, for a photo whose expected codes are `codes` (RGB, 0 - 255, not rounded) and
// whose codes carry independent noise of variance `variance` (code^2, per pixel and channel,
// the rounding to 8-bit RGB included). Per 8 x 8 block and coefficient, with s the noise-free
// coefficient, sigma^2 the noise's variance in it (the RGB noise through the YCbCr matrix, the
// block's mean; chroma: box-averaged) plus the encoder's rounding of Y, Cb, Cr (and of the
// chroma average) and q the quantisation step:
//   E = E[(Q(s + n) - s)^2], beta = E[(Q(s + n) - s) n] / sigma^2
// (Gaussian n), and the bias b = E[Q(s + n) - s]. E holds both the error quantisation adds to
// strong coefficients and the noise it removes from weak ones (beta -> 0). The error splits
// into the bias (the same in the neighbouring blocks, whose coefficients on a smooth picture
// are nearly the same: weighted by the coherent spectrum), beta x the noise (correlated between
// Y, Cb and Cr as the RGB noise is) and a remainder D = E - b^2 - beta^2 sigma_rgb^2 taken as
// independent between blocks, coefficients and components. Back in R, G, B (R = Y + 1.402 Cr, ...),
// weighted by the texel's spectrum: for channel k
//   var_k = sum_uv K_uv sum_j sigma_j^2 (sum_c M_kc beta_c,uv A_cj)^2         (the noise)
//         + sum_c M_kc^2 (sum_uv (K^c_uv D_c,uv + coherent K^c_uv b_c,uv^2)
//                          + rounding after the inverse DCT and upsampling)
// with A the RGB -> YCbCr matrix, M its inverse, chroma's beta at the same spatial frequency
// (coefficient 2u, 2v; none above the chroma plane's Nyquist), and in D also the deterministic
// error of 4:2:0 on the noise-free chroma (Up(Down(C)) - C, its coefficients' squares in the
// luma blocks, weighted by K). Without coding (q -> 0, no
// roundings, no subsampling) this is sum(w^2) sigma_k^2, the white-noise model.
class JpegCodingModel {
 public:
  JpegCodingModel(const ImageF& codes, const ImageF& variance, int quality);
  // The variance var_k above (code^2, per RGB channel) of the mean with spectrum `spectrum`
  // around pixel (x, y), divided by spectrum.luma_sum: the variance of independent per-pixel
  // noise that would leave the same in that mean.
  std::array<double, 3> WhiteEquivalentVariance(int x, int y, const JpegSpectrum& spectrum) const;

 private:
  struct Block {
    std::array<float, 64> beta{}, d{}, bias2{};  // per coefficient
  };
  int luma_w_ = 0, chroma_w_ = 0;              // blocks per row
  std::vector<Block> y_, cb_, cr_;             // luma blocks; chroma blocks (16 x 16 pixels)
  std::vector<std::array<float, 3>> rgb_var_;  // per luma block: the mean RGB noise variance
  // Per luma block, Cb and Cr: the squared coefficients of what 4:2:0 does to the noise-free
  // chroma (the box mean upsampled again, less the chroma itself).
  std::vector<std::array<float, 64>> subsampled_[2];
};

// The calibrated chain's own noise sources (all optional).
struct ChainNoiseModel {
  // truth/flat.exr: the per-pixel gain (vignetting x screen gain) the flat divides out; the
  // merged variance is divided by its square. Empty: gain 1.
  std::string gain_exr;
  // truth/dark.exr: the dark signal (black + current x exposure) under the flat frames' and the
  // reference's values. Empty: none.
  std::string dark_exr;
  // The flat frames: their count (0: no flat), level at exposure 1 and exposure. Their mean per
  // pixel divides every photo, so its relative noise multiplies the slab texel's value.
  int flat_frames = 0;
  double flat_level = 0.5, flat_exposure = 1;
  // The scale's reading: position, lab point, radius of calibrate scale's quadratic fit; its
  // relative noise scales every texel alike. reference_radius_px 0: no scale step.
  int reference_i = 0, reference_j = 0;
  Eigen::Vector2d reference_mm = Eigen::Vector2d::Zero();
  int reference_radius_px = 0;
};

struct PositionNoiseFloor {
  int i = 0, j = 0;
  double relative = 0;  // predicted relative L2 of the position
};
struct NoiseFloor {
  double overall = 0;         // predicted relative L2 over the lit texels of all positions
  double scale_relative = 0;  // of which the scale reading's part (relative, every texel)
  std::vector<PositionNoiseFloor> positions;
};

// Predicts the relative L2 error (as core/slab_compare.h measures it: lit texels, >= 1 % of the
// position's peak, inside the slab's mask) that noise leaves in `slab_dir`. `clean` is the
// same capture without noise, its photos float EXR sensor values (the expected values of the
// noisy ones); `screen_json` maps texels to photo pixels; `truth_dir` holds the exact slab.
// Per photo pixel and channel, each slide's brackets are merged with inverse-variance weights
// (reconstruct's merge): var = 1 / sum_k (t_k^2 / var(s_k)) over the unclipped exposures k,
// divided by the gain^2 the flat divides out, times (filter peak x radiometric scale)^2. A
// texel's value is a weighted mean of the sensor's samples: the demosaic (Bayer), the mean of
// F x F pixels (F = round(side / 3), reconstruct's downsample) and K x K bilinear samples over
// the texel (reconstruct/rectify.cc); the sum of its squared weights is computed for a square
// texel of the area the screen calibration gives (N = texel area / pixel area, side sqrt(N)),
// averaged over 16 sub-pixel offsets and the mosaic's phases. The deconvolution with the
// stencil [b, a, b] (a = 5/6, b = 1/12) multiplies white noise's variance by
// (a / (a^2 - 4 b^2)^1.5)^2 in 2D. The flat's noise adds truth^2 x its relative variance
// through the same averaging and deconvolution, the scale reading's truth^2 x its relative
// variance.
NoiseFloor PredictNoiseFloor(const std::string& slab_dir, const std::string& clean,
                             const std::string& screen_json, const std::string& truth_dir,
                             const SensorNoiseModel& sensor, const ChainNoiseModel& chain = {});

}  // namespace lumislab::testing
