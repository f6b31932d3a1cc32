// The slab's irradiance (illuminance for a lux slab) on the plane z = D of the luminaire frame, by
// the exact CPU reference (docs/method.md §4.5; nothing in the way, so no visibility rays): what
// `lumislab-export irradiance` draws and the report's plane pictures and near-field table use.
#pragma once

#include <string>
#include <vector>

#include "core/image.h"
#include "core/slab.h"

namespace lumislab {

struct PlaneIrradiance {
  ImageF irradiance;  // size x size, 3 channels, W/m^2 or lx; +x right, +y up (row 0 on top)
  double plane_z_mm = 0;
  double extent_mm = 0;  // the square's side on the plane, centred on the luminaire's axis
  bool complete = true;  // false: stopped by a signal before every row was done
  // The luminance (the slab's channel weights) over the pixels: the validity check's numbers.
  double min_luminance = 0, max_luminance = 0;
  int negative_pixels = 0;    // below -kPlaneNegativeTolerance x max_luminance
  int below_zero_pixels = 0;  // below 0 (the dual filter's ringing, the noise)

  // "N of M pixels below 0 (min X unit, max Y unit)".
  std::string NegativeText(const std::string& unit) const;
};

// Where the exact model resolves a plane z = D (docs/method.md §4.9 "Planes near S"). Near S the
// supports' spread |1 - d/D| (K + 2) h on M and the parallax of the light behind S grow as d/D,
// the dual filter's negative lobes stop cancelling and the plane's illuminance rings below 0.
// On the demo slab (h 5 mm, K 1, d 750 mm; 32 x 32 pixels over 60 mm) it has pixels below -1 %
// of its maximum at every D <= 25 mm (min -17278 lx of 401407 at 20 mm, -1.0e7 of 5.0e7 at
// 1 mm) and none from 30 mm = 2 (K + 2) h; its axial illuminance follows the far field from an
// effective depth of 27 +- 1 mm behind S for D = 50 ... 200 mm (24 mm at 750) but drifts to 25,
// 23 and 21 mm at 40, 35 and 30 mm. Far planes ring too, at their edges beyond the grid's cover
// (at 4d = 3000 mm over the window: 85 of 14641 pixels, min -1.8 % of the maximum). Hence, in
// supports' extents (K + 2) h:
//   D < 2 (K + 2) h: refused (exit 2), nothing written;
//   D < 3 (K + 2) h, or pixels below -1 % of the maximum: a warning (stderr, and a note at the
//   report's plane) saying so; the values are left as computed (the EXR is the model's output).
constexpr double kPlaneNegativeTolerance = 0.01;
constexpr double kPlaneNearFieldRefuseSupports = 2;
constexpr double kPlaneNearFieldWarnSupports = 3;

// `extent_mm` 0: the slab window seen at D (window x D / d).
PlaneIrradiance RenderPlaneIrradiance(const SlabInfo& info, const std::vector<ImageF>& irradiance,
                                      double distance_mm, double extent_mm, int size, int samples,
                                      int threads);

// The plane's validity (issue 29 red team: negative lux written at 2 and 20 mm, and a rising then
// falling axial illuminance): refused planes (above) are InputError naming `option` (exit 2);
// warned ones are LogWarning, the text returned for the report ("" when neither).
std::string CheckPlaneResolved(const PlaneIrradiance& plane, const SlabInfo& info,
                               const std::string& unit, const std::string& option);
// The supports' extent (K + 2) h, mm (K from the slab's dual filter).
double SupportExtentMm(const SlabInfo& info);

}  // namespace lumislab
