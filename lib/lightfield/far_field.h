// The far-field intensity of a slab (docs/design.md §4.9), the input of the polar plot:
//   I(w) = ∫_S L(u, v, w) cos(theta) du dv,
// with the exact model's L~ = (1/h^2) Σ_ij (R^2/cos^2 theta) Φ_ij(u, v) E_ij(s, t) (§3.3). Towards
// a fixed direction w every (u, v) looks at (s, t) = (u, v) + d (w_x, w_y) / w_z, and R = d / cos
// theta is the same for all, so
//   I(w) = (d^2 / cos^3 theta) Σ_ij (1/h^2) ∫ Φ_ij(u, v) E_ij((u, v) + d w_xy / w_z) du dv,
// the inner integral by BellQuadrature's N x N rule (N = 1: E_ij at c_ij + d w_xy / w_z).
// W/sr per RGB channel (cd for a slab in lux). Minimal on purpose: lumislab-export's photometry
// (IES / EULUMDAT) is the place for the full far-field table; this is what the polar plot needs.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/image.h"
#include "core/slab.h"

namespace lumislab {

// Unit direction of photometry type C (docs/design.md §5.17): gamma from +z (the luminaire's
// axis), C = 0 towards +x, C = 90 towards +y; degrees.
Eigen::Vector3d DirectionFromCGamma(double c_deg, double gamma_deg);

// True when every position's samples towards w fall inside the slab window, i.e. the slab saw all
// of its light in that direction (elsewhere I(w) below falls short). False for w_z <= 0.
bool SlabSeesDirection(const SlabInfo& info, const Eigen::Vector3d& w);

// I(w) from E_ij of each position (linear index j * nu + i, empty images: absent positions, no
// light), W/sr; zero for w_z <= 0. samples: N per axis (1 .. 64).
Eigen::Vector3d SlabFarFieldIntensity(const SlabInfo& info, const std::vector<ImageF>& irradiance,
                                      const Eigen::Vector3d& w, int samples = 1);

}  // namespace lumislab
