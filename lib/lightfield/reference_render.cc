#include "lib/lightfield/reference_render.h"

#include <embree3/rtcore.h>

#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>

#include "core/basis.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/stop_signal.h"
#include "lib/lightfield/camera.h"
#include "lib/lightfield/light_field.h"

namespace lumislab {

// The Embree device and the committed scene (scene frame, the mesh's triangles as they are).
struct ReferenceScene::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Embree() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

// Embree reports errors through the device; turn the first one into a Failure (exit 1).
void CheckDevice(RTCDevice device, const char* what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error != RTC_ERROR_NONE)
    throw Failure(std::string("Embree: ") + what + " failed (error " + std::to_string(error) + ")");
}

// Relative and absolute lengths that keep a ray off the surface it starts on: the scene's
// vertices are floats, so a hit point is only known to ~1e-7 of its coordinates.
double SurfaceOffset(const Eigen::Vector3d& p) { return 1e-3 + 2e-6 * p.cwiseAbs().maxCoeff(); }

Eigen::Vector3d Unproject(const Eigen::Matrix4d& scene_from_clip, double x, double y, double z) {
  const Eigen::Vector4d p = scene_from_clip * Eigen::Vector4d(x, y, z, 1);
  return p.head<3>() / p.w();
}

}  // namespace

ReferenceScene::ReferenceScene(const SceneSetup& setup, int width, int height)
    : embree_(std::make_unique<Embree>()),
      mesh_(setup.mesh),
      pose_(setup.pose),
      cull_back_faces_(setup.closed_room),
      width_(width),
      height_(setup.plane ? width : height),
      radiance_scale_(setup.plane ? 1.0 : 1.0 / kPi) {
  LUMISLAB_CHECK(width_ > 0 && height_ > 0, "reference image size");
  LUMISLAB_CHECK(mesh_.triangles() > 0, "reference scene without triangles");
  const Eigen::Matrix4f clip_from_scene = setup.plane
                                              ? PlaneView(setup.plane_z, setup.extent)
                                              : OrbitCamera(setup, double(width_) / height_);
  scene_from_clip_ = clip_from_scene.cast<double>().inverse();

  embree_->device = rtcNewDevice(nullptr);
  if (!embree_->device) throw Failure("Embree: cannot create a device");
  embree_->scene = rtcNewScene(embree_->device);
  rtcSetSceneFlags(embree_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(embree_->scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geometry = rtcNewGeometry(embree_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  const size_t vertices = mesh_.positions.size();
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices));
  auto* index = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                              3 * sizeof(unsigned), mesh_.triangles()));
  CheckDevice(embree_->device, "allocating the scene buffers");
  for (size_t k = 0; k < vertices; ++k)
    for (int c = 0; c < 3; ++c) v[3 * k + c] = mesh_.positions[k][c];
  for (size_t k = 0; k < 3 * mesh_.triangles(); ++k) index[k] = unsigned(k);
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(embree_->scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(embree_->scene);
  CheckDevice(embree_->device, "building the scene");
}

ReferenceScene::~ReferenceScene() = default;

