#include "core/slab_compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"

namespace lumislab {

std::string SlabComparison::Summary() const {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "%zu positions: relative L2 error over lit texels max %.3f %%, median %.3f %%, "
                "overall %.3f %%",
                positions.size(), 100 * max_relative_l2, 100 * median_relative_l2,
                100 * overall_relative_l2);
  int unseen = 0, lit = 0;
  for (const auto& p : positions) unseen += p.unseen_lit_texels, lit += p.lit_texels;
  std::string summary = buf;
  if (unseen > 0)
    summary += "; " + std::to_string(unseen) + " of " + std::to_string(lit) +
               " lit texels not seen (mask 0)";
  return summary;
}

SlabComparison CompareSlabs(const std::string& slab_dir, const std::string& reference_dir,
                            double lit_fraction) {
  const SlabInfo info = SlabInfo::Load(slab_dir);
  const SlabInfo ref_info = SlabInfo::Load(reference_dir);
  if (info.layout.res_x != ref_info.layout.res_x || info.layout.res_y != ref_info.layout.res_y)
    throw BadInput(slab_dir + "/slab.json: resolution differs from the reference " + reference_dir +
                   " (reconstruct with --resolution " + std::to_string(ref_info.layout.res_x) +
                   ")");
  if (info.grid.nu != ref_info.grid.nu || info.grid.nv != ref_info.grid.nv)
    throw BadInput(slab_dir + "/slab.json: grid differs from the reference " + reference_dir);
  // Lux slabs are compared in luminance (each slab's channel_weights): a lux slab's photometric
  // quantity is its luminance, its RGB is the camera's, and a synthetic truth of spectral
  // emitters holds grey luminance (lib/synthetic/truth.h WriteTruthSlab). Others channel by
  // channel.
  const bool luminance = info.units == "lux" && ref_info.units == "lux";
  const int channels = luminance ? 1 : 3;
  auto value = [&](const SlabInfo& si, const SlabPosition& sp, size_t k, int c) -> double {
    const float* rgb = &sp.irradiance.data[k * 3];
    if (!luminance) return rgb[c];
    return si.channel_weights[0] * rgb[0] + si.channel_weights[1] * rgb[1] +
           si.channel_weights[2] * rgb[2];
  };
  SlabComparison out;
  double total_err2 = 0, total_ref2 = 0;
  for (const auto& [i, j] : info.present) {
    if (!ref_info.IsPresent(i, j)) continue;
    const SlabPosition p = ReadSlabPosition(slab_dir, info, i, j);
    const SlabPosition r = ReadSlabPosition(reference_dir, ref_info, i, j);
    float peak = 0;
    for (float v : r.irradiance.data) peak = std::max(peak, std::abs(v));
    PositionError e;
    e.i = i;
    e.j = j;
    double err2 = 0, ref2 = 0;
    const size_t n = size_t(info.layout.res_x) * info.layout.res_y;
    for (size_t k = 0; k < n; ++k) {
      float mag = 0;
      for (int c = 0; c < 3; ++c) mag = std::max(mag, std::abs(r.irradiance.data[k * 3 + c]));
      if (mag < lit_fraction * peak || mag == 0) continue;
      ++e.lit_texels;
      if (p.mask.data[k] < 0.5f) {
        ++e.unseen_lit_texels;
        continue;
      }
      for (int c = 0; c < channels; ++c) {
        const double ref = value(ref_info, r, k, c);
        const double d = value(info, p, k, c) - ref;
        err2 += d * d;
        ref2 += ref * ref;
        e.max_abs = std::max(e.max_abs, std::abs(d));
      }
    }
    // Lit in the reference but nothing of it seen in the slab: nothing was recovered (100 %),
    // not "no error".
    e.relative_l2 = ref2 > 0 ? std::sqrt(err2 / ref2) : (e.lit_texels > 0 ? 1.0 : 0.0);
    total_err2 += err2;
    total_ref2 += ref2;
    out.positions.push_back(e);
  }
  if (out.positions.empty())
    throw BadInput(slab_dir + ": no position in common with the reference " + reference_dir);
  std::vector<double> errs;
  for (const auto& e : out.positions) errs.push_back(e.relative_l2);
  std::sort(errs.begin(), errs.end());
  out.max_relative_l2 = errs.back();
  out.median_relative_l2 = errs[errs.size() / 2];
  out.overall_relative_l2 = total_ref2 > 0 ? std::sqrt(total_err2 / total_ref2) : 0;
  return out;
}

}  // namespace lumislab
