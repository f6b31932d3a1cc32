// One photo in the bracket merge (reconstruct/photo_merge.h): the terms of its noise model
// (NoiseModel), its near-black floor, the exposure the merge divides by, and the readers that
// give its values a row at a time. Shared by the merge (photo_merge.cc) and the bracket-ratio
// estimate (bracket_ratios.cc).
#pragma once

#include <array>
#include <cstddef>
#include <limits>
#include <memory>
#include <vector>

#include "lib/photo/dataset_photo.h"
#include "lib/photo/photo_io.h"
#include "reconstruct/merge_kernels.h"
#include "reconstruct/photo_merge.h"

namespace lumislab::merge {

// A clipped value in the merge's rows: NaN, which fails every comparison, so that a clipped value
// is neither well exposed nor near-black, and x == x tells whether a value is unclipped.
constexpr float kClipped = std::numeric_limits<float>::quiet_NaN();

// The stored codes of `photo` map to linear values as code * Gain() - Offset(), with nothing
// else applied per pixel (the condition under which Photo's Gain/Offset/SaturationCode may stand
// in for LinearReader): linear transfer, unity white balance, 16-bit or float RGB. (A JPEG's
// fractional codes go through the code tables, which share the reader's clipping rule.)
bool CodesAreLinear(const Photo& photo);

// One photo in the merge, with what the noise model and the near-black test need. u is the
// recorded value above black in units of the white level (the reader's value times the
// recorded exposure), the same whatever exposure the merge assumes.
// The lowest 8-bit code whose value a fitted response curve gives to within noise
// (calibrate response's consistency report starts there too, calibrate/radiometric).
constexpr int kTrustedCode = 32;

struct Exposure {
  LinearReader reader;
  // CodesAreLinear: u = code * u_gain - u_offset, clipped at code >= saturation_code (or NaN),
  // read a row at a time instead of through the reader.
  const Photo* source = nullptr;
  bool linear_codes = false;
  float u_gain = 0, u_offset = 0, saturation_code = 0;
  // 8-bit photos without per-pixel corrections (dark map, hot pixels, flat field): u per code
  // and channel, [c * 256 + code] for c = R, G, B, NaN where clipped, read through the reader
  // from a 256-pixel photo holding every code, so the table is the decoder's own linearisation.
  // Valid because LinearReader maps a code the same way at every pixel. Empty for other photos.
  std::vector<float> code_u;
  // A JPEG's fractional codes: code_u of R, G, B read between codes (ReadBetweenCodes) at every
  // fractional code (FractionalCodeTable), for ReadFractionalCodes; equal tables are one, shared
  // by the channels and exposures that have them (MakeExposures). Null for other photos.
  std::array<std::shared_ptr<const std::vector<float>>, 3> fractional_u;
  int slide = 0;        // 0: p, 1: n
  float recorded = 1;   // exposure in dataset.json
  float effective = 1;  // the exposure the merge divides by (recorded, or from the ratios)
  // Well exposed: not clipped, u >= floor_u and u > 0; unclipped below that: near-black.
  float floor_u = 0;
  // u of 8-bit code kTrustedCode per channel (0 for other photos): below it a response curve
  // fitted to the photos absorbs the camera's dark offset (docs/formats.md §14) and reads a few
  // % low, too little for the merge's weights, too much for the bracket ratios' estimate.
  float trusted_u[3] = {0, 0, 0};
  float read_var = 0;   // (read noise / full well)^2, u^2
  float code_step = 0;  // one code in u units at curve slope 1 (0: float photo)
  Transfer transfer = Transfer::kLinear;
  float black = 0, range = 1;                  // curve value = u * range + black
  std::array<float, kQuantTable> quant_var{};  // q^2 / 12 at curve value k / (kQuantTable - 1)
  // The table varies (sRGB, or a calibrated response curve); otherwise entry 0 holds for all.
  bool curved = false;

  Exposure(const DecodedPhoto& p, const NoiseModel& noise, double near_black_codes);
  // Variance of u at an expected value u (NoiseModel); the quantisation term from a table over
  // the curve value (1/1024 steps: the weights need not be exact, and a pow per value and
  // exposure would cost more than decoding the photo).
  float Variance(float u, float inv_full_well) const {
    if (!curved) return u * inv_full_well + read_var + quant_var[0];
    return u * inv_full_well + read_var + quant_var[QuantTableEntry(u * range + black)];
  }
};

std::vector<Exposure> MakeExposures(const std::vector<DecodedPhoto>& photos,
                                    const MergeOptions& options);

// Indices of one slide's photos, shortest recorded exposure first (ties in listing order).
std::vector<size_t> SlideOrder(const std::vector<Exposure>& exposures, int slide);

// `pixels` pixels of row y from x0 into uk as the recorded value above black u (R, G, B; NaN
// where clipped), through the reader that suits the photo: its linear codes, its per-code
// tables, or pixel by pixel through its LinearReader.
void ReadRow(const Exposure& e, int y, int x0, int pixels, float* __restrict uk);

}  // namespace lumislab::merge
