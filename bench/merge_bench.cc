// merge_bench: the cost of the merged light field (docs/method.md §4.12) against the number of
// orientations K: the merged far field on the exports' full-sphere grid (C every 5 degrees, gamma
// every 2.5 degrees over 0-180, N x N = 4 x 4 quadrature: `ies`'s default) and 100 000 merged
// rays (`tm25`), and the process's peak memory (VmHWM) after each K. Every orientation holds a
// copy of one truth slab of the built-in scene "full-sphere" (9 x 7 positions, h = 5 mm, d =
// 750 mm, a 2 m screen, `resolution` texels): the cost depends on the slabs' size and the poses,
// not on their light. The poses turn the luminaire so that K directions spread over the sphere
// (a Fibonacci sphere; K = 6: the cube's faces) face the screen. Ks ascend, so VmHWM after K is
// the peak of that K (its slabs and the merge's working set; the earlier Ks used less).
// Usage: merge_bench [threads (0: all cores)] [resolution] [K list, comma separated]
#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/dataset.h"
#include "core/geometry.h"
#include "core/luminaire_set.h"
#include "core/parallel.h"
#include "lib/lightfield/merged_far_field.h"
#include "lib/synthetic/scene.h"
#include "lib/synthetic/truth.h"

namespace lumislab {
namespace {

double PeakMemoryMiB() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024;
  return 0;
}

// The rotation that takes unit direction a (luminaire frame) to +z (capture frame).
Eigen::Matrix3d FacingScreen(const Eigen::Vector3d& a) {
  const Eigen::Vector3d z(0, 0, 1);
  const Eigen::Vector3d axis = a.cross(z);
  const double angle = std::atan2(axis.norm(), a.dot(z));
  if (axis.norm() < 1e-12)
    return a.z() > 0 ? Eigen::Matrix3d::Identity() : RotationZyxDegrees({180, 0, 0});
  return RotationFromVector(axis.normalized() * angle);
}

std::vector<Eigen::Vector3d> Directions(int k) {
  if (k == 6) return {{0, 0, 1}, {1, 0, 0}, {0, 0, -1}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
  std::vector<Eigen::Vector3d> out;
  const double golden = kPi * (3 - std::sqrt(5.0));
  for (int i = 0; i < k; ++i) {
    const double z = k == 1 ? 1 : 1 - 2 * (i + 0.5) / k, r = std::sqrt(1 - z * z);
    out.push_back({r * std::cos(golden * i), r * std::sin(golden * i), z});
  }
  return out;
}

int Main(int argc, char** argv) {
  const int threads = ResolveThreads(argc > 1 ? std::atoi(argv[1]) : 0);
  const int resolution = argc > 2 ? std::atoi(argv[2]) : 96;
  std::vector<int> ks = {1, 2, 6, 12, 24};
  if (argc > 3) {
    ks.clear();
    std::stringstream list(argv[3]);
    for (std::string item; std::getline(list, item, ',');) ks.push_back(std::stoi(item));
  }
  const SynthScene scene = LoadScene("full-sphere");
  SlabInfo info = DefaultSlabInfo(9, 7, 5, resolution);
  info.layout.window_w_mm = info.layout.window_h_mm = 2000;
  const Luminaire turned =
      scene.luminaire.Turned(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, -10));
  std::vector<SlabPosition> positions(size_t(info.grid.count()));
  ParallelFor(info.grid.count(), threads, [&](int k) {
    positions[size_t(k)] = TruthPosition(turned, info, k % info.grid.nu, k / info.grid.nu);
  });
  const OrientationCone cone = ConeOfSlab(info);
  std::vector<double> c, gamma;
  for (int k = 0; k < 72; ++k) c.push_back(5.0 * k);
  for (int k = 0; k <= 72; ++k) gamma.push_back(2.5 * k);
  std::printf(
      "%d threads, 9 x 7 positions at %d x %d texels, far field %zu x %zu directions "
      "(N = 4), 100000 rays\n\n",
      threads, resolution, resolution, c.size(), gamma.size());
  std::printf("| K | far field (s) | rays (s) | peak memory (MiB) | seen share |\n");
  std::printf("|---|---|---|---|---|\n");
  for (int k : ks) {
    std::vector<PosedSlab> slabs;
    const std::vector<Eigen::Vector3d> axes = Directions(k);
    for (int o = 0; o < k; ++o) {
      PosedSlab s;
      s.name = "o" + std::to_string(o);
      s.info = info;
      s.positions = positions;  // a copy each: the memory of K slabs
      s.capture_from_luminaire = FacingScreen(axes[size_t(o)]);
      s.centre_mm = Eigen::Vector3d(0, 0, -10);
      s.cone = cone;
      slabs.push_back(std::move(s));
    }
    FarFieldOptions options;
    options.samples = 4;
    options.threads = threads;
    auto t0 = std::chrono::steady_clock::now();
    const MergedFarField merged = ComputeMergedFarField(slabs, c, gamma, options);
    auto t1 = std::chrono::steady_clock::now();
    const MergedRays rays = SampleMergedRays(slabs, 100000, 1, threads);
    auto t2 = std::chrono::steady_clock::now();
    const double seen = 1 - double(merged.ff.unseen) / merged.ff.values.size();
    std::printf("| %d | %.2f | %.2f | %.0f | %.3f |\n", k,
                std::chrono::duration<double>(t1 - t0).count(),
                std::chrono::duration<double>(t2 - t1).count(), PeakMemoryMiB(), seen);
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace
}  // namespace lumislab

int main(int argc, char** argv) { return lumislab::Main(argc, argv); }
