// The slab as the renderer uses it (docs/method.md §4): per grid position the texture
// E'_ij = E_ij / g_ij in W/sr (g_ij the shift-invariant geometry term, converted to m^-2), read
// from disk ready to upload, and the CPU evaluation of the same textured-spot-light formula (eq. 14
// for one position; tests and exact comparisons). No GL here: the renderer only uploads E'.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "core/image.h"
#include "core/slab.h"

namespace lumislab {

// E'_ij from E_ij (3 channels, layout of `info`): E' = E[W/m^2] / (g[mm^-2] * 1e6).
ImageF IntensityFromIrradiance(const SlabInfo& info, int i, int j, const ImageF& irradiance);

// Bilinear lookup of a 3-channel texture in the slab layout at (s, t) mm; zero outside the window
// (texels are clamped at the edge inside it), like the GL sampler.
Eigen::Vector3d SampleLayout(const SlabLayout& layout, const ImageF& texture, double s, double t);

// The irradiance one grid position's spot light gives at point x with unit normal n (both in
// the luminaire frame, mm), without visibility: V=1. W/m^2.
Eigen::Vector3d SpotIrradiance(const SlabInfo& info, int i, int j, const ImageF& intensity,
                               const Eigen::Vector3d& x, const Eigen::Vector3d& n);

// E'_ij of position (i, j) read from the slab folder (ReadSlabPosition, checked against `info`).
ImageF ReadIntensity(const std::string& slab_dir, const SlabInfo& info, int i, int j);
// E' of each of `positions` (i, j), read and derived on `threads` threads; same order.
std::vector<ImageF> ReadIntensities(const std::string& slab_dir, const SlabInfo& info,
                                    const std::vector<std::pair<int, int>>& positions, int threads);

}  // namespace lumislab
