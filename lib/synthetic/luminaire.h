// The synthetic luminaire: point emitters with cos^n lobes behind the filter plane S
// (docs/design.md §1-3). Everything here is analytic, so it doubles as the ground truth of every
// synthetic test.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "core/basis.h"
#include "lib/photometry/intensity_distribution.h"

namespace lumislab {

// A measured far-field distribution (IES or EULUMDAT file, docs/design.md §5.10, §5.17) as an
// emitter's lobe: the file's intensity divided by its peak, its gamma = 0 axis and C = 0 plane
// turned into the luminaire frame by `luminaire_from_file` (R = Rz Ry Rx of rotation_deg).
struct MeasuredLobe {
  std::shared_ptr<const IntensityDistribution> distribution;
  std::string file;  // the path it was read from
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();
  Eigen::Matrix3d luminaire_from_file = Eigen::Matrix3d::Identity();
  double peak = 1;  // the largest value of the file (cd or W/sr)

  // Reads the file (BadInput naming it) and sets the rotation.
  static MeasuredLobe Load(const std::string& file, const Eigen::Vector3d& rotation_deg);
  // The file's intensity towards unit direction w (luminaire frame) over its peak.
  double Shape(const Eigen::Vector3d& w) const;
};

// One point emitter. Intensity towards direction w (unit) is I0 cos^n(angle of w to +z), or
// I0 times a measured lobe, for w_z > 0 and zero behind.
struct Emitter {
  Eigen::Vector3d position_mm;     // luminaire frame, z < 0 (behind S)
  Eigen::Vector3d intensity_w_sr;  // I0 per RGB channel, W/sr (a measured lobe's peak)
  double lobe_exponent = 0;        // n >= 0
  std::shared_ptr<const MeasuredLobe> measured = nullptr;  // set: replaces cos^n

  // cos^n(angle of the unit direction w to +z) or the measured lobe, zero for w_z <= 0.
  double Shape(const Eigen::Vector3d& w) const;
  // I0 Shape(w) (W/sr).
  Eigen::Vector3d Intensity(const Eigen::Vector3d& w) const { return Shape(w) * intensity_w_sr; }
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
