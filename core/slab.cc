#include "core/slab.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "core/json.h"
#include "core/parallel.h"

namespace lumislab {

bool SlabInfo::IsPresent(int i, int j) const {
  return std::binary_search(present.begin(), present.end(), std::make_pair(i, j));
}

void SlabInfo::MarkPresent(int i, int j) {
  const auto p = std::make_pair(i, j);
  auto it = std::lower_bound(present.begin(), present.end(), p);
  if (it == present.end() || *it != p) present.insert(it, p);
}

SlabInfo SlabInfo::FromDataset(const Dataset& dataset, int resolution) {
  SlabInfo info;
  info.distance_mm = dataset.distance_mm;
  info.grid = dataset.grid;
  info.layout = dataset.Layout(resolution);
  info.units = dataset.radiometric_scale ? "W/m^2" : "relative";
  info.filter = dataset.filter;
  return info;
}

SlabInfo SlabInfo::Load(const std::string& slab_dir) {
  const std::string file = slab_dir + "/slab.json";
  const JsonDocument doc = JsonDocument::Load(file);
  doc.CheckSchemaVersion(kSlabSchemaVersion);
  const JsonView root = doc.root();
  SlabInfo info;
  info.distance_mm = ParseDistance(root["distance_mm"]);
  info.grid = ParseGrid(root["grid"]);
  const Eigen::Vector2d window = ParseLengthPair(root["window_mm"]);
  info.layout.window_w_mm = window.x();
  info.layout.window_h_mm = window.y();
  info.layout.res_x = root["resolution"][0].IntIn(1, kMaxSlabResolution);
  info.layout.res_y = root["resolution"][1].IntIn(1, kMaxSlabResolution);
  info.units = root["units"].OneOf({"W/m^2", "lux", "relative"});
  info.filter = ParseFilterInfo(root["filter"], info.grid);
  // Optional (Rec. 709's when absent: slabs written before it, and captures without a colour
  // calibration).
  if (root.Has("channel_weights")) {
    const JsonView weights = root["channel_weights"];
    const std::vector<double> w = weights["rgb"].Numbers(3);
    info.channel_weights = {w[0], w[1], w[2]};
    if (!(std::abs(info.channel_weights.sum() - 1) < 1e-6 && info.channel_weights.maxCoeff() > 0))
      weights["rgb"].Fail("3 weights summing to 1, one of them > 0");
    info.channel_weights_from_colour = weights["from"].OneOf({"rec709", "colour"}) == "colour";
  }
  const JsonView present = root["present"];
  for (size_t k = 0; k < present.Size(); ++k) {
    if (present[k].Size() != 2) present[k].Fail("a position [i, j]");
    info.MarkPresent(present[k][0].IntIn(0, info.grid.nu - 1),
                     present[k][1].IntIn(0, info.grid.nv - 1));
  }
  return info;
}

void SlabInfo::Save(const std::string& slab_dir) const {
  nlohmann::json j;
  // Version 1 unless the weights are not Rec. 709's (an older reader ignoring them would misread).
  j["schema_version"] = channel_weights_from_colour ? kSlabSchemaVersion : 1;
  j["distance_mm"] = distance_mm;
  j["grid"] = GridJson(grid);
  j["window_mm"] = {layout.window_w_mm, layout.window_h_mm};
  j["resolution"] = {layout.res_x, layout.res_y};
  j["units"] = units;
  j["filter"] = FilterInfoJson(filter);
  j["channel_weights"] = {{"rgb", {channel_weights.x(), channel_weights.y(), channel_weights.z()}},
                          {"from", channel_weights_from_colour ? "colour" : "rec709"}};
  nlohmann::json list = nlohmann::json::array();
  for (const auto& [i, jj] : present) list.push_back({i, jj});
  j["present"] = list;
  j["complete"] = Complete();
  // Unchanged content is not rewritten: slab.json's time then says when the slab last changed
  // (pipelines redo what is older than it: pipelines/process-luminaire.sh).
  const std::string path = slab_dir + "/slab.json", text = DumpJson(j, path) + "\n";
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec) && ReadTextFile(path) == text) return;
  WriteTextAtomically(path, text);
}

std::string SlabPositionPath(const std::string& slab_dir, int i, int j) {
  return slab_dir + "/pos_" + std::to_string(i) + "_" + std::to_string(j) + ".exr";
}

