// Receiver-plane irradiance of acquire's default synthetic luminaire (lib/synthetic/scene.h
// DefaultScene, truth slab from lib/synthetic/truth.h) against its analytic PlaneIrradiance at
// D = d, 2d, 4d, compared inside the window's cone (where the slab holds light).
#include <gtest/gtest.h>

#include <cmath>

#include "core/geometry.h"
#include "core/slab.h"
#include "lib/lightfield/camera.h"
#include "lib/lightfield/light_field.h"
#include "lib/lightfield/scenes.h"
#include "lib/synthetic/scene.h"
#include "lib/synthetic/truth.h"
#include "preview/gl_context.h"
#include "preview/renderer.h"

namespace lumislab {
namespace {

struct Errors {
  double flux = 0, l2 = 0;
};

Errors AgainstAnalytic(double factor) {
  static OffscreenContext context(16, 16);
  const SynthScene scene = DefaultScene();
  const SlabInfo info = SlabInfo::FromDataset(DatasetSkeleton(scene), 300);
  const double d = info.distance_mm, plane_z = factor * d;
  const double extent = info.layout.window_w_mm * plane_z / d;
  const int pixels = 240;
  RenderOptions options;
  options.radiance_scale = 1.0;
  options.shadows = false;
  Renderer renderer(info, pixels, pixels, options);
  renderer.SetScene(MakeReceiverPlane(plane_z, 1.2 * extent));
  renderer.SetCamera(PlaneView(plane_z, extent));
  for (int j = 0; j < info.grid.nv; ++j) {
    for (int i = 0; i < info.grid.nu; ++i) {
      renderer.SetPosition(i, j,
                           IntensityFromIrradiance(
                               info, i, j, TruthPosition(scene.luminaire, info, i, j).irradiance));
    }
  }
  renderer.Render();
  const ImageF image = renderer.Read();
  const Eigen::Vector2d corner = info.grid.Centre(info.grid.nu - 1, info.grid.nv - 1);
  const double inner_x = 0.5 * info.layout.window_w_mm - info.layout.TexelW();
  const double inner_y = 0.5 * info.layout.window_h_mm - info.layout.TexelH();
  auto inside = [&](double x, double y) {
    for (double cx : {-corner.x(), corner.x()}) {
      for (double cy : {-corner.y(), corner.y()}) {
        if (std::abs(cx + (x - cx) * d / plane_z) > inner_x ||
            std::abs(cy + (y - cy) * d / plane_z) > inner_y) {
          return false;
        }
      }
    }
    for (const Emitter& e : scene.luminaire.emitters) {
      const Eigen::Vector2d m = IntersectPlaneZ(e.position_mm, {x, y, plane_z}, d);
      if (std::abs(m.x()) > inner_x || std::abs(m.y()) > inner_y) return false;
    }
    return true;
  };
  double sum_r = 0, sum_a = 0, diff2 = 0, norm2 = 0;
  for (int row = 0; row < pixels; ++row) {
    for (int col = 0; col < pixels; ++col) {
      const double x = -0.5 * extent + (col + 0.5) * extent / pixels;
      const double y = 0.5 * extent - (row + 0.5) * extent / pixels;
      if (!inside(x, y)) continue;
      const Eigen::Vector3d a = scene.luminaire.PlaneIrradiance(x, y, plane_z);
      for (int c = 0; c < 3; ++c) {
        sum_r += image.at(col, row, c);
        sum_a += a[c];
        diff2 += std::pow(image.at(col, row, c) - a[c], 2);
        norm2 += a[c] * a[c];
      }
    }
  }
  EXPECT_GT(sum_a, 0);
  return {std::abs(sum_r / sum_a - 1), std::sqrt(diff2 / norm2)};
}

TEST(PreviewAcquireLuminaire, PlaneIrradianceAtD) {
  const Errors e = AgainstAnalytic(1);
  std::printf("acquire default, D = d:  flux %.4f %%, L2 %.4f %%\n", 100 * e.flux, 100 * e.l2);
  EXPECT_LE(e.flux, 0.005);
  EXPECT_LE(e.l2, 0.02);
}

TEST(PreviewAcquireLuminaire, PlaneIrradianceAt2D) {
  const Errors e = AgainstAnalytic(2);
  std::printf("acquire default, D = 2d: flux %.4f %%, L2 %.4f %%\n", 100 * e.flux, 100 * e.l2);
  EXPECT_LE(e.flux, 0.005);
  EXPECT_LE(e.l2, 0.025);
}

TEST(PreviewAcquireLuminaire, PlaneIrradianceAt4D) {
  const Errors e = AgainstAnalytic(4);
  std::printf("acquire default, D = 4d: flux %.4f %%, L2 %.4f %%\n", 100 * e.flux, 100 * e.l2);
  EXPECT_LE(e.flux, 0.005);
  EXPECT_LE(e.l2, 0.03);
}

}  // namespace
}  // namespace lumislab
