// The light slab on disk (docs/formats.md): slab/slab.json + slab/pos_<i>_<j>.exr.
// Each position stores E_ij (irradiance on M, luminaire frame, W m^-2 or relative) as float RGB
// plus a "mask" channel (1 = seen, 0 = not seen; unseen texels hold 0), in the texel layout of
// SlabLayout. Metadata is repeated as EXR attributes so one file stands on its own.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "core/dataset.h"
#include "core/grid.h"
#include "core/image.h"

namespace lumislab {

// slab.json is written as version 2 when its channel_weights are not Rec. 709's (an older reader
// would weigh the channels with Rec. 709's and misread the slab's luminance), else as version 1.
constexpr int kSlabSchemaVersion = 2;
// Texels per side of a slab: what ReadExr reads back (kMaxExrPixels = 8192^2).
constexpr int kMaxSlabResolution = 8192;

// Rec. 709 luminance weights of linear RGB (they sum to 1): the slab's channel weights when no
// colour calibration gave the camera's own (SlabInfo::channel_weights), and the scalar of
// pictures that are not photometric (tone mapping, the photos' gray for detection and metering).
inline Eigen::Vector3d Rec709Weights() { return {0.2126, 0.7152, 0.0722}; }

struct SlabInfo {
  double distance_mm = 0;
  SamplingGrid grid;
  SlabLayout layout;
  std::string units = "W/m^2";  // or "lux" (calib/scale.json from a lux meter), "relative"
  FilterInfo filter;
  // RGB -> the one channel every photometric stage reads (far field, rays, total light,
  // irradiance pictures): luminance Y with its weights summed to 1. The camera's own from its
  // colour calibration (calib/colour.json through calib/scale.json) or Rec. 709's (old slabs,
  // captures without one; `channel_weights_from_colour` false).
  Eigen::Vector3d channel_weights = Rec709Weights();
  bool channel_weights_from_colour = false;
  std::vector<std::pair<int, int>> present;  // positions written so far (i, j)

  bool IsPresent(int i, int j) const;
  void MarkPresent(int i, int j);  // keeps `present` sorted and unique
  bool Complete() const { return int(present.size()) == grid.count(); }

  static SlabInfo FromDataset(const Dataset& dataset, int resolution);
  static SlabInfo Load(const std::string& slab_dir);  // validates slab.json
  void Save(const std::string& slab_dir) const;       // atomic
};

struct SlabPosition {
  int i = 0;
  int j = 0;
  ImageF irradiance;  // 3 channels, layout.res_x x layout.res_y, row 0 on top
  ImageF mask;        // 1 channel, 1 seen / 0 not seen
};

std::string SlabPositionPath(const std::string& slab_dir, int i, int j);
void WriteSlabPosition(const std::string& slab_dir, const SlabInfo& info, const SlabPosition& p);
// Reads and checks size/attributes against `info`.
SlabPosition ReadSlabPosition(const std::string& slab_dir, const SlabInfo& info, int i, int j);
// Positions whose EXR is in the folder, complete and of info's resolution (for watchers that do
// not trust slab.json yet, and for resumed runs: a file of another resolution left by an
// interrupted --force run, or a truncated one, is not counted).
std::vector<std::pair<int, int>> ScanSlabPositions(const std::string& slab_dir,
                                                   const SlabInfo& info);

// Every position the slab lists, E_ij and mask, by linear index j * nu + i (empty for the
// others), read on `threads` threads (ReadSlabPosition: a damaged file is exit 2).
std::vector<SlabPosition> ReadSlabPositions(const std::string& slab_dir, const SlabInfo& info,
                                            int threads);

}  // namespace lumislab