SurfacePoint ReferenceScene::Primary(int col, int row) const {
  // The pixel centre's ray from the near to the far clip plane (row 0 on top, as Renderer::Read).
  const double nx = 2.0 * (col + 0.5) / width_ - 1.0;
  const double ny = 1.0 - 2.0 * (row + 0.5) / height_;
  const Eigen::Vector3d from = Unproject(scene_from_clip_, nx, ny, -1);
  const Eigen::Vector3d to = Unproject(scene_from_clip_, nx, ny, 1);
  const Eigen::Vector3d dir = to - from;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  float tnear = 0;
  SurfacePoint out;
  for (int attempt = 0; attempt < 256; ++attempt) {  // skips back faces one at a time
    RTCRayHit rh{};
    rh.ray.org_x = float(from.x());
    rh.ray.org_y = float(from.y());
    rh.ray.org_z = float(from.z());
    rh.ray.dir_x = float(dir.x());
    rh.ray.dir_y = float(dir.y());
    rh.ray.dir_z = float(dir.z());
    rh.ray.tnear = tnear;
    rh.ray.tfar = 1.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(embree_->scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return out;
    const size_t k = 3 * size_t(rh.hit.primID);
    const Eigen::Vector3d a = mesh_.positions[k].cast<double>();
    const Eigen::Vector3d b = mesh_.positions[k + 1].cast<double>();
    const Eigen::Vector3d c = mesh_.positions[k + 2].cast<double>();
    // GL's front faces are counter-clockwise on screen: (b - a) x (c - a) towards the eye.
    if (cull_back_faces_ && (b - a).cross(c - a).dot(dir) > 0) {
      tnear = std::nextafter(rh.ray.tfar, 2.0f);
      continue;
    }
    const double bu = rh.hit.u, bv = rh.hit.v, bw = 1.0 - bu - bv;
    const Eigen::Vector3d p = bw * a + bu * b + bv * c;
    const Eigen::Vector3d n =
        (bw * mesh_.normals[k] + bu * mesh_.normals[k + 1] + bv * mesh_.normals[k + 2])
            .cast<double>();
    out.hit = true;
    out.x = pose_.inverse() * p;
    out.n = (pose_.linear().transpose() * n).normalized();
    out.albedo =
        (bw * mesh_.albedo[k] + bu * mesh_.albedo[k + 1] + bv * mesh_.albedo[k + 2]).cast<double>();
    return out;
  }
  return out;
}

bool ReferenceScene::Visible(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  const Eigen::Vector3d from = pose_ * a, to = pose_ * b;
  const Eigen::Vector3d dir = to - from;
  const double length = dir.norm();
  if (!(length > 0)) return true;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray{};
  ray.org_x = float(from.x());
  ray.org_y = float(from.y());
  ray.org_z = float(from.z());
  ray.dir_x = float(dir.x());
  ray.dir_y = float(dir.y());
  ray.dir_z = float(dir.z());
  // Off both ends by the surface offset: the ray starts on the lit surface.
  const double margin = std::min(0.25, SurfaceOffset(from) / length);
  ray.tnear = float(margin);
  ray.tfar = float(1.0 - margin);
  ray.mask = 0xFFFFFFFFu;
  rtcOccluded1(embree_->scene, &context, &ray);
  return ray.tfar >= 0;  // set to -inf when something blocks it
}

void BellQuadrature(int n, std::vector<double>* offsets, std::vector<double>* weights) {
  LUMISLAB_CHECK(n >= 1, "samples per support");
  offsets->assign(n, 0.0);
  weights->assign(n, 0.0);
  // Cells k and n - 1 - k mirror each other: compute the left half, mirror it, so the rule is
  // exactly symmetric (an odd n's middle cell has its centroid at 0).
  for (int k = 0; k < (n + 1) / 2; ++k) {
    const double a = -1.0 + 2.0 * k / n, b = -1.0 + 2.0 * (k + 1) / n;
    const double mass = BellIntegral(a, b);
    double centroid = 0;
    if (2 * k + 1 != n) {
      // First moment over the cell: midpoint rule on 4096 steps (phi is a smooth quadratic on
      // each piece; the error is ~1e-8 of the cell width).
      constexpr int kSteps = 4096;
      double moment = 0;
      for (int m = 0; m < kSteps; ++m) {
        const double x = a + (m + 0.5) * (b - a) / kSteps;
        moment += x * Bell(x);
      }
      centroid = moment * (b - a) / kSteps / mass;
    }
    (*offsets)[k] = centroid;
    (*weights)[k] = mass;
    if (n - 1 - k != k) {
      (*offsets)[n - 1 - k] = -centroid;
      (*weights)[n - 1 - k] = mass;
    }
  }
  double sum = 0;
  for (double w : *weights) sum += w;
  for (double& w : *weights) w /= sum;
}

namespace {

// Runs `pixel` over every pixel, rows in parallel, with progress and stopping between rows.
ReferenceImage RenderRows(const ReferenceScene& view, const ReferenceOptions& options,
                          const char* label,
                          const std::function<Eigen::Vector3d(const SurfacePoint&)>& pixel) {
  ReferenceImage out;
  out.irradiance = ImageF(view.width(), view.height(), 3);
  out.image = ImageF(view.width(), view.height(), 3);
  std::atomic<bool> stopped{false};
  std::unique_ptr<Progress> progress;
  if (options.progress) progress = std::make_unique<Progress>(label, view.height());
  ParallelFor(view.height(), options.threads, [&](int row) {
    if (stopped || StopRequested()) {
      stopped = true;
      return;
    }
    for (int col = 0; col < view.width(); ++col) {
      const SurfacePoint p = view.Primary(col, row);
      if (!p.hit) continue;
      const Eigen::Vector3d e = pixel(p);
      for (int c = 0; c < 3; ++c) {
        // Never a NaN or infinity in an image: a degenerate point gives no light.
        const double value = std::isfinite(e[c]) ? e[c] : 0.0;
        out.irradiance.at(col, row, c) = float(value);
        out.image.at(col, row, c) = float(value * p.albedo[c] * view.radiance_scale());
      }
    }
    if (progress) progress->Advance();
  });
  if (progress && !stopped) progress->Finish();
  out.complete = !stopped;
  return out;
}

}  // namespace

ReferenceImage RenderReference(const ReferenceScene& view, const SlabInfo& info,
                               const std::vector<ImageF>& irradiance,
                               const ReferenceOptions& options) {
  LUMISLAB_CHECK(int(irradiance.size()) == info.grid.count(), "one E_ij per grid position");
  std::vector<double> offsets, weights;
  BellQuadrature(options.samples, &offsets, &weights);
  const double h = info.grid.spacing_mm, d = info.distance_mm;
  const int n = options.samples;
  return RenderRows(view, options, "reference", [&](const SurfacePoint& p) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    if (!(p.x.z() > 0)) return sum;  // light leaves S only towards +z
    for (int j = 0; j < info.grid.nv; ++j) {
      for (int i = 0; i < info.grid.nu; ++i) {
        const ImageF& e = irradiance[size_t(j) * info.grid.nu + i];
        if (e.empty()) continue;
        const Eigen::Vector2d c = info.grid.Centre(i, j);
        for (int b = 0; b < n; ++b) {
          for (int a = 0; a < n; ++a) {
            const Eigen::Vector3d q(c.x() + h * offsets[a], c.y() + h * offsets[b], 0.0);
            const Eigen::Vector3d rel = p.x - q;
            const double length = rel.norm();
            const double cos_recv = -p.n.dot(rel) / length;
            if (!(cos_recv > 0)) continue;
            const double s = q.x() + rel.x() * d / rel.z();
            const double t = q.y() + rel.y() * d / rel.z();
            const Eigen::Vector3d value = SampleLayout(info.layout, e, s, t);
            if (value.isZero()) continue;
            if (options.visibility && !view.Visible(p.x, q)) continue;
            const double dz = rel.z();
            sum += (weights[a] * weights[b] * d * d * length * cos_recv / (dz * dz * dz)) * value;
          }
        }
      }
    }
    return sum;
  });
}

