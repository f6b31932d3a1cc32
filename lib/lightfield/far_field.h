// What a slab says about the luminaire far away and as rays (docs/formats.md §17): the
// far-field intensity I(w) = integral over S of L(x, w) cos(theta) dA, from the exact model of
// docs/method.md §3.3, and rays importance-sampled from the slab's radiance (TM-25 export).
// GL-free.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/slab.h"
#include "core/slab_light.h"  // ReadSlabPositions

namespace lumislab {

struct FarFieldOptions {
  int samples = 4;  // N x N bell quadrature per position
  // RGB -> the one channel; none: the slab's (SlabInfo::channel_weights, luminance: cd for lux
  // slabs).
  std::optional<Eigen::Vector3d> channel_weights;
  int threads = 1;
};

// I on a C / gamma grid (degrees, type C: gamma = 0 along +z, C = 0 towards +x, C = 90 towards
// -y, TypeCDirection; docs/formats.md §17).
struct FarField {
  std::vector<double> c_deg, gamma_deg;
  std::vector<double> values;  // values[ic * gamma_deg.size() + ig]: W/sr (cd for lux slabs)
  std::vector<uint8_t> seen;   // 1: every sample of every position saw the direction
  int unseen = 0;              // directions not seen (value 0), those behind S included
  int behind = 0;              // of which gamma >= 90: behind S, never seen
};

// I(w) = d^2 / (cos^3 theta 10^6) sum_ij sum_k (w_k / h^2) E_ij(q_k + d tan(theta) (cos C,
// -sin C)) (W/sr), w = TypeCDirection(C, theta): the exact model's radiance (R^2 / cos^2 theta)
// E_ij / h^2 with R = d / cos theta for every point q of S, times cos theta, integrated over S with
// the bell quadrature of each position (BellQuadrature, N x N points q_k of weight w_k). A
// direction is seen when every point lands inside the window on texels whose bilinear neighbours
// are all seen (mask 1); otherwise, and for gamma >= 90 (light leaves S towards +z only), its value
// is 0. Positions with an empty image are left out (the caller decides whether a partial slab may
// be used).
FarField ComputeFarField(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                         const std::vector<double>& c_deg, const std::vector<double>& gamma_deg,
                         const FarFieldOptions& options);

// The same I(w) at arbitrary unit directions of the slab's frame (normalised here), with each
// direction's seen flag: ComputeFarField is this on its C / gamma grid. The registration and the
// merged far field of a luminaire folder (core/luminaire_set.h) look slabs up with it.
struct FarFieldAt {
  std::vector<double> values;  // W/sr (cd for lux slabs), 0 where unseen
  std::vector<uint8_t> seen;
};
FarFieldAt ComputeFarFieldAt(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                             const std::vector<Eigen::Vector3d>& directions,
                             const FarFieldOptions& options);

struct SlabRay {
  Eigen::Vector3d origin_mm;  // on S (z = 0), luminaire frame
  Eigen::Vector3d direction;  // unit, z > 0
};
struct SlabRays {
  std::vector<SlabRay> rays;
  double flux_per_ray = 0;  // W (lm for lux slabs); the same for every ray
  double total_flux = 0;    // the slab's flux: sum over positions and seen texels of E dA
  // What making the light field non-negative moved (docs/formats.md §17), W and mm:
  double moved_flux = 0;           // the negative part within texels, cancelled over (u, v)
  double moved_mean_mm = 0;        // mean distance on S from the mass taken to the nearest lobe
  double moved_max_mm = 0;         // the largest such distance
  double uncentred_flux = 0;       // of moved_flux, where the profile's centroid could not be kept
  double texel_moved_flux = 0;     // texels of negative net flux, cancelled against neighbours
  double texel_moved_mean_mm = 0;  // their mean distance on M
};

// N rays distributed as the slab's light field (the exact model, docs/method.md §3.3): through
// texel dA of M, basis function ij sends Phi_ij(u, v) E_ij(s, t) / h^2 du dv dA (W), so the flux
// density over (u, v, s, t) is sum_ij Phi_ij E_ij / h^2. E_ij is signed (the dual filter has
// negative lobes) and so is the sum; a ray file carries no negative flux, so the field is first
// made non-negative keeping what planes at any distance see to first order: each texel's profile
// over (u, v), on cells of h / 4, has its negative cells cancelled against positive cells within
// h of them, keeping the texel's flux (the irradiance at d, exactly) and its (u, v) centroid
// (the centre of its light on every plane); texels of negative net flux are first cancelled
// against their nearest neighbours. Then each ray draws a texel by its flux, a cell of its
// profile by its flux, (u, v) uniformly in the cell and (s, t) uniformly in the texel. Every
// ray carries total_flux / N. Deterministic for a seed, whatever the thread count (texels run
// on `threads` threads, each with its own random stream). The one channel is the slab's
// (SlabInfo::channel_weights: luminance, lm for lux slabs).
SlabRays SampleSlabRays(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                        int64_t count, uint64_t seed, int threads = 1);

}  // namespace lumislab
