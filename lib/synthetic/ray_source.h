// A TM-25 ray file as a synthetic source (scene emitter "rays", docs/formats.md §10, §17): the
// file's rays placed in the luminaire frame, and the splat map that turns rays into irradiance
// on a plane. A ray is a sample of the light field, so the capture deposits each ray's flux on a
// fine lattice of the receiving plane with a tent kernel and reads the lattice back bilinearly:
// the photos, the truth slab and the calibration captures all read the same map
// (PlaneLight in luminaire.h), so the truth is exactly what the photos hold.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

namespace lumislab {

// One ray in the luminaire frame: origin on or behind S (z <= 0), unit direction towards +z
// (k_z > 0), flux in the file's unit (lm or W).
struct SourceRay {
  Eigen::Vector3d origin_mm;
  Eigen::Vector3d direction;
  double flux = 0;
};

struct RaySource {
  std::string file;                                        // the path it was read from
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();   // the file's origin, luminaire frame
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();  // R = Rz Ry Rx of the file's axes
  Eigen::Vector3d rgb = Eigen::Vector3d::Ones();           // W per channel per unit of a ray's flux
  double cell_mm = 0;       // the splat lattice's spacing on the receiving plane (0: unresolved)
  bool photometric = true;  // the file's rays carry lm (else W)
  // The rays that reach S, luminaire frame (shared: a scene is copied per thread).
  std::shared_ptr<const std::vector<SourceRay>> rays;
  size_t file_rays = 0;      // rays in the file
  size_t skipped_away = 0;   // k_z <= 0 in the luminaire frame: never reach S
  size_t skipped_front = 0;  // origin in front of S (z > 0): they do not pass the slide
  double flux = 0;           // sum of the kept rays' flux (file unit)

  // Reads the file (ReadTm25: BadInput naming it and the field), turns and moves its rays into
  // the luminaire frame (x' = R x + position, k' = R k) and keeps those that cross S from
  // behind; the others are counted and logged. No ray left: BadInput naming the file.
  static RaySource Load(const std::string& file, const Eigen::Vector3d& position_mm,
                        const Eigen::Vector3d& rotation_deg, const Eigen::Vector3d& rgb,
                        double cell_mm);
};

// A splat lattice on a plane: nodes at (k cell, l cell) (aligned to 0, so a point's value does
// not depend on the region asked for), covering [x0, x1] x [y0, y1] plus one node each side.
// Add deposits a flux bilinearly (tent kernel) on the four nodes around its point; At reads the
// nodes bilinearly and divides by the cell's area: irradiance in W/m^2 (flux in W, mm lattice),
// whose integral over the plane is the flux deposited.
class RaySplat {
 public:
  RaySplat(double x0_mm, double x1_mm, double y0_mm, double y1_mm, double cell_mm, int channels);
  void Add(double x_mm, double y_mm, const double* flux);       // `channels` values
  void At(double x_mm, double y_mm, double* irradiance) const;  // `channels` values
  int channels() const { return channels_; }

 private:
  // Calls f(node index into nodes_, tent weight) for the up-to-4 lattice nodes around (x, y)
  // that lie in the region (none for a point beyond 1e15 cells). Add and At share it.
  template <typename F>
  void ForEachNode(double x_mm, double y_mm, F f) const;

  double cell_;
  int channels_;
  long k0_, l0_;  // lattice index of node (0, 0)
  int nx_, ny_;
  std::vector<double> nodes_;  // (l - l0) nx + (k - k0), channels each
};

// Default splat cell of a scene: the larger screen side / 200 (6 mm on the 1.2 m screen).
constexpr double kRayCellsPerScreen = 200;
// Finest splat cell a scene may ask for: the larger screen side / 4096.
constexpr double kMaxRayCellsPerScreen = 4096;

}  // namespace lumislab
