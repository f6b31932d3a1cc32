// One orientation's far field as the registration reads it (docs/method.md §4.12,
// "Registration"): I (W/sr, cd for lux slabs) on a regular grid of the capture frame's
// screen-plane coordinates (x/z, y/z), where the slab's far field is smooth and a bicubic
// interpolator can be differentiated; with each node's seen flag. No Ceres here.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/luminaire_set.h"
#include "core/slab.h"

namespace lumislab {

struct FarFieldGrid {
  double x_max = 0, y_max = 0;  // the grid spans [-x_max, x_max] x [-y_max, y_max] of (x/z, y/z)
  int nx = 0, ny = 0;           // nodes per row, rows
  std::vector<double> values;   // values[row * nx + col]: I (W/sr), 0 where unseen
  std::vector<uint8_t> seen;    // 1: the far field saw the node's direction

  double StepX() const { return 2 * x_max / (nx - 1); }
  double StepY() const { return 2 * y_max / (ny - 1); }
  // The capture-frame direction of node (col, row).
  Eigen::Vector3d Direction(int col, int row) const;
  // (col, row) in node units of capture-frame direction w (z > 0): what the interpolator takes.
  template <typename T>
  void GridCoordinates(const T* w, T* col, T* row) const {
    *col = (w[0] / w[2] + x_max) / StepX();
    *row = (w[1] / w[2] + y_max) / StepY();
  }
  // True when w (capture frame) lies in front of S and every node the bicubic interpolation
  // around it reads (4 x 4) is inside the grid and seen.
  bool SeenAround(const Eigen::Vector3d& w_capture) const;
};

// The far field of a complete slab on a grid covering `cone` (its half-angles' tangents), about
// `nodes_per_tan` nodes per unit of x/z: the slab's own far field (lib/lightfield/far_field.h,
// the exact model with the default bell quadrature) at each node's direction.
FarFieldGrid SampleFarFieldGrid(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                                const OrientationCone& cone, double nodes_per_tan, int threads);

}  // namespace lumislab
