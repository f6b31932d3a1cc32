// Ceres cost of one luminaire-frame direction w seen by two orientations a and b (docs/method.md
// §4.12, "Registration"): the same direction must have the same intensity in both far fields,
//   r = (I_a(v_a) g(theta_b) - I_b(v_b) g(theta_a)) / (scale (g(theta_a) + g(theta_b)) / 2),
// v_k = Exp(c_k) R_k w, i.e. I_a / g(theta_a) - I_b / g(theta_b) scaled back by their mean gain,
// with R_k the nominal capture_from_luminaire rotation, c_k the orientation's correction (a
// rotation vector, radians, in its capture frame: the refined pose is Exp(c_k) R_k), I_k its
// far field on the screen-plane grid (FarFieldGrid) read with a bicubic interpolator, theta_k
// the angle of v_k from k's capture axis and g the gain profile shared by every orientation,
//   g(theta) = 1 + p_1 (1 - cos theta) + p_2 (1 - cos theta)^2:
// the far field's error that depends on the angle from the capture axis alone (the same rig for
// every orientation), which across an overlap would otherwise read as a small turn. g(0) = 1:
// a gain common to all directions cancels from every residual, and r does not change when g is
// multiplied by a constant (a profile growing everywhere away from the axis cannot shrink the
// residuals by dividing every intensity by it). `scale` is the pair's mean
// intensity over its overlap, so r is relative and the robust loss's scale and the disagreement
// threshold read alike for bright and dim overlaps.
#pragma once

#include <ceres/ceres.h>
#include <ceres/cubic_interpolation.h>
#include <ceres/rotation.h>

#include <Eigen/Core>

#include "calibrate/orientations/far_field_grid.h"

namespace lumislab {

using FarFieldInterpolator = ceres::BiCubicInterpolator<ceres::Grid2D<double, 1>>;

// The gain profile's coefficients p_1, p_2 (registration.h reports them).
constexpr int kGainProfileTerms = 2;

// g(theta) = 1 + p_1 u + p_2 u^2, u = 1 - cos theta.
template <typename T>
T GainProfile(const T* p, const T& cos_theta) {
  const T u = T(1) - cos_theta;
  return T(1) + p[0] * u + p[1] * u * u;
}

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
  bool operator()(const T* const c_a, const T* const c_b, const T* const profile,
                  T* residual) const {
    T g_a, g_b;
    const T i_a = Intensity(grid_a_, far_a_, c_a, profile, w_a_, &g_a);
    const T i_b = Intensity(grid_b_, far_b_, c_b, profile, w_b_, &g_b);
    residual[0] = (i_a * g_b - i_b * g_a) / (T(0.5 * scale_) * (g_a + g_b));
    return true;
  }

  static ceres::CostFunction* Create(const FarFieldGrid* grid_a, const FarFieldInterpolator* far_a,
                                     const Eigen::Vector3d& w_a, const FarFieldGrid* grid_b,
                                     const FarFieldInterpolator* far_b, const Eigen::Vector3d& w_b,
                                     double scale) {
    return new ceres::AutoDiffCostFunction<OverlapCost, 1, 3, 3, kGainProfileTerms>(
        new OverlapCost(grid_a, far_a, w_a, grid_b, far_b, w_b, scale));
  }

 private:
  template <typename T>
  // I_k(v) at the corrected direction v and g(theta) there (v is a unit vector: cos theta = v_z).
  static T Intensity(const FarFieldGrid* grid, const FarFieldInterpolator* far, const T* c,
                     const T* profile, const Eigen::Vector3d& w, T* gain) {
    const T w_nominal[3] = {T(w.x()), T(w.y()), T(w.z())};
    T v[3];
    ceres::AngleAxisRotatePoint(c, w_nominal, v);
    T col, row, value;
    grid->GridCoordinates(v, &col, &row);
    far->Evaluate(row, col, &value);
    *gain = GainProfile(profile, v[2]);
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
