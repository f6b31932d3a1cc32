// Light merging (RenderOptions::merge_group): the merged textures of blocks of positions and the
// shortcuts' light passes, which also serve shadow-map sharing.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "preview/renderer.h"
#include "preview/renderer_gl.h"

namespace lumislab {

// The merged texture of a block G (centre c̄) for distant receivers: a receiver at depth z looks
// member k up at s_k = x d/z + c_k (1 - d/z) and the merged light at s̄ = x d/z + c̄ (1 - d/z), so
//     M_G(s) = Σ_k E'_k(s + (c_k - c̄))
// equals the members' sum at z = ∞ and is off by E'_k displaced by e_k = (c_k - c̄) d/z at z:
// |error| ≤ (r d / z) Σ_k max|∇E'_k| (r the block's radius). The spot factor cosθ cosθ'/δ² of
// c̄ instead of c_k changes by at most 5 r/δ ≤ 5 r/z of the largest term (cosθ and cosθ' by r/δ
// and 2r/δ, 1/δ² by 2r/δ). Relative to the block's peak P = max M_G the error is at most
//     (r / z) (d Σ_k max|∇E'_k| / P + 5),
// so receivers at z ≥ z_G = r (d Σ_k max|∇E'_k| / P + 5) / merge_error use the merged light
// (per channel, the largest z_G). The merged light's visibility is the mean of its members'
// shadow-map tests (each at its own map: soft shadows stay as soft), so
//     Σ_k V_k E'_k  ≈  (1/n Σ_k V_k) Σ_k E'_k,
// exact where the members see the receiver alike or their E' are alike.
void Renderer::MergedTexture(int group) {
  const SamplingGrid& grid = info_.grid;
  const int g = options_.merge_group, bu = (grid.nu + g - 1) / g;
  const std::vector<int> members = BlockMembers(grid, g, group % bu, group / bu);
  double radius = 0;
  const Eigen::Vector2d mean = MeanCentre(grid, members, &radius);
  const int rx = info_.layout.res_x, ry = info_.layout.res_y;
  const double w = info_.layout.window_w_mm, h = info_.layout.window_h_mm;
  ImageF merged(rx, ry, 3);
  double gradient[3] = {0, 0, 0};
  for (int l : members) {
    const ImageF& e = intensity_[l];
    const Eigen::Vector2d c = grid.Centre(l % grid.nu, l / grid.nu) - mean;
    // Texel shift of E'_k: u = s/W + 1/2 (columns), v = 1/2 - t/H (rows).
    const double du = c.x() / w * rx, dv = -c.y() / h * ry;
    for (int y = 0; y < ry; ++y) {
      const double qy = y + 0.5 + dv;   // in texels from the window's top edge
      if (qy < 0 || qy > ry) continue;  // outside the window: the member gives no light
      const double fy = std::clamp(qy - 0.5, 0.0, double(ry - 1));
      const int y0 = std::min(int(fy), ry - 1), y1 = std::min(y0 + 1, ry - 1);
      const double ty = fy - y0;
      for (int x = 0; x < rx; ++x) {
        const double qx = x + 0.5 + du;
        if (qx < 0 || qx > rx) continue;
        const double fx = std::clamp(qx - 0.5, 0.0, double(rx - 1));
        const int x0 = std::min(int(fx), rx - 1), x1 = std::min(x0 + 1, rx - 1);
        const double tx = fx - x0;
        for (int ch = 0; ch < 3; ++ch) {
          merged.at(x, y, ch) +=
              float((1 - ty) * ((1 - tx) * e.at(x0, y0, ch) + tx * e.at(x1, y0, ch)) +
                    ty * ((1 - tx) * e.at(x0, y1, ch) + tx * e.at(x1, y1, ch)));
        }
      }
    }
    // max |∇E'_k| per mm from neighbouring texels.
    for (int ch = 0; ch < 3; ++ch) {
      double m = 0;
      for (int y = 0; y < ry; ++y) {
        for (int x = 0; x < rx; ++x) {
          if (x + 1 < rx) m = std::max(m, std::abs(e.at(x + 1, y, ch) - e.at(x, y, ch)) * rx / w);
          if (y + 1 < ry) m = std::max(m, std::abs(e.at(x, y + 1, ch) - e.at(x, y, ch)) * ry / h);
        }
      }
      gradient[ch] += m;
    }
  }
  double z = 0;
  for (int ch = 0; ch < 3; ++ch) {
    double peak = 0;
    for (int y = 0; y < ry; ++y)
      for (int x = 0; x < rx; ++x) peak = std::max(peak, double(std::abs(merged.at(x, y, ch))));
    if (peak > 0) z = std::max(z, radius * (info_.distance_mm * gradient[ch] / peak + 5));
  }
  const int layer = grid.count() + group;
  glBindTexture(GL_TEXTURE_2D_ARRAY, gl_->intensity);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, layer, rx, ry, 1, GL_RGB, GL_FLOAT,
                  merged.data.data());
  merged_z_[group] = z;
  merged_valid_[group] = true;
}

