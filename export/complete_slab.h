// What lumislab-export's files and pictures need of a slab: all of it. A partial slab lacks the
// light of its missing positions, so its far field, rays and irradiance would be too low without
// a word (the preview shows partial slabs; export does not).
#pragma once

#include <filesystem>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/slab.h"

namespace lumislab {

// A dataset folder or its slab/: the folder holding slab.json (every export subcommand takes
// either).
inline std::string ResolveSlabDir(const std::string& path) {
  namespace fs = std::filesystem;
  if (fs::is_regular_file(path + "/slab.json")) return path;
  if (fs::is_regular_file(path + "/slab/slab.json")) return path + "/slab";
  throw BadInput(path + ": no slab.json there nor in " + path +
                 "/slab (--slab takes a dataset folder or its slab/)");
}

// Before any work: `out` can be written (CheckOutputPath: no link, special file or folder; its
// folder exists: exit 3), it is none of a dataset's or slab's own files (RefuseOutputOverInputs),
// and an export never replaces a file silently nor keeps an old one
// while reporting success: an existing `out` is exit 2 naming it unless `force`.
inline void CheckExportOutput(const std::string& out, bool force) {
  if (out.empty()) throw BadInput("--out: expected a file path, got an empty one");
  CheckOutputPath(out);
  RefuseOutputOverInputs(out);
  const std::filesystem::path folder = std::filesystem::absolute(out).parent_path();
  if (!std::filesystem::is_directory(folder))
    throw IoError(out, "cannot write it: the folder " + folder.string() + " does not exist");
  if (!force && std::filesystem::exists(out))
    throw BadInput(out + ": exists (--force rewrites it)");
}

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
