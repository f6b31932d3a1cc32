#include "lib/synthetic/luminaire.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/geometry.h"

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

MeasuredLobe MeasuredLobe::Load(const std::string& file, const Eigen::Vector3d& rotation_deg) {
  MeasuredLobe lobe;
  lobe.distribution = std::make_shared<const IntensityDistribution>(ReadIntensityFile(file));
  lobe.file = file;
  lobe.rotation_deg = rotation_deg;
  const Eigen::Vector3d r = rotation_deg * kPi / 180;
  lobe.luminaire_from_file = (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
                              Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
                                 .toRotationMatrix();
  const std::vector<double>& v = lobe.distribution->values;
  lobe.peak = *std::max_element(v.begin(), v.end());
  if (!(lobe.peak > 0)) throw BadInput(file + ": no light in the distribution (every value 0)");
  return lobe;
}

double MeasuredLobe::Shape(const Eigen::Vector3d& w) const {
  const Eigen::Vector3d local = luminaire_from_file.transpose() * w;
  const double gamma = std::acos(std::clamp(local.z(), -1.0, 1.0)) * 180 / kPi;
  const double c = std::atan2(local.y(), local.x()) * 180 / kPi;
  return distribution->Intensity(c, gamma) / peak;
}

double Emitter::Shape(const Eigen::Vector3d& w) const {
  if (!(w.z() > 0)) return 0;
  return measured ? measured->Shape(w) : PowCos(w.z(), lobe_exponent);
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
  const double r = std::sqrt(r2);
  const double cos_m = dz / r;
  // I cos / r^2 with r in metres: the plane M is normal to z, as is the lobe axis.
  if (e.measured) return e.Shape(Eigen::Vector3d(dx, dy, dz) / r) * cos_m * 1e6 / r2;
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