// The shortcuts' light passes: with merging, the blocks whose members all are added now become
// a merged light for receivers at least z_far deep (the largest of their z_G) and their members
// shade the nearer ones; the other positions shade all.
void Renderer::ShortcutPasses(const std::vector<int>& todo) {
  const SamplingGrid& grid = info_.grid;
  auto entry = [&](int l) {
    LightEntry e;
    e.centre = grid.Centre(l % grid.nu, l / grid.nu);
    e.layer = l;
    e.shadow_centre = shadow_centre_[l];
    e.shadow_layer = shadow_layer_[l];
    e.support = support_[l];
    return e;
  };
  std::vector<LightEntry> near_only, both, far_only;
  std::vector<bool> adding(grid.count(), false);
  for (int l : todo) adding[l] = true;
  std::vector<bool> merged(grid.count(), false);
  double z_far = 0;
  const int g = options_.merge_group;
  if (g > 1) {
    const int bu = (grid.nu + g - 1) / g, bv = (grid.nv + g - 1) / g;
    if (int(merged_valid_.size()) != bu * bv || merged_group_size_ != g) {
      merged_valid_.assign(bu * bv, false);
      merged_z_.assign(bu * bv, 0);
      merged_group_size_ = g;
    }
    for (int bj = 0; bj < bv; ++bj) {
      for (int bi = 0; bi < bu; ++bi) {
        const std::vector<int> members = BlockMembers(grid, g, bi, bj);
        if (members.size() < 2) continue;
        if (!std::all_of(members.begin(), members.end(), [&](int l) { return adding[l]; }))
          continue;
        const int group = bj * bu + bi;
        if (!merged_valid_[group]) MergedTexture(group);
        double radius = 0;
        LightEntry e;
        e.centre = MeanCentre(grid, members, &radius);
        e.layer = grid.count() + group;
        int nearest = members[0];
        for (int l : members) {
          if ((grid.Centre(l % grid.nu, l / grid.nu) - e.centre).norm() <
              (grid.Centre(nearest % grid.nu, nearest / grid.nu) - e.centre).norm())
            nearest = l;
        }
        e.shadow_centre = shadow_centre_[nearest];
        e.shadow_layer = shadow_layer_[nearest];
        e.span_begin = int(near_only.size());  // the members follow at this index
        e.span_count = int(members.size());
        // The summed texture's support: the members' (their rectangles' bounding box).
        e.support = {info_.layout.res_x, info_.layout.res_y, 0, 0};
        for (int l : members) {
          const std::array<int, 4>& m = support_[l];
          if (m[0] >= m[2] || m[1] >= m[3]) continue;
          e.support = {std::min(e.support[0], m[0]), std::min(e.support[1], m[1]),
                       std::max(e.support[2], m[2]), std::max(e.support[3], m[3])};
        }
        far_only.push_back(e);
        z_far = std::max(z_far, merged_z_[group] / options_.merge_error);
        for (int l : members) {
          near_only.push_back(entry(l));
          merged[l] = true;
        }
      }
    }
  }
  for (int l : todo)
    if (!merged[l]) both.push_back(entry(l));
  if (far_only.empty()) z_far = std::numeric_limits<double>::infinity();
  state_.merged_lights = int(far_only.size());
  state_.z_merge = z_far;
  const size_t total = near_only.size() + both.size() + far_only.size();
  if (total <= size_t(kShortcutLightsPerPass)) {
    std::vector<LightEntry> entries = near_only;
    entries.insert(entries.end(), both.begin(), both.end());
    entries.insert(entries.end(), far_only.begin(), far_only.end());
    EntriesPass(entries, true, int(near_only.size() + both.size()), int(near_only.size()), z_far);
    return;
  }
  // Too many for one pass: every position on its own, in passes of kShortcutLightsPerPass.
  state_.merged_lights = 0;
  for (size_t start = 0; start < todo.size(); start += kShortcutLightsPerPass) {
    const size_t end = std::min(todo.size(), start + kShortcutLightsPerPass);
    std::vector<LightEntry> entries;
    for (size_t k = start; k < end; ++k) entries.push_back(entry(todo[k]));
    EntriesPass(entries, true, int(entries.size()), int(entries.size()),
                std::numeric_limits<double>::infinity());
  }
}

}  // namespace lumislab
