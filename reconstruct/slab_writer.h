// Writes positions of one slab folder from several threads; slab.json has exactly one writer.
#pragma once

#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "core/dataset.h"
#include "core/slab.h"
#include "reconstruct/radiometry.h"

namespace lumislab {

class SlabWriter {
 public:
  // Opens `dir` (default: dataset/slab): keeps positions whose EXR already exists (unless
  // `force`), rejects an existing slab of another resolution unless `force`; writes a valid
  // slab.json right away. `radiometry`: the slab's units (calib/scale.json: "W/m^2" or "lux";
  // "relative") and channel weights (calib/scale.json's); null takes the units from the dataset
  // and Rec. 709's weights.
  SlabWriter(const Dataset& dataset, int resolution, bool force, const std::string& dir = "",
             const ReconstructRadiometry* radiometry = nullptr);

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
