// The far-field intensity of a slab (docs/design.md §4.9), the input of the polar plot:
//   I(w) = ∫_S L(u, v, w) cos(theta) du dv,
// with the exact model's L~ = (1/h^2) Σ_ij (R^2/cos^2 theta) Φ_ij(u, v) E_ij(s, t) (§3.3). Towards
// a fixed direction w every (u, v) looks at (s, t) = (u, v) + d (w_x, w_y) / w_z, and R = d / cos
// theta is the same for all, so
//   I(w) = (d^2 / cos^3 theta) Σ_ij (1/h^2) ∫ Φ_ij(u, v) E_ij((u, v) + d w_xy / w_z) du dv,
// the inner integral by BellQuadrature's N x N rule.
// **Minimal stand-in**: the photometry work (lumislab-export ies/ldt, issue 11) builds the full
// far field under the same names and interface; this file keeps only what the polar plot needs,
// so that the two merge into one implementation (theirs).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/slab.h"

namespace lumislab {

// Rec. 709 luminance: the one channel the far field carries (W/sr for W/m^2 slabs, cd for lux).
inline Eigen::Vector3d LuminanceWeights() { return {0.2126, 0.7152, 0.0722}; }

// Every position the slab lists (E_ij and mask) by linear index j * nu + i, empty for the
// others, read on `threads` threads; a damaged file is exit 2 (ReadSlabPosition).
std::vector<SlabPosition> ReadSlabPositions(const std::string& slab_dir, const SlabInfo& info,
                                            int threads);

struct FarFieldOptions {
  int samples = 4;  // N x N bell quadrature per position
  Eigen::Vector3d channel_weights = LuminanceWeights();
  int threads = 1;
};

// I on a C / gamma grid (degrees, photometry type C: gamma = 0 along +z, C = 0 towards +x, C = 90
// towards +y; docs/design.md §5.17).
struct FarField {
  std::vector<double> c_deg, gamma_deg;
  std::vector<double> values;  // values[ic * gamma_deg.size() + ig], W/sr (cd for lux slabs)
  std::vector<uint8_t> seen;   // 1: every sample of every position landed on seen texels
  int unseen = 0;              // directions not seen (value 0), those behind S included
  int behind = 0;              // of which gamma >= 90: behind S, never seen
};

// The formula above for each (C, gamma); a direction is seen when every sample lands inside the
// window on texels whose bilinear neighbours are all seen (mask 1), else its value is 0 (the slab
// lacks part of its light). Positions with an empty image are left out.
FarField ComputeFarField(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                         const std::vector<double>& c_deg, const std::vector<double>& gamma_deg,
                         const FarFieldOptions& options);

}  // namespace lumislab
