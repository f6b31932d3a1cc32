#include "export/plane_irradiance.h"

#include <algorithm>

#include "core/error.h"
#include "core/log.h"
#include "core/stop_signal.h"
#include "lib/lightfield/reference_render.h"
#include "lib/lightfield/scene_setup.h"

namespace lumislab {

std::string PlaneIrradiance::NegativeText(const std::string& unit) const {
  return std::to_string(negative_pixels) + " of " +
         std::to_string(irradiance.width * irradiance.height) + " pixels below -" +
         Num(100 * kPlaneNegativeTolerance, 2) + " % of the maximum (min " + Num(min_luminance, 6) +
         " " + unit + ", max " + Num(max_luminance, 6) + " " + unit + ")";
}

PlaneIrradiance RenderPlaneIrradiance(const SlabInfo& info, const std::vector<ImageF>& irradiance,
                                      double distance_mm, double extent_mm, int size, int samples,
                                      int threads) {
  SceneRequest scene;
  scene.name = "plane";
  scene.receiver_plane_mm = distance_mm;
  scene.extent_mm = extent_mm;
  const SceneSetup setup = MakeSceneSetup(scene, info);
  const ReferenceScene view(setup, size, size);
  ReferenceOptions options;
  options.samples = samples;
  options.threads = threads;
  options.visibility = false;  // the plane alone: nothing casts a shadow
  const StopSignalScope stop_signals;
  ReferenceImage image = RenderReference(view, info, irradiance, options);
  PlaneIrradiance out;
  out.irradiance = std::move(image.irradiance);
  out.plane_z_mm = setup.plane_z;
  out.extent_mm = setup.extent;
  out.complete = image.complete;
  const Eigen::Vector3d w = info.channel_weights;
  std::vector<double> luminance;
  for (int y = 0; y < out.irradiance.height; ++y)
    for (int x = 0; x < out.irradiance.width; ++x)
      luminance.push_back(w[0] * out.irradiance.at(x, y, 0) + w[1] * out.irradiance.at(x, y, 1) +
                          w[2] * out.irradiance.at(x, y, 2));
  if (!luminance.empty()) {
    out.min_luminance = *std::min_element(luminance.begin(), luminance.end());
    out.max_luminance = *std::max_element(luminance.begin(), luminance.end());
  }
  for (double v : luminance) {
    if (v < -kPlaneNegativeTolerance * std::max(out.max_luminance, 0.0)) ++out.negative_pixels;
    if (v < 0) ++out.below_zero_pixels;
  }
  return out;
}

double SupportExtentMm(const SlabInfo& info) {
  const double k = std::max<double>(1, double(info.filter.dual_coefficients.size()) - 1);
  return (k + 2) * info.grid.spacing_mm;
}

std::string CheckPlaneResolved(const PlaneIrradiance& plane, const SlabInfo& info,
                               const std::string& unit, const std::string& option) {
  const double D = plane.plane_z_mm, support = SupportExtentMm(info);
  const double refuse_mm = kPlaneNearFieldRefuseSupports * support,
               warn_mm = kPlaneNearFieldWarnSupports * support;
  const std::string limits = " (docs/method.md §4.9 \"Planes near S\": refused below " +
                             Num(refuse_mm, 4) + " mm = " + Num(kPlaneNearFieldRefuseSupports, 3) +
                             " (K + 2) h, trusted from " + Num(warn_mm, 4) +
                             " mm = " + Num(kPlaneNearFieldWarnSupports, 3) + " (K + 2) h)";
  if (D < refuse_mm)
    throw InputError(option, "", "a plane at least " + Num(refuse_mm, 4) + " mm from S" + limits,
                     Num(D, 6) + " mm; nothing written");
  if (!(D < warn_mm) && plane.negative_pixels == 0) return "";
  const std::string text =
      "the plane at " + Num(D, 4) + " mm" +
      (D < warn_mm ? " is nearer S than the exact model is trusted" : std::string()) +
      (plane.negative_pixels > 0
           ? std::string(D < warn_mm ? "; " : " has ") + plane.NegativeText(unit) +
                 ": the dual filter's ringing where the model does not resolve the plane "
                 "(left as computed, not clamped)"
           : std::string()) +
      (D < warn_mm ? limits : std::string(" (docs/method.md §4.9)"));
  LogWarning(text);
  return text;
}

}  // namespace lumislab
