#include "lib/synthetic/luminaire.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/geometry.h"
#include "core/slab.h"  // Rec709Weights
#include "lib/photometry/colour.h"
#include "lib/synthetic/scene.h"  // DefaultLuminousEfficacy

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
  lobe.luminaire_from_file = RotationZyxDegrees(rotation_deg);
  const std::vector<double>& v = lobe.distribution->values;
  lobe.peak = *std::max_element(v.begin(), v.end());
  if (!(lobe.peak > 0)) throw BadInput(file + ": no light in the distribution (every value 0)");
  return lobe;
}

double MeasuredLobe::Shape(const Eigen::Vector3d& w) const {
  // The file's (C, gamma) of w: type C in the file's frame (TypeCAngles, docs/formats.md §17).
  const Eigen::Vector2d c_gamma = TypeCAngles(luminaire_from_file.transpose() * w);
  return distribution->Intensity(c_gamma.x(), c_gamma.y()) / peak;
}

double Emitter::LuminousEfficacy() const {
  return cct_k > 0 ? lumislab::LuminousEfficacy(Blackbody(cct_k)) : DefaultLuminousEfficacy();
}

double Emitter::LuminousIntensity(const Eigen::Vector3d& w) const {
  return cct_k > 0 ? LuminousEfficacy() * radiant_w_sr * Shape(w)
                   : LuminousEfficacy() * Rec709Weights().dot(Intensity(w));
}

double Emitter::Shape(const Eigen::Vector3d& w) const {
  const double c = w.dot(axis);
  if (!(c > 0)) return 0;
  return measured ? measured->Shape(w) : PowCos(c, lobe_exponent);
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
  // I cos / r^2 with r in metres: the plane M is normal to z (and so is the lobe's default axis).
  if (e.measured || e.axis != Eigen::Vector3d::UnitZ())
    return e.Shape(Eigen::Vector3d(dx, dy, dz) / r) * cos_m * 1e6 / r2;
  return PowCos(cos_m, e.lobe_exponent + 1) * 1e6 / r2;
}

