#include "calibrate/orientations/far_field_grid.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "lib/lightfield/far_field.h"

namespace lumislab {

Eigen::Vector3d FarFieldGrid::Direction(int col, int row) const {
  return Eigen::Vector3d(-x_max + col * StepX(), -y_max + row * StepY(), 1.0).normalized();
}

bool FarFieldGrid::SeenAround(const Eigen::Vector3d& w) const {
  if (!(w.z() > 1e-6)) return false;
  double col = 0, row = 0;
  GridCoordinates(w.data(), &col, &row);
  const int c0 = int(std::floor(col)) - 1, r0 = int(std::floor(row)) - 1;
  if (c0 < 0 || r0 < 0 || c0 + 3 >= nx || r0 + 3 >= ny) return false;
  for (int r = r0; r < r0 + 4; ++r)
    for (int c = c0; c < c0 + 4; ++c)
      if (!seen[size_t(r) * nx + c]) return false;
  return true;
}

FarFieldGrid SampleFarFieldGrid(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                                const OrientationCone& cone, double nodes_per_tan, int threads) {
  LUMISLAB_CHECK(cone.distance_mm > 0 && nodes_per_tan > 0, "a cone and a grid density");
  FarFieldGrid grid;
  // Two nodes beyond the cone on each side, so that the interpolation's 4 x 4 stencil reaches
  // the cone's edge (the nodes outside are unseen).
  const double tx = cone.half_w_mm / cone.distance_mm, ty = cone.half_h_mm / cone.distance_mm;
  grid.nx = std::max(8, int(std::ceil(2 * tx * nodes_per_tan)) + 5);
  grid.ny = std::max(8, int(std::ceil(2 * ty * nodes_per_tan)) + 5);
  grid.x_max = tx * (grid.nx - 1) / (grid.nx - 5);
  grid.y_max = ty * (grid.ny - 1) / (grid.ny - 5);
  const size_t count = size_t(grid.nx) * grid.ny;
  grid.values.assign(count, 0.0);
  grid.seen.assign(count, 0);
  std::vector<Eigen::Vector3d> directions(count);
  for (size_t k = 0; k < count; ++k)
    directions[k] = grid.Direction(int(k % size_t(grid.nx)), int(k / size_t(grid.nx)));
  FarFieldOptions options;
  options.threads = threads;
  FarFieldAt far = ComputeFarFieldAt(info, positions, directions, options);
  grid.values = std::move(far.values);
  grid.seen = std::move(far.seen);
  return grid;
}

}  // namespace lumislab
