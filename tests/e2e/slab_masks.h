// The slab mask's rule at the screen's edge (docs/method.md §3.5 step 3), for tests that check
// masks: a texel along the screen's edge whose samples' reads reach past it keeps only its other
// samples, and is unseen when fewer than a quarter are left, so texels within about one texel
// of the screen's edge may be unseen.
#pragma once

#include <Eigen/Core>
#include <string>

#include "core/grid.h"

namespace lumislab::testing {

// Whether texel (col, row) of the position whose filter centre is `c` (mm), its lab rectangle
// (luminaire frame minus c) grown by `band` texels on every side, lies on the screen of
// `screen_w_mm` x `screen_h_mm`.
bool TexelOnScreen(const SlabLayout& layout, const Eigen::Vector2d& c, double screen_w_mm,
                   double screen_h_mm, int col, int row, double band = 0);

// Texels of position (i, j) that are lit in the truth slab (largest channel magnitude at least
// `lit_fraction` of the position's largest), on the screen `band` texels or more from its edge
// (the slab window is the screen's rectangle, docs/method.md §1.4), and yet unseen in the slab:
// what something other than the screen's edge masked (a saturated or a hot pixel). Same resolution
// in both.
int UnseenLitTexelsAwayFromTheEdge(const std::string& slab_dir, const std::string& truth_dir, int i,
                                   int j, double band = 1, double lit_fraction = 0.01);

}  // namespace lumislab::testing
