// The synthetic luminaire: point emitters with cos^n lobes behind the filter plane S
// (docs/design.md §1-3). Everything here is analytic, so it doubles as the ground truth of every
// synthetic test.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/basis.h"

namespace lumislab {

// One point emitter. Intensity towards direction w (unit) is I0 cos^n(angle of w to +z) for
// w_z > 0 and zero behind.
struct Emitter {
  Eigen::Vector3d position_mm;     // luminaire frame, z < 0 (behind S)
  Eigen::Vector3d intensity_w_sr;  // I0 per RGB channel, W/sr
  double lobe_exponent = 0;        // n >= 0
  // I0 cos^n(angle of the unit direction w to +z), zero for w_z <= 0 (W/sr).
  Eigen::Vector3d Intensity(const Eigen::Vector3d& w) const;
};

struct Luminaire {
  std::vector<Emitter> emitters;

  // RGB irradiance (W/m^2) on the plane z = plane_z_mm at (x,y) (luminaire frame), no filter.
  Eigen::Vector3d PlaneIrradiance(double x_mm, double y_mm, double plane_z_mm) const;
  // Signed E_ij(s,t) on M (z = d_mm) through Phi~ centred at c (the ground truth), W/m^2.
  Eigen::Vector3d FilteredIrradiance(const DualFilter& f, double h_mm, const Eigen::Vector2d& c_mm,
                                     double d_mm, double s_mm, double t_mm) const;
  // Irradiance (W/m^2) at (s,t) on M through the two printed slides T+ = max(Phi~,0)/peak and
  // T- = max(-Phi~,0)/peak of the filter centred at c; peak (E+ - E-) = FilteredIrradiance.
  void SlideIrradiance(const DualFilter& f, double peak, double h_mm, const Eigen::Vector2d& c_mm,
                       double d_mm, double s_mm, double t_mm, Eigen::Vector3d* plus,
                       Eigen::Vector3d* minus) const;
};

// Unfiltered irradiance (W/m^2, per unit I0) that emitter e sends to (s,t,d), and the point
// (u,v) where that ray crosses S (z = 0). Returns 0 when the point is not in front of e.
double EmitterIrradianceFactor(const Emitter& e, double d_mm, double s_mm, double t_mm,
                               double* u_mm, double* v_mm);

}  // namespace lumislab