Luminaire Luminaire::Turned(const Eigen::Matrix3d& rotation,
                            const Eigen::Vector3d& new_centre_mm) const {
  if (!ray_sources.empty())
    throw BadInput("a luminaire with ray sources (TM-25 files) cannot be turned into orientations");
  Luminaire out;
  out.centre_mm = new_centre_mm;
  for (size_t k = 0; k < emitters.size(); ++k) {
    Emitter e = emitters[k];
    e.position_mm = rotation * (e.position_mm - centre_mm) + new_centre_mm;
    if (!(e.position_mm.z() < 0))
      throw BadInput("emitter " + std::to_string(k) +
                     " lands at z = " + std::to_string(e.position_mm.z()) +
                     " mm, on or in front of S, in this orientation: move the luminaire's centre "
                     "further behind S");
    e.axis = (rotation * e.axis).normalized();
    if (e.measured) {
      auto lobe = std::make_shared<MeasuredLobe>(*e.measured);
      lobe->luminaire_from_file = rotation * e.measured->luminaire_from_file;
      lobe->rotation_deg = RotationZyxDegreesOf(lobe->luminaire_from_file);
      e.measured = lobe;
    }
    out.emitters.push_back(std::move(e));
  }
  return out;
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

namespace lumislab {

PlaneLight::PlaneLight(const Luminaire& luminaire, double plane_z_mm, const Eigen::Vector2d& lo_mm,
                       const Eigen::Vector2d& hi_mm, int channels)
    : luminaire_(&luminaire), plane_z_mm_(plane_z_mm) {
  if (luminaire.ray_sources.empty()) return;
  // One lattice for all ray sources: the finest cell asked for.
  double cell = 0;
  for (const RaySource& r : luminaire.ray_sources)
    if (r.cell_mm > 0 && (cell == 0 || r.cell_mm < cell)) cell = r.cell_mm;
  if (!(cell > 0))
    throw BadInput(luminaire.ray_sources.front().file +
                   ": rays.cell_mm: expected the splat cell (a scene file sets its default from "
                   "the screen), got none");
  rays_ = std::make_unique<RaySplat>(lo_mm.x(), hi_mm.x(), lo_mm.y(), hi_mm.y(), cell, channels);
}

PlaneLight PlaneLight::ThroughSlides(const Luminaire& luminaire, const DualFilter& f, double h_mm,
                                     const Eigen::Vector2d& c_mm, double d_mm,
                                     const Eigen::Vector2d& lo_mm, const Eigen::Vector2d& hi_mm) {
  PlaneLight light(luminaire, d_mm, lo_mm, hi_mm, 6);
  light.slides_ = true;
  light.filter_ = f;
  light.peak_ = f.Peak2D();
  light.h_mm_ = h_mm;
  light.c_mm_ = c_mm;
  if (!light.rays_) return light;
  const double support = f.SupportHalfWidth();
  double flux[6];
  // Each ray from its origin through S (where the slides weigh it, as SlideIrradiance weighs a
  // point emitter's ray) onto M.
  for (const RaySource& source : luminaire.ray_sources)
    for (const SourceRay& ray : *source.rays) {
      const Eigen::Vector3d& o = ray.origin_mm;
      const Eigen::Vector3d& k = ray.direction;
      const double to_s = -o.z() / k.z();
      const double fu = (o.x() + k.x() * to_s - c_mm.x()) / h_mm;
      const double fv = (o.y() + k.y() * to_s - c_mm.y()) / h_mm;
      if (std::abs(fu) >= support || std::abs(fv) >= support) continue;
      const double phi = f.Eval2D(fu, fv) / light.peak_;  // the slide pair's transmittance
      if (phi == 0) continue;
      const double to_m = (d_mm - o.z()) / k.z();
      const Eigen::Vector3d w = (std::abs(phi) * ray.flux) * source.rgb;
      for (int c = 0; c < 3; ++c) {
        flux[c] = phi > 0 ? w[c] : 0;
        flux[3 + c] = phi < 0 ? w[c] : 0;
      }
      light.rays_->Add(o.x() + k.x() * to_m, o.y() + k.y() * to_m, flux);
    }
  return light;
}

PlaneLight PlaneLight::Open(const Luminaire& luminaire, double plane_z_mm,
                            const Eigen::Vector2d& lo_mm, const Eigen::Vector2d& hi_mm) {
  PlaneLight light(luminaire, plane_z_mm, lo_mm, hi_mm, 3);
  if (!light.rays_) return light;
  double flux[3];
  for (const RaySource& source : luminaire.ray_sources)
    for (const SourceRay& ray : *source.rays) {
      const double to_plane = (plane_z_mm - ray.origin_mm.z()) / ray.direction.z();
      if (!(to_plane > 0)) continue;  // the plane is behind the ray's origin
      for (int c = 0; c < 3; ++c) flux[c] = ray.flux * source.rgb[c];
      light.rays_->Add(ray.origin_mm.x() + ray.direction.x() * to_plane,
                       ray.origin_mm.y() + ray.direction.y() * to_plane, flux);
    }
  return light;
}

void PlaneLight::Slides(double s_mm, double t_mm, Eigen::Vector3d* plus,
                        Eigen::Vector3d* minus) const {
  LUMISLAB_CHECK(slides_, "PlaneLight: not through slides");
  luminaire_->SlideIrradiance(filter_, peak_, h_mm_, c_mm_, plane_z_mm_, s_mm, t_mm, plus, minus);
  if (!rays_) return;
  double e[6];
  rays_->At(s_mm, t_mm, e);
  *plus += Eigen::Vector3d(e[0], e[1], e[2]);
  *minus += Eigen::Vector3d(e[3], e[4], e[5]);
}

Eigen::Vector3d PlaneLight::Filtered(double s_mm, double t_mm) const {
  LUMISLAB_CHECK(slides_, "PlaneLight: not through slides");
  Eigen::Vector3d sum =
      luminaire_->FilteredIrradiance(filter_, h_mm_, c_mm_, plane_z_mm_, s_mm, t_mm);
  if (!rays_) return sum;
  double e[6];
  rays_->At(s_mm, t_mm, e);
  for (int c = 0; c < 3; ++c) sum[c] += peak_ * (e[c] - e[3 + c]);
  return sum;
}

Eigen::Vector3d PlaneLight::Irradiance(double s_mm, double t_mm) const {
  LUMISLAB_CHECK(!slides_, "PlaneLight: through slides");
  Eigen::Vector3d sum = luminaire_->PlaneIrradiance(s_mm, t_mm, plane_z_mm_);
  if (!rays_) return sum;
  double e[3];
  rays_->At(s_mm, t_mm, e);
  return sum + Eigen::Vector3d(e[0], e[1], e[2]);
}

void RequirePointEmitters(const Luminaire& luminaire, const std::string& source,
                          const std::string& what) {
  if (luminaire.ray_sources.empty()) return;
  throw BadInput(source + ": luminaire: " + what +
                 " needs point emitters, got a TM-25 ray source (" +
                 luminaire.ray_sources.front().file + ")");
}

}  // namespace lumislab
