// What JPEG coding leaves in a weighted mean of a photo's codes (a texel's value): the model of
// the noise floor's JPEG term (noise_floor.h), checked against real coding in
// jpeg_coding_noise_test.cc.
#pragma once

#include <array>
#include <map>
#include <utility>
#include <vector>

#include "core/image.h"

namespace lumislab::testing {

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

}  // namespace lumislab::testing
