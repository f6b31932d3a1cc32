// One light field of several slabs (docs/method.md §4.12, "The merged light field"): a luminaire
// measured from several orientations (core/luminaire_set.h), each orientation's complete slab
// with its pose, looked at as one luminaire in its own frame. The far field of every orientation
// is read at the directions it sees and blended where several see one; the rays of every slab
// are turned into the luminaire frame and thinned by the same blend. GL-free. (The preview blends
// with the taper alone, its shader's copy of ConeTaper pinned by tests/preview: it reads no seen
// masks.)
//
// Frames: R_k (capture_from_luminaire) maps luminaire-frame directions into orientation k's
// capture frame, w_capture = R_k w; points x_capture = R_k x + centre_k (docs/formats.md §19).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/luminaire_set.h"
#include "core/slab.h"
#include "lib/lightfield/far_field.h"

namespace lumislab {

// One orientation's slab in the luminaire frame: the slab (complete: the caller checks), its
// pose and the cone of directions it sees (ConeOfDataset).
struct PosedSlab {
  std::string name;  // the orientation's name (luminaire.json)
  std::string slab_dir;
  SlabInfo info;
  std::vector<SlabPosition> positions;
  Eigen::Matrix3d capture_from_luminaire = Eigen::Matrix3d::Identity();  // R_k
  Eigen::Vector3d centre_mm = Eigen::Vector3d::Zero();  // luminaire origin, capture frame
  OrientationCone cone;
};

// The blend weights of the orientations at luminaire-frame direction w (unit): orientation k
// gets t_k / sum_j t_j, t_k = ConeTaper(cone_k, R_k w, taper_deg) x seen_k, where seen_k says
// whether orientation k's far field saw R_k w (its mask). Where no orientation's taper is above 0
// but some saw w (the cone is drawn with a margin the seen mask need not keep), the orientations
// that saw it share it equally; where none saw it every weight is 0. The weights sum to 1 or 0.
// The one implementation of the blend with seen masks: the merged far field and the merged rays
// call it.
std::vector<double> BlendWeights(const std::vector<OrientationCone>& cones,
                                 const std::vector<Eigen::Matrix3d>& capture_from_luminaire,
                                 const std::vector<uint8_t>& seen, const Eigen::Vector3d& w,
                                 double taper_deg = kDefaultTaperDeg);

// The slabs' common unit (SlabInfo::units): every orientation carries its own radiometric scale
// (its calib/scale.json), so the merged intensity is in one unit only when every slab's is the
// same: "lux" (cd, lm) or "W/m^2" (W/sr, W) throughout. BadInput naming the slab.json of the
// first slab unlike the first otherwise. "relative" slabs (no scale) are refused when there are
// several: each one's level is its own capture's exposure, so their sum would not be one
// luminaire's light (one relative slab alone is what it is, as export states).
std::string CommonUnits(const std::vector<PosedSlab>& slabs);

// The merged far field on a C / gamma grid of the luminaire frame (gamma 0-180: the full sphere).
struct MergedFarField {
  // values: sum_k weight_k I_k(R_k w); seen: some orientation saw w; unseen: the others (value
  // 0); behind: 0 (no direction is behind every orientation's S by construction).
  FarField ff;
  std::vector<uint8_t> seen_by;  // per direction: how many orientations have weight > 0
  // Per orientation: the flux it contributes (sum over the grid's cells of weight I dOmega, the
  // zonal sum of IntensityDistribution::TotalFlux), in the slabs' unit.
  std::vector<double> contribution;
  // The radiometric scale across orientations, where two both weigh directions (weight > 0 in
  // both): the ratio of their fluxes there, sum I_b dOmega / sum I_a dOmega (1 when the two
  // slabs' scales agree), over how many grid directions; only pairs that share a direction.
  struct PairScale {
    int a = 0, b = 0;
    int directions = 0;
    double ratio = 1;
  };
  std::vector<PairScale> pair_scales;
};

// Each grid direction w (TypeCDirection, luminaire frame) looked up in every orientation k at
// R_k w with ComputeFarFieldAt (its capture frame; the translation centre_k does not change a
// far field) and blended with BlendWeights. `options` as ComputeFarField's (one channel: each
// slab's channel_weights unless given).
MergedFarField ComputeMergedFarField(const std::vector<PosedSlab>& slabs,
                                     const std::vector<double>& c_deg,
                                     const std::vector<double>& gamma_deg,
                                     const FarFieldOptions& options);

// Rays of several slabs as one ray set in the luminaire frame. Slab k draws n_k rays
// (SampleSlabRays, seed + k), each turned into the luminaire frame (origin R_k^T (x - centre_k),
// direction R_k^T w) and kept with probability weight_k(w) (BlendWeights with each orientation's
// seen mask read on a 1 degree grid, nearest direction). Flux bookkeeping: a kept ray carries
// Phi_k / n_k, the same for every slab because n_k = N Phi_k / sum_j q_j Phi_j, where q_j is
// the kept share of slab j's flux measured on a first small draw; so the union carries
// sum_k q_k Phi_k = the blended flux (each direction's flux once), with about N rays, and
// `total_flux` is the kept rays' sum (a Monte Carlo estimate of the merged flux: relative
// error about 1 / sqrt(N) of the overlap's share).
struct MergedRays {
  // Luminaire frame; total_flux the kept rays' sum, flux_per_ray its mean (each ray's own in
  // ray_flux: slab k's Phi_k / n_k, equal across slabs up to the first estimate's error).
  SlabRays rays;
  std::vector<float> ray_flux;     // per ray (W; lm for lux slabs)
  std::vector<int64_t> drawn;      // per slab: n_k
  std::vector<int64_t> kept;       // per slab: rays kept
  std::vector<double> slab_flux;   // per slab: Phi_k (its whole slab, SlabRays::total_flux)
  std::vector<double> kept_share;  // per slab: q_k from the first draw
};
MergedRays SampleMergedRays(const std::vector<PosedSlab>& slabs, int64_t count, uint64_t seed,
                            int threads = 1);

}  // namespace lumislab