ReferenceImage RenderPointSources(const ReferenceScene& view,
                                  const std::vector<PointSource>& sources,
                                  const ReferenceOptions& options) {
  for (const PointSource& source : sources)
    LUMISLAB_CHECK(options.whole_frame || source.position_mm.z() < 0, "point sources lie behind S");
  return RenderRows(view, options, "analytic", [&](const SurfacePoint& p) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    if (!options.whole_frame && !(p.x.z() > 0)) return sum;
    for (const PointSource& source : sources) {
      const Eigen::Vector3d rel = p.x - source.position_mm;
      const double r2 = rel.squaredNorm();
      const double r = std::sqrt(r2);
      const double cos_recv = -p.n.dot(rel) / r;
      if (!(cos_recv > 0)) continue;
      // Where the ray from the source to x crosses S (the whole frame: the source itself).
      const Eigen::Vector3d on_s =
          options.whole_frame
              ? source.position_mm
              : Eigen::Vector3d(source.position_mm + rel * (-source.position_mm.z() / rel.z()));
      if (options.visibility && !view.Visible(p.x, on_s)) continue;
      sum += source.intensity_w_sr(rel / r) * (cos_recv / r2 * 1e6);
    }
    return sum;
  });
}

std::vector<ImageF> ReadSlabIrradiance(const std::string& slab_dir, const SlabInfo& info,
                                       int threads) {
  if (info.present.empty())
    throw InputError(slab_dir + "/slab.json", "present", "at least one position", "none");
  std::vector<ImageF> out(size_t(info.grid.count()));
  ParallelFor(int(info.present.size()), threads, [&](int k) {
    const auto [i, j] = info.present[k];
    out[size_t(j) * info.grid.nu + i] = ReadSlabPosition(slab_dir, info, i, j).irradiance;
  });
  return out;
}

}  // namespace lumislab
