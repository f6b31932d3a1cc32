// Writes positions of one slab folder from several threads; slab.json has exactly one writer.
#pragma once

#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "core/dataset.h"
#include "core/slab.h"

namespace lumislab {

class SlabWriter {
 public:
  // Opens `dir` (default: dataset/slab): keeps positions whose EXR already exists (unless
  // `force`), rejects an existing slab of another resolution unless `force`; writes a valid
  // slab.json right away. `units`: the slab's units when not dataset.json's (calib/scale.json:
  // "W/m^2" or "lux"; "relative"); "" takes them from the dataset.
  SlabWriter(const Dataset& dataset, int resolution, bool force, const std::string& dir = "",
             const std::string& units = "");

  // Unlocked: read its layout and grid only while positions are written (`present` changes
  // under the lock; ask IsPresent, Complete, PresentCount).
  const SlabInfo& info() const { return info_; }
  const std::string& dir() const { return dir_; }
  bool IsPresent(int i, int j) const;
  bool Complete() const;
  int PresentCount() const;
  // Writes slab/pos_<i>_<j>.exr atomically, then marks it present in slab.json.
  void Write(const SlabPosition& position);

 private:
  std::string dir_;
  SlabInfo info_;  // layout/grid fixed at construction; `present` guarded by mutex_
  mutable std::mutex mutex_;
};

}  // namespace lumislab
