// Sampling grid on S and the slab texel layout on M (docs/method.md §1, docs/formats.md). All
// lengths in mm, luminaire frame.
#pragma once

#include <Eigen/Core>

namespace lumislab {

struct SamplingGrid {
  int nu = 0;
  int nv = 0;
  double spacing_mm = 0;  // h

  int count() const { return nu * nv; }
  // Filter centre c_ij on S (z = 0), luminaire frame.
  Eigen::Vector2d Centre(int i, int j) const {
    return {(i - 0.5 * (nu - 1)) * spacing_mm, (j - 0.5 * (nv - 1)) * spacing_mm};
  }
  int Index(int i, int j) const { return j * nu + i; }
};

// Texel layout of every slab position: window [-W/2, W/2] x [-H/2, H/2] on M; column c covers
// s = -W/2 + (c + 0.5) W/res_x, row r covers t = +H/2 - (r + 0.5) H/res_y (row 0 on top).
struct SlabLayout {
  double window_w_mm = 0;
  double window_h_mm = 0;
  int res_x = 0;
  int res_y = 0;

  double TexelW() const { return window_w_mm / res_x; }
  double TexelH() const { return window_h_mm / res_y; }
  // Centre of texel (col, row) in mm on M, luminaire frame.
  Eigen::Vector2d TexelCentre(int col, int row) const {
    return {-0.5 * window_w_mm + (col + 0.5) * TexelW(),
            0.5 * window_h_mm - (row + 0.5) * TexelH()};
  }
  // Continuous texel coordinates (col, row) of a point (s, t); texel centres are integers.
  Eigen::Vector2d ToTexel(double s, double t) const {
    return {(s + 0.5 * window_w_mm) / TexelW() - 0.5, (0.5 * window_h_mm - t) / TexelH() - 0.5};
  }
};

}  // namespace lumislab
