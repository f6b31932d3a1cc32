// What lumislab-export's files and pictures need of a slab: all of it. A partial slab lacks the
// light of its missing positions, so its far field, rays and irradiance would be too low without
// a word (the preview shows partial slabs; export does not).
#pragma once

#include <string>

#include "core/error.h"
#include "core/slab.h"

namespace lumislab {

// BadInput naming <slab_dir>/slab.json and `present` unless every position is there.
inline void RequireCompleteSlab(const SlabInfo& info, const std::string& slab_dir) {
  if (info.Complete()) return;
  throw InputError(slab_dir + "/slab.json", "present",
                   "every position of the " + std::to_string(info.grid.nu) + " x " +
                       std::to_string(info.grid.nv) +
                       " grid (a partial slab lacks the light of the others: finish it with "
                       "lumislab-reconstruct)",
                   std::to_string(info.present.size()) + " position(s)");
}

}  // namespace lumislab
