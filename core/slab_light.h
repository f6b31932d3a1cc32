// How much light a slab or its far field holds, and the check every stage that reads one makes of
// it ("slab.total_light"; the far field's in lib/lightfield/far_field_light.h; docs/verifies.md,
// "Slabs and exports").
//
// E_ij is signed (the dual filter has negative lobes, docs/method.md §3), so a legitimate slab
// has some negative light: its texels' net flux sum_ij E_ij dA dips below 0 where the dual rings.
// A slab whose total is negative or not a number is no measurement of a luminaire (the two slides
// swapped, E = N - P).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/checks.h"
#include "core/slab.h"

namespace lumislab {

struct SlabLight {
  int positions = 0;    // positions with an image, summed
  double total = 0;     // sum over texels of the net flux sum_ij E_ij dA (W; lm for lux slabs)
  double positive = 0;  // sum over texels of the positive net fluxes
  double negative = 0;  // sum over texels of |the negative net fluxes|
  // The same over positions: each position's total sum_texels E_ij dA (a legitimate position's
  // is positive where it sees light; a position whose slides were swapped is negative).
  double position_positive = 0, position_negative = 0;
  int negative_positions = 0;
  std::pair<int, int> most_negative{-1, -1};  // the position of the most negative total
  double PositionNegativeShare() const {
    return position_negative / (position_positive + position_negative);
  }
  // negative / (positive + negative): 0 for a field with no negative texel, 1 when all is
  // negative; NaN when the slab holds no light at all.
  double NegativeShare() const { return negative / (positive + negative); }
};

// The one channel (channel_weights . RGB; the slab's own, SlabInfo::channel_weights, unless
// given: luminance, as calib/scale.json's reading weighed RGB, so lux slabs give lm and W/m^2
// slabs W) of every seen texel of the positions with an image, summed one position at a time (a
// stage that does not hold the slab reads it position by position: one image in memory, not the
// whole slab).
class SlabLightSum {
 public:
  explicit SlabLightSum(const SlabInfo& info) : SlabLightSum(info, info.channel_weights) {}
  SlabLightSum(const SlabInfo& info, const Eigen::Vector3d& channel_weights);
  void Add(const SlabPosition& position);  // one with an image; its i, j name it
  SlabLight Result() const;

 private:
  Eigen::Vector3d weights_;
  double area_m2_;
  std::vector<double> texel_flux_;
  SlabLight light_;
  double lowest_ = 0;
};
// The same over a whole slab (positions without an image are skipped).
SlabLight MeasureSlabLight(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                           const Eigen::Vector3d& channel_weights);
inline SlabLight MeasureSlabLight(const SlabInfo& info,
                                  const std::vector<SlabPosition>& positions) {
  return MeasureSlabLight(info, positions, info.channel_weights);
}

// Whether the sign of a slab's total light says anything: on a grid of one row or column the
// positions are all at its edge, where the dual coefficients of a legitimate slab may sum below 0
// (a 1 x 1 slab of tests/e2e/hard_cases_geometry_test sums to -1.37 and is 0.29 % from its
// truth); 2 x 2 and larger grids sum to the luminaire's light (the demo's 9 x 7: +1.23; 2 x 2:
// positive in the catalogue and tests/e2e/consistency_slab_test).
bool TotalLightHasASign(const SlabInfo& info);

// The verdict of `check` on a total of light (`what` names it in messages): fails (exit 2,
// naming <slab_dir>/slab.json) on NaN, and on a negative total where TotalLightHasASign; warns on
// exactly 0 (a slab of no light: a black capture, not an inconsistent one); passes otherwise.
void JudgeTotalLight(const std::string& check, const std::string& what, const SlabLight& light,
                     const SlabInfo& info, const std::string& slab_dir, const std::string& sums,
                     const nlohmann::json& values, CheckLog& checks);

// Checks "slab.total_light" of the slab in `slab_dir` into `checks` (a stage's log, e.g.
// CheckLog(DatasetOfSlab(slab_dir), "export ies")) by JudgeTotalLight; passes with the measured
// numbers,
// the negative shares among them, otherwise. The shares are recorded, not held to a limit: a
// legitimate 2-position slab (tests/reconstruct) has 45 % of its texels' |flux| negative, the
// demo's 63 positions 0 %, the demo with a quarter of its positions' slides swapped 37 %; a
// tenth swapped 1.3 % (no limit separates those; the total catches every slide swapped: the
// demo's -1.23 against +1.23, a half swapped -0.20).
SlabLight CheckSlabLight(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                         const std::string& slab_dir, CheckLog& checks);
// The same of a slab measured already (SlabLightSum).
void CheckSlabLight(const SlabInfo& info, const SlabLight& light, const std::string& slab_dir,
                    CheckLog& checks);

// The numbers a check records: the sums and the shares.
nlohmann::json SlabLightValues(const SlabLight& light);

// The dataset folder holding the slab in `slab_dir` (its parent when that has a dataset.json),
// or "" for a bare slab: where a stage reading the slab records its checks.
std::string DatasetOfSlab(const std::string& slab_dir);

}  // namespace lumislab
