// The slab's irradiance (illuminance for a lux slab) on the plane z = D of the luminaire frame, by
// the exact CPU reference (docs/method.md §4.5; nothing in the way, so no visibility rays): what
// `lumislab-export irradiance` draws and the report's plane pictures and near-field table use.
#pragma once

#include <vector>

#include "core/image.h"
#include "core/slab.h"

namespace lumislab {

struct PlaneIrradiance {
  ImageF irradiance;  // size x size, 3 channels, W/m^2 or lx; +x right, +y up (row 0 on top)
  double plane_z_mm = 0;
  double extent_mm = 0;  // the square's side on the plane, centred on the luminaire's axis
  bool complete = true;  // false: stopped by a signal before every row was done
};

// `extent_mm` 0: the slab window seen at D (window x D / d).
PlaneIrradiance RenderPlaneIrradiance(const SlabInfo& info, const std::vector<ImageF>& irradiance,
                                      double distance_mm, double extent_mm, int size, int samples,
                                      int threads);

}  // namespace lumislab
