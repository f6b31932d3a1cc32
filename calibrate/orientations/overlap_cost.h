// Ceres cost of one luminaire-frame direction w seen by two orientations a and b (docs/method.md
// §4.12, "Registration"): the same direction must have the same intensity in both far fields,
//   r = (I_a(Exp(c_a) R_a w) - I_b(Exp(c_b) R_b w)) / scale,
// with R_k the nominal capture_from_luminaire rotation, c_k the orientation's correction (a
// rotation vector, radians, in its capture frame: the refined pose is Exp(c_k) R_k) and I_k its
// far field on the screen-plane grid (FarFieldGrid) read with a bicubic interpolator. `scale` is
// the pair's mean intensity over its overlap, so r is relative and the robust loss's scale and
// the disagreement threshold read alike for bright and dim overlaps.
#pragma once

#include <ceres/ceres.h>
#include <ceres/cubic_interpolation.h>
#include <ceres/rotation.h>

#include <Eigen/Core>

#include "calibrate/orientations/far_field_grid.h"

namespace lumislab {

using FarFieldInterpolator = ceres::BiCubicInterpolator<ceres::Grid2D<double, 1>>;

class OverlapCost {
 public:
  // w_a = R_a w, w_b = R_b w: the direction in each orientation's nominal capture frame.
  OverlapCost(const FarFieldGrid* grid_a, const FarFieldInterpolator* far_a,
              const Eigen::Vector3d& w_a, const FarFieldGrid* grid_b,
              const FarFieldInterpolator* far_b, const Eigen::Vector3d& w_b, double scale)
      : grid_a_(grid_a),
        far_a_(far_a),
        w_a_(w_a),
        grid_b_(grid_b),
        far_b_(far_b),
        w_b_(w_b),
        scale_(scale) {}

  template <typename T>
  bool operator()(const T* const c_a, const T* const c_b, T* residual) const {
    const T i_a = Intensity(grid_a_, far_a_, c_a, w_a_);
    const T i_b = Intensity(grid_b_, far_b_, c_b, w_b_);
    residual[0] = (i_a - i_b) / scale_;
    return true;
  }

  static ceres::CostFunction* Create(const FarFieldGrid* grid_a, const FarFieldInterpolator* far_a,
                                     const Eigen::Vector3d& w_a, const FarFieldGrid* grid_b,
                                     const FarFieldInterpolator* far_b, const Eigen::Vector3d& w_b,
                                     double scale) {
    return new ceres::AutoDiffCostFunction<OverlapCost, 1, 3, 3>(
        new OverlapCost(grid_a, far_a, w_a, grid_b, far_b, w_b, scale));
  }

 private:
  template <typename T>
  static T Intensity(const FarFieldGrid* grid, const FarFieldInterpolator* far, const T* c,
                     const Eigen::Vector3d& w) {
    const T w_nominal[3] = {T(w.x()), T(w.y()), T(w.z())};
    T v[3];
    ceres::AngleAxisRotatePoint(c, w_nominal, v);
    T col, row, value;
    grid->GridCoordinates(v, &col, &row);
    far->Evaluate(row, col, &value);
    return value;
  }

  const FarFieldGrid* grid_a_;
  const FarFieldInterpolator* far_a_;
  Eigen::Vector3d w_a_;
  const FarFieldGrid* grid_b_;
  const FarFieldInterpolator* far_b_;
  Eigen::Vector3d w_b_;
  double scale_;
};

}  // namespace lumislab
