#include "slab_masks.h"

#include <algorithm>
#include <cmath>

#include "core/slab.h"

namespace lumislab::testing {

bool TexelOnScreen(const SlabLayout& l, const Eigen::Vector2d& c, double screen_w_mm,
                   double screen_h_mm, int col, int row, double band) {
  // The tolerance of reconstruct/rectify.cc MarkInside.
  const double half_w = 0.5 * screen_w_mm + 1e-9, half_h = 0.5 * screen_h_mm + 1e-9;
  const double mx = band * l.TexelW(), my = band * l.TexelH();
  const double x0 = -0.5 * l.window_w_mm + col * l.TexelW() - c.x() - mx;
  const double x1 = -0.5 * l.window_w_mm + (col + 1) * l.TexelW() - c.x() + mx;
  const double y0 = 0.5 * l.window_h_mm - (row + 1) * l.TexelH() - c.y() - my;
  const double y1 = 0.5 * l.window_h_mm - row * l.TexelH() - c.y() + my;
  return x0 >= -half_w && x1 <= half_w && y0 >= -half_h && y1 <= half_h;
}

int UnseenLitTexelsAwayFromTheEdge(const std::string& slab_dir, const std::string& truth_dir, int i,
                                   int j, double band, double lit_fraction) {
  const SlabInfo info = SlabInfo::Load(slab_dir);
  const SlabInfo truth_info = SlabInfo::Load(truth_dir);
  const SlabPosition s = ReadSlabPosition(slab_dir, info, i, j);
  const SlabPosition t = ReadSlabPosition(truth_dir, truth_info, i, j);
  const SlabLayout& l = info.layout;
  auto magnitude = [&](int col, int row) {
    float m = 0;
    for (int ch = 0; ch < 3; ++ch) m = std::max(m, std::abs(t.irradiance.at(col, row, ch)));
    return m;
  };
  float peak = 0;
  for (int row = 0; row < l.res_y; ++row)
    for (int col = 0; col < l.res_x; ++col) peak = std::max(peak, magnitude(col, row));
  int count = 0;
  for (int row = 0; row < l.res_y; ++row)
    for (int col = 0; col < l.res_x; ++col)
      count +=
          s.mask.at(col, row, 0) == 0.f && magnitude(col, row) >= lit_fraction * peak &&
          TexelOnScreen(l, info.grid.Centre(i, j), l.window_w_mm, l.window_h_mm, col, row, band);
  return count;
}

}  // namespace lumislab::testing
