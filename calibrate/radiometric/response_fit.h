// The least-squares fit behind `lumislab-calibrate response` (docs/formats.md §14): the log of
// a camera's inverse response, g(z) = ln(linear value of code z), from pixels seen in several
// frames of known exposure. Debevec and Malik's model g(z_ij) = ln E_i + ln t_j, with four
// changes that make it hold up on noisy JPEG frames:
//   - codes are continuous (a sample's code is a local mean, not rounded): g is piecewise
//     linear between the 256 integer codes, so a mean code carries its fraction;
//   - each sample's ln E_i is eliminated in closed form, so the normal equations stay 256 x 256
//     whatever the number of samples (tens of thousands, where OpenCV's dense SVD grows with
//     them);
//   - the weights follow the noise: a code's error (JPEG's and the sensor's, about constant in
//     code units) becomes g'(z) times it in ln E, so later passes weight by 1 / g'(z)^2;
//   - the smoothness term is on g's second derivative in ln(z + 1), which a power law (a gamma
//     curve) does not pay, rather than in z.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace lumislab {

// Observations: `codes[i * frames + j]` is sample i's code in frame j, in [0, 255], or a
// negative number where the sample is not usable in that frame (clipped, black). `log_exposure`
// has `frames` entries. `smoothness` weighs the squared second difference of g at each code
// (in ln(z + 1), scaled to code 128's spacing) against one code's share of the data (1: alike).
// Returns g at codes 0 .. 255 with g(255) = 0 (codes beyond the data are extrapolated linearly by
// the smoothness term); `used` (optional) gets the number of samples seen in at least two frames.
std::array<double, 256> FitLogInverseResponse(const std::vector<float>& codes, int frames,
                                              const std::vector<double>& log_exposure,
                                              double smoothness, size_t* used = nullptr);

// How far the observations sit from a fitted g, by code: the weighted mean residual
// g(z_ij) - ln E_i - ln t_j (ln E_i as in the fit) of the observations whose code falls in each
// of 256 / bin_width bins of `bin_width` codes, and their number (0: the mean is 0). A set of
// observations that the curve describes gives means near 0 in every bin; one channel's data
// under a curve fitted to all three shows there whether that channel's response differs.
struct ResidualBins {
  std::vector<double> mean;
  std::vector<size_t> count;
};
ResidualBins ResidualsByCode(const std::vector<float>& codes, int frames,
                             const std::vector<double>& log_exposure,
                             const std::array<double, 256>& g, int bin_width);

}  // namespace lumislab