void WriteSlabPosition(const std::string& slab_dir, const SlabInfo& info, const SlabPosition& p) {
  const int w = info.layout.res_x, h = info.layout.res_y;
  if (p.irradiance.width != w || p.irradiance.height != h || p.irradiance.channels != 3 ||
      p.mask.width != w || p.mask.height != h || p.mask.channels != 1)
    throw Failure("WriteSlabPosition: image size does not match the slab layout");
  ImageF out(w, h, 4);
  for (size_t k = 0; k < size_t(w) * h; ++k) {
    for (int c = 0; c < 3; ++c) out.data[k * 4 + c] = p.irradiance.data[k * 3 + c];
    out.data[k * 4 + 3] = p.mask.data[k];
  }
  ExrAttributes attr;
  attr.ints["lumislab.schema_version"] = 1;  // the EXR's own layout: unchanged since version 1
  attr.ints["lumislab.i"] = p.i;
  attr.ints["lumislab.j"] = p.j;
  attr.doubles["lumislab.distance_mm"] = info.distance_mm;
  attr.doubles["lumislab.spacing_mm"] = info.grid.spacing_mm;
  const Eigen::Vector2d c = info.grid.Centre(p.i, p.j);
  attr.doubles["lumislab.centre_x_mm"] = c.x();
  attr.doubles["lumislab.centre_y_mm"] = c.y();
  attr.doubles["lumislab.window_w_mm"] = info.layout.window_w_mm;
  attr.doubles["lumislab.window_h_mm"] = info.layout.window_h_mm;
  attr.strings["lumislab.units"] = info.units;
  attr.strings["lumislab.quantity"] = "E_ij: irradiance on M through filter (i,j), luminaire frame";
  ExrOptions options;
  options.compression = ExrCompression::kNone;  // PIZ/ZIP on noisy float data: slow, little gain
  WriteExr(SlabPositionPath(slab_dir, p.i, p.j), out, {"R", "G", "B", "mask"}, attr, options);
}

SlabPosition ReadSlabPosition(const std::string& slab_dir, const SlabInfo& info, int i, int j) {
  const std::string path = SlabPositionPath(slab_dir, i, j);
  ExrAttributes attr;
  const ImageF in = ReadExr(path, {"R", "G", "B", "mask"}, &attr);
  if (in.width != info.layout.res_x || in.height != info.layout.res_y)
    throw InputError(path, "dataWindow",
                     std::to_string(info.layout.res_x) + "x" + std::to_string(info.layout.res_y) +
                         " texels (slab.json resolution)",
                     std::to_string(in.width) + "x" + std::to_string(in.height));
  if (attr.ints.count("lumislab.i") &&
      (attr.ints["lumislab.i"] != i || attr.ints["lumislab.j"] != j))
    throw InputError(
        path, "lumislab.i/j", "position " + std::to_string(i) + "," + std::to_string(j),
        std::to_string(attr.ints["lumislab.i"]) + "," + std::to_string(attr.ints["lumislab.j"]));
  SlabPosition p;
  p.i = i;
  p.j = j;
  p.irradiance = ImageF(in.width, in.height, 3);
  p.mask = ImageF(in.width, in.height, 1);
  for (size_t k = 0; k < size_t(in.width) * in.height; ++k) {
    for (int c = 0; c < 3; ++c) {
      const float v = in.data[k * 4 + c];
      if (!std::isfinite(v)) throw InputError(path, "pixel data", "finite values", "NaN or Inf");
      p.irradiance.data[k * 3 + c] = v;
    }
    p.mask.data[k] = in.data[k * 4 + 3];
  }
  return p;
}

std::vector<std::pair<int, int>> ScanSlabPositions(const std::string& slab_dir,
                                                   const SlabInfo& info) {
  std::vector<std::pair<int, int>> found;
  for (int j = 0; j < info.grid.nv; ++j)
    for (int i = 0; i < info.grid.nu; ++i)
      if (ExrComplete(SlabPositionPath(slab_dir, i, j), info.layout.res_x, info.layout.res_y))
        found.emplace_back(i, j);
  std::sort(found.begin(), found.end());
  return found;
}

std::vector<SlabPosition> ReadSlabPositions(const std::string& slab_dir, const SlabInfo& info,
                                            int threads) {
  if (info.present.empty())
    throw InputError(slab_dir + "/slab.json", "present", "at least one position", "none");
  std::vector<SlabPosition> out(size_t(info.grid.count()));
  ParallelFor(int(info.present.size()), threads, [&](int k) {
    const auto [i, j] = info.present[k];
    out[size_t(info.grid.Index(i, j))] = ReadSlabPosition(slab_dir, info, i, j);
  });
  return out;
}

}  // namespace lumislab
