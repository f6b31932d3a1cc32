// A small analytic luminaire (point emitters with cos^n lobes behind S) and its exact slab, used
// by the preview's tests and benchmark until acquire's synthetic luminaire can stand in.
// TODO(core/acquire): replace with acquire/luminaire.h once lumislab_acquire builds.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/slab.h"

namespace lumislab {

struct PointEmitter {
  Eigen::Vector3d position_mm;  // luminaire frame, z < 0
  double lobe = 1;              // I = I0 cos^lobe about +z
  Eigen::Vector3d intensity;    // I0 per channel, W/sr
};

std::vector<PointEmitter> DefaultPointEmitters();

// Analytic irradiance (W/m^2) on the plane z = plane_z_mm (normal towards the luminaire).
Eigen::Vector3d PlaneIrradiance(const std::vector<PointEmitter>& emitters, double x_mm, double y_mm,
                                double plane_z_mm);

// Slab metadata: d, nu x nv grid of spacing h, window w x w mm at res x res, truncated dual (1).
SlabInfo MakeSlabInfo(double d_mm, int nu, int nv, double h_mm, double window_mm, int res);

// Exact E_ij(s,t) at texel centres (mask all ones).
SlabPosition TruthPosition(const std::vector<PointEmitter>& emitters, const SlabInfo& info, int i,
                           int j);

// Writes a complete truth slab into `dir` (slab.json + all positions).
void WriteTruthSlab(const std::vector<PointEmitter>& emitters, const SlabInfo& info,
                    const std::string& dir);

}  // namespace lumislab
