// The exact CPU reference of the preview (docs/method.md §4.5): what each pixel of a view sees,
// found by ray casting (Embree 3), lit by
//  * the slab through the exact model (docs/method.md §3.3): eq. 12 of Granier et al. integrated
//  over S with
//    N x N samples per basis support and visibility by one occlusion ray per sample, or
//  * point sources straight (the analytic truth of a synthetic luminaire), with the same
//    visibility.
// Slow by design; multithreaded over image rows (ParallelFor), deterministic (each pixel's sum
// runs in one fixed order whatever the thread count), stops between rows on StopRequested().
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/slab.h"
#include "lib/lightfield/scene_setup.h"

namespace lumislab {

// What the pixel (col, row) of a view sees: the first surface along its ray (back faces skipped
// in a closed room, as the preview culls them), in the luminaire frame.
struct SurfacePoint {
  bool hit = false;
  Eigen::Vector3d x{0, 0, 0};       // mm, luminaire frame
  Eigen::Vector3d n{0, 0, 1};       // unit shading normal (interpolated, as the preview's)
  Eigen::Vector3d albedo{0, 0, 0};  // interpolated per-vertex albedo
};

// The scene of a SceneSetup in Embree, with the view the preview would render of it.
class ReferenceScene {
 public:
  // The setup's mesh and pose; the camera is the preview's (orbit camera with the image's aspect,
  // or the receiver plane's orthographic view, which is square: height is then width).
  ReferenceScene(const SceneSetup& setup, int width, int height);
  ~ReferenceScene();
  ReferenceScene(const ReferenceScene&) = delete;
  ReferenceScene& operator=(const ReferenceScene&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  // Irradiance view (receiver plane: albedo x E) or Lambertian radiance (albedo / pi x E).
  double radiance_scale() const { return radiance_scale_; }
  SurfacePoint Primary(int col, int row) const;
  // True when nothing of the scene lies on the open segment between a and b (luminaire frame).
  bool Visible(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;

 private:
  struct Embree;
  std::unique_ptr<Embree> embree_;
  Mesh mesh_;
  Eigen::Isometry3d pose_;  // luminaire frame -> scene frame
  Eigen::Matrix4d scene_from_clip_;
  bool cull_back_faces_ = false;
  int width_ = 0, height_ = 0;
  double radiance_scale_ = 1.0;
};

struct ReferenceOptions {
  int samples = 4;         // N: N x N samples per basis support (1: the paper's eq. 14 sample)
  int threads = 1;         // ParallelFor threads over image rows
  bool visibility = true;  // false: V = 1 (no occlusion rays; the preview's --no-shadows)
  bool progress = true;    // a Progress bar on stderr (rows)
  // RenderPointSources over the whole luminaire frame (a luminaire folder measured from several
  // orientations, docs/method.md §4.12): sources anywhere, every receiver lit, visible when
  // nothing lies between it and the source.
  bool whole_frame = false;
};

// A rendered view: per pixel the irradiance at the surface (W/m^2, luminaire frame; 0 where no
// surface, behind S or unlit) and the image the preview writes (radiance_scale x albedo x E).
struct ReferenceImage {
  ImageF irradiance;
  ImageF image;
  bool complete = true;  // false: stopped (StopRequested) before every row was done
};

// The slab of a view: E_ij of each position by linear index j * nu + i (3 channels, the layout
// of info); an empty image is an absent position (it gives no light, as in the preview).
// The exact model: for each position, N x N sample points (u, v) over the support [-h, h]^2 of
// Phi_ij, the tensor product of BellQuadrature, so that the weights of one position integrate
// Phi_ij exactly (h^2; N = 1: one sample at c_ij with weight h^2, the paper's eq. 14).
// A sample (u, v) with weight w, delta = x - (u, v, 0), and (s, t) where the ray from (u, v, 0)
// through x meets M, adds
//   (w / h^2) (R^2 / cos^2 theta) E_ij(s, t) * cos(theta) cos(theta') / |delta|^2 * V
//   = (w / h^2) E_ij(s, t) d^2 |delta| cos(theta') / delta_z^3 * V      (W/m^2)
// (R^2 / cos^2 theta = R^4 / d^2 = d^2 |delta|^4 / delta_z^4; the mm^2 of 1/g and the mm^-2 of
// the solid angle cancel), E_ij bilinear in the texels and zero outside the slab window, V one
// occlusion ray from x to (u, v, 0). On the plane z = d with normal -z this is w / h^2 E_ij(x)
// for every sample: the exact model gives sum_ij E_ij(x) at any N (docs/method.md §4.5).
ReferenceImage RenderReference(const ReferenceScene& view, const SlabInfo& info,
                               const std::vector<ImageF>& irradiance,
                               const ReferenceOptions& options);

// E_ij of every position slab.json lists, by linear index j * nu + i (empty images for the
// others), read on `threads` threads: the input of RenderReference. A listed position that is
// missing or damaged is exit 2 naming its file; a slab without positions is exit 2.
std::vector<ImageF> ReadSlabIrradiance(const std::string& slab_dir, const SlabInfo& info,
                                       int threads);

// A point light behind S (luminaire frame, z < 0) with its intensity (W/sr, RGB) towards a unit
// direction: the synthetic luminaire's emitters (lib/synthetic) handed in without this library
// depending on them.
struct PointSource {
  Eigen::Vector3d position_mm;
  std::function<Eigen::Vector3d(const Eigen::Vector3d& direction)> intensity_w_sr;
};

// Irradiance straight from point sources: I(w) cos(theta') / r^2 per source, for points in front
// of S (x_z > 0) only, visible when nothing lies between x and the point where the ray to the
// source crosses S (the same visibility as the slab's light: the luminaire's own side of S is not
// part of the scene's shadows); with options.whole_frame, any source and receiver, visibility to
// the source itself. options.samples is not used.
ReferenceImage RenderPointSources(const ReferenceScene& view,
                                  const std::vector<PointSource>& sources,
                                  const ReferenceOptions& options);

// Sample offsets (units of h, in (-1, 1)) and weights (sum 1) of the 1D rule of
// RenderReference: the bell's support cut into N equal cells (strata), each sampled once at its
// centroid under phi with the weight of its exact integral of phi. Exact for integrands linear
// in each cell; N = 1 is one sample at the centre with weight 1. (Plain cell centres weighted by
// phi are not monotone: N = 2 then errs on the second moment as much as N = 1, with the
// opposite sign.)
void BellQuadrature(int n, std::vector<double>* offsets, std::vector<double>* weights);

}  // namespace lumislab
