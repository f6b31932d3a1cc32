// The synthetic luminaire: point emitters with cos^n lobes behind the filter plane S
// (docs/method.md §1-3), and TM-25 ray files as sources (lib/synthetic/ray_source.h). The point
// emitters are analytic, so they double as the ground truth of every synthetic test; a ray
// source's truth is its own rays through the same splat as its photos (PlaneLight).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "core/basis.h"
#include "lib/photometry/intensity_distribution.h"
#include "lib/synthetic/ray_source.h"

namespace lumislab {

// A measured far-field distribution (IES or EULUMDAT file, docs/formats.md §10, §17) as an
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

// One point emitter. Intensity towards direction w (unit) is I0 cos^n(angle of w to the axis), or
// I0 times a measured lobe, for w . axis > 0 and zero behind (the axis is +z unless the scene
// gives one: light leaves S only towards +z, so an emitter of a captured luminaire looks there;
// a turned luminaire's emitters look wherever the turn takes them, Luminaire::Turned).
struct Emitter {
  Eigen::Vector3d position_mm;     // luminaire frame, z < 0 (behind S)
  Eigen::Vector3d intensity_w_sr;  // I0 per RGB channel, W/sr (a measured lobe's peak)
  double lobe_exponent = 0;        // n >= 0
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();         // unit; the lobe's axis, luminaire frame
  std::shared_ptr<const MeasuredLobe> measured = nullptr;  // set: replaces cos^n
  // > 0: the emitter's light is a blackbody at this temperature (scene field "cct_k", with
  // intensity_w_sr a single number, the radiant intensity over 380 - 780 nm, W/sr = radiant_w_sr);
  // intensity_w_sr then holds the synthetic camera's RGB of that spectrum (lib/synthetic/
  // spectral.h: a flat spectrum of 1 W/sr would give 1 in every channel). 0: no spectrum.
  double cct_k = 0;
  double radiant_w_sr = 0;

  // cos^n(angle of the unit direction w to the axis) or the measured lobe, zero for w . axis <= 0.
  double Shape(const Eigen::Vector3d& w) const;
  // I0 Shape(w) (W/sr).
  Eigen::Vector3d Intensity(const Eigen::Vector3d& w) const { return Shape(w) * intensity_w_sr; }
  // The luminous efficacy of its light, lm/W: 683 sum(V s) / sum(s) of its blackbody for an
  // emitter with a spectrum; DefaultLuminousEfficacy (an equal-energy spectrum) without.
  double LuminousEfficacy() const;
  // Its luminous intensity towards w, cd = 683 integral of V I_lambda: LuminousEfficacy x
  // radiant_w_sr x Shape(w) with a spectrum; without one (RGB is then no spectrum), the
  // synthetic convention LuminousEfficacy x the Rec. 709 mix of Intensity(w).
  double LuminousIntensity(const Eigen::Vector3d& w) const;
};

struct Luminaire {
  std::vector<Emitter> emitters;
  std::vector<RaySource> ray_sources;  // scene emitters with "rays" (a TM-25 file)
  // The luminaire's own origin in the frame its positions are given in (scene field
  // luminaire.centre_mm, default the origin of S): the point a turn is about.
  Eigen::Vector3d centre_mm = Eigen::Vector3d::Zero();

  // The luminaire turned by R about its centre, the centre moved to centre_mm: the luminaire as
  // an orientation of a luminaire folder sees it (core/luminaire_set.h: x' = R (x - centre) +
  // centre_mm, axes and measured lobes turned by R). BadInput naming the emitter when one lands
  // on or in front of S (z >= 0), or when the luminaire has ray sources (not turned yet).
  Luminaire Turned(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& centre_mm) const;

  // The three functions below are the point emitters' light at one point, analytic; a ray
  // source's light needs its rays splatted over a region first: PlaneLight does both.
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

// The light a luminaire sends onto a plane, over a region of it (luminaire frame, mm): the point
// emitters analytically (the Luminaire functions above), the ray sources through a RaySplat of
// their rays built once here (cost: their rays). The photos, the truth slab and the calibration
// captures read their light through it. The luminaire must outlive it.
class PlaneLight {
 public:
  // Through the two slides of the filter centred at c (T+ and T-, docs/method.md §2.5) onto M
  // (z = d), over [lo, hi] of M.
  static PlaneLight ThroughSlides(const Luminaire& luminaire, const DualFilter& f, double h_mm,
                                  const Eigen::Vector2d& c_mm, double d_mm,
                                  const Eigen::Vector2d& lo_mm, const Eigen::Vector2d& hi_mm);
  // Without a slide onto the plane z = plane_z over [lo, hi].
  static PlaneLight Open(const Luminaire& luminaire, double plane_z_mm,
                         const Eigen::Vector2d& lo_mm, const Eigen::Vector2d& hi_mm);

  // Through the slides: irradiance (W/m^2) with T+ and with T- in (SlideIrradiance's).
  void Slides(double s_mm, double t_mm, Eigen::Vector3d* plus, Eigen::Vector3d* minus) const;
  // Through the slides: the signed E_ij = peak (E+ - E-) (FilteredIrradiance's for the point
  // emitters; the same expression of the same splat for the rays, so photos and truth agree).
  Eigen::Vector3d Filtered(double s_mm, double t_mm) const;
  // Without a slide: the irradiance (W/m^2).
  Eigen::Vector3d Irradiance(double s_mm, double t_mm) const;

 private:
  PlaneLight(const Luminaire& luminaire, double plane_z_mm, const Eigen::Vector2d& lo_mm,
             const Eigen::Vector2d& hi_mm, int channels);
  const Luminaire* luminaire_;
  bool slides_ = false;
  DualFilter filter_ = DualFilter::Truncated(1);
  double peak_ = 1, h_mm_ = 1, plane_z_mm_ = 0;
  Eigen::Vector2d c_mm_ = Eigen::Vector2d::Zero();
  std::unique_ptr<RaySplat> rays_;  // null without ray sources; 6 channels (E+, E-) or 3
};

// For what knows point emitters only (analytic images, GridCovers, the study): BadInput naming
// `source` and the first ray source's file when the luminaire has one.
void RequirePointEmitters(const Luminaire& luminaire, const std::string& source,
                          const std::string& what);

// Unfiltered irradiance (W/m^2, per unit I0) that emitter e sends to (s,t,d), and the point
// (u,v) where that ray crosses S (z = 0). Returns 0 when the point is not in front of e.
double EmitterIrradianceFactor(const Emitter& e, double d_mm, double s_mm, double t_mm,
                               double* u_mm, double* v_mm);

}  // namespace lumislab
