// Compares a slab against a reference slab (the synthetic truth/ folder) position by position.
#pragma once

#include <string>
#include <vector>

#include "core/slab.h"

namespace lumislab {

struct PositionError {
  int i = 0;
  int j = 0;
  double relative_l2 = 0;     // ||E - E_ref|| / ||E_ref|| over lit, seen texels, RGB together
                              // (lux slabs: their luminance, each slab's channel_weights)
  double max_abs = 0;         // max |E - E_ref| over those texels (slab units)
  int lit_texels = 0;         // texels where |E_ref| >= lit_fraction * max |E_ref| of the position
  int unseen_lit_texels = 0;  // lit in the reference but masked out in the slab
};

struct SlabComparison {
  std::vector<PositionError> positions;  // one per position present in both
  double max_relative_l2 = 0;
  double median_relative_l2 = 0;
  double overall_relative_l2 = 0;  // all positions' texels together
  std::string Summary() const;     // one line
};

// lit_fraction: a texel is "lit" when its reference magnitude (max over channels, absolute value)
// is at least this fraction of the position's largest reference magnitude.
SlabComparison CompareSlabs(const std::string& slab_dir, const std::string& reference_dir,
                            double lit_fraction = 0.01);

}  // namespace lumislab
