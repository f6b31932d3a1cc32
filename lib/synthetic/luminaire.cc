#include "lib/synthetic/luminaire.h"

#include <cmath>

namespace lumislab {
namespace {

// cos^p with a fast path for small integer exponents (the common lobes).
double PowCos(double c, double p) {
  const int k = int(p);
  if (double(k) == p && k >= 0 && k <= 16) {
    double r = 1, b = c;
    for (int e = k; e > 0; e >>= 1, b *= b)
      if (e & 1) r *= b;
    return r;
  }
  return std::pow(c, p);
}

}  // namespace

Eigen::Vector3d Emitter::Intensity(const Eigen::Vector3d& w) const {
  if (!(w.z() > 0)) return Eigen::Vector3d::Zero();
  return PowCos(w.z(), lobe_exponent) * intensity_w_sr;
}

double EmitterIrradianceFactor(const Emitter& e, double d_mm, double s_mm, double t_mm,
                               double* u_mm, double* v_mm) {
  const Eigen::Vector3d& p = e.position_mm;
  const double dz = d_mm - p.z();  // > 0: the receiver is in front of the emitter
  const double dx = s_mm - p.x(), dy = t_mm - p.y();
  // Ray from e to (s,t,d) crosses z = 0 at parameter -p_z / dz.
  const double a = -p.z() / dz;
  *u_mm = p.x() + dx * a;
  *v_mm = p.y() + dy * a;
  if (!(dz > 0)) return 0;
  const double r2 = dx * dx + dy * dy + dz * dz;  // mm^2
  const double cos_m = dz / std::sqrt(r2);
  // I cos / r^2 with r in metres: the plane M is normal to z, as is the lobe axis.
  return PowCos(cos_m, e.lobe_exponent + 1) * 1e6 / r2;
}

Eigen::Vector3d Luminaire::PlaneIrradiance(double x_mm, double y_mm, double plane_z_mm) const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double u, v;
  for (const Emitter& e : emitters)
    sum += EmitterIrradianceFactor(e, plane_z_mm, x_mm, y_mm, &u, &v) * e.intensity_w_sr;
  return sum;
}

Eigen::Vector3d Luminaire::FilteredIrradiance(const DualFilter& f, double h_mm,
                                              const Eigen::Vector2d& c_mm, double d_mm, double s_mm,
                                              double t_mm) const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double u, v;
  for (const Emitter& e : emitters) {
    const double g = EmitterIrradianceFactor(e, d_mm, s_mm, t_mm, &u, &v);
    if (g == 0) continue;
    const double phi = f.Eval2D((u - c_mm.x()) / h_mm, (v - c_mm.y()) / h_mm);
    sum += phi * g * e.intensity_w_sr;
  }
  return sum;
}

void Luminaire::SlideIrradiance(const DualFilter& f, double peak, double h_mm,
                                const Eigen::Vector2d& c_mm, double d_mm, double s_mm, double t_mm,
                                Eigen::Vector3d* plus, Eigen::Vector3d* minus) const {
  plus->setZero();
  minus->setZero();
  const double support = f.SupportHalfWidth();
  double u, v;
  for (const Emitter& e : emitters) {
    const double g = EmitterIrradianceFactor(e, d_mm, s_mm, t_mm, &u, &v);
    const double fu = (u - c_mm.x()) / h_mm, fv = (v - c_mm.y()) / h_mm;
    if (g == 0 || std::abs(fu) >= support || std::abs(fv) >= support) continue;
    const double phi = f.Eval2D(fu, fv) / peak;  // transmittance of the signed slide pair
    if (phi > 0) {
      *plus += (phi * g) * e.intensity_w_sr;
    } else if (phi < 0) {
      *minus += (-phi * g) * e.intensity_w_sr;
    }
  }
}

}  // namespace lumislab
