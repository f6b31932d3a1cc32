#include "reconstruct/slab_writer.h"

#include <filesystem>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"

namespace lumislab {

SlabWriter::SlabWriter(const Dataset& dataset, int resolution, bool force, const std::string& dir,
                       const ReconstructRadiometry* radiometry)
    : dir_(dir.empty() ? dataset.Path("slab") : dir),
      info_(SlabInfo::FromDataset(dataset, resolution)) {
  info_.present.clear();
  if (radiometry) {
    info_.units = radiometry->units;
    info_.channel_weights = radiometry->channel_weights;
    info_.channel_weights_from_colour = radiometry->channel_weights_from_colour;
  }
  if (!force && std::filesystem::exists(dir_ + "/slab.json")) {
    const SlabInfo old = SlabInfo::Load(dir_);
    if (old.layout.res_x != info_.layout.res_x || old.layout.res_y != info_.layout.res_y)
      throw InputError(dir_ + "/slab.json", "resolution",
                       std::to_string(resolution) + " as asked (or use --force to redo the slab)",
                       std::to_string(old.layout.res_x) + "x" + std::to_string(old.layout.res_y));
  }
  MakeDirectories(dir_);
  if (const int n = RemoveOrphanedTemporaries(dir_))
    LogInfo(dir_, ": removed ", n, " temporary file(s) of an interrupted run");
  if (!force)
    for (const auto& [i, j] : ScanSlabPositions(dir_, info_)) info_.MarkPresent(i, j);
  info_.Save(dir_);
}

bool SlabWriter::IsPresent(int i, int j) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return info_.IsPresent(i, j);
}

bool SlabWriter::Complete() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return info_.Complete();
}

int SlabWriter::PresentCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return int(info_.present.size());
}

void SlabWriter::Write(const SlabPosition& position) {
  SlabInfo snapshot;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    snapshot = info_;
  }
  WriteSlabPosition(dir_, snapshot, position);
  std::lock_guard<std::mutex> lock(mutex_);
  info_.MarkPresent(position.i, position.j);
  info_.Save(dir_);
}

}  // namespace lumislab
