// The light slab on disk (docs/formats.md): slab/slab.json + slab/pos_<i>_<j>.exr.
// Each position stores E_ij (irradiance on M, luminaire frame, W m^-2 or relative) as float RGB
// plus a "mask" channel (1 = seen, 0 = not seen; unseen texels hold 0), in the texel layout of
// SlabLayout. Metadata is repeated as EXR attributes so one file stands on its own.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/dataset.h"
#include "core/grid.h"
#include "core/image.h"

namespace lumislab {

constexpr int kSlabSchemaVersion = 1;
// Texels per side of a slab: what ReadExr reads back (kMaxExrPixels = 8192^2).
constexpr int kMaxSlabResolution = 8192;

struct SlabInfo {
  double distance_mm = 0;
  SamplingGrid grid;
  SlabLayout layout;
  std::string units = "W/m^2";  // or "lux" (calib/scale.json from a lux meter), "relative"
  FilterInfo filter;
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
