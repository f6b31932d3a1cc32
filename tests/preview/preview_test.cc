// Preview renderer tests (OSMesa): GL against a CPU evaluation of the same formula, receiver-plane
// irradiance against the analytic irradiance of a point-emitter luminaire, partial slabs and
// incremental (--watch) accumulation, cached shadow maps, sRGBE accumulation error.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "core/exr_io.h"
#include "core/geometry.h"
#include "core/slab.h"
#include "lib/lightfield/camera.h"
#include "lib/lightfield/false_colour.h"
#include "lib/lightfield/light_field.h"
#include "lib/lightfield/scene_setup.h"
#include "lib/lightfield/scenes.h"
#include "lib/lightfield/tone_map.h"
#include "lib/synthetic/truth.h"
#include "preview/cli.h"
#include "preview/gl_context.h"
#include "preview/renderer.h"
#include "preview_slab_files.h"
#include "preview_test_util.h"

namespace lumislab {
namespace {

// Small scene: receiver plane at z = 1000 behind a square occluder at z = 500; 3x3 grid of
// spot lights. GL (shadow maps, bilinear E', float accumulation) against the CPU evaluation of
// the same sum with exact ray-cast visibility.
TEST(PreviewRenderer, MatchesCpuEvaluationWithShadows) {
  Context();
  const SlabInfo info = DefaultSlabInfo(3, 3, 20, 100);
  const double plane_z = 1000, extent = 1400, occ_z = 500,
               occ_half = 103;  // shadow edges pass near pixel centres
  Mesh mesh = MakeReceiverPlane(plane_z, 2 * extent);
  // Off-centre (+x, +y) so that a flipped image axis shows: the umbra is around 2 * occ_centre.
  const Eigen::Vector2d occ_centre(150, 70);
  const float ox = float(occ_centre.x()), oy = float(occ_centre.y()), oh = float(occ_half);
  mesh.AddQuad({ox - oh, oy - oh, float(occ_z)}, {ox - oh, oy + oh, float(occ_z)},
               {ox + oh, oy + oh, float(occ_z)}, {ox + oh, oy - oh, float(occ_z)}, {1, 1, 1});
  RenderOptions options;
  options.radiance_scale = 1.0;
  options.shadow_size = 1024;
  const int pixels = 140;
  Renderer renderer(info, pixels, pixels, options);
  renderer.SetScene(mesh);
  renderer.SetCamera(PlaneView(plane_z, extent));
  const Luminaire luminaire = DefaultScene().luminaire;
  std::vector<ImageF> intensity;
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      intensity.push_back(
          IntensityFromIrradiance(info, i, j, TruthPosition(luminaire, info, i, j).irradiance));
      renderer.SetPosition(i, j, intensity.back());
    }
  }
  renderer.Render();
  const ImageF image = renderer.Read();
  // Pixels whose ray to some c_ij passes within 2 mm (2.5 shadow texels) of the occluder's edge
  // are compared separately: the shadow map's 2x2 comparison filter blurs the edge there.
  double diff2 = 0, norm2 = 0, umbra = 0, umbra_ref = 0, all_diff2 = 0, all_norm2 = 0;
  int edge_pixels = 0;
  for (int row = 0; row < pixels; ++row) {
    for (int col = 0; col < pixels; ++col) {
      const Eigen::Vector3d x(-0.5 * extent + (col + 0.5) * extent / pixels,
                              0.5 * extent - (row + 0.5) * extent / pixels, plane_z);
      Eigen::Vector3d ref = Eigen::Vector3d::Zero();
      bool near_edge = false;
      for (int j = 0; j < 3; ++j) {
        for (int i = 0; i < 3; ++i) {
          const Eigen::Vector2d c = info.grid.Centre(i, j);
          const Eigen::Vector2d hit =
              c + (x.head<2>() - c) * (occ_z / plane_z) - occ_centre;  // occluder frame
          near_edge |= std::abs(hit.cwiseAbs().maxCoeff() - occ_half) < 2.0;
          if (std::abs(hit.x()) < occ_half && std::abs(hit.y()) < occ_half) continue;
          ref += SpotIrradiance(info, i, j, intensity[j * 3 + i], x, {0, 0, -1});
        }
      }
      edge_pixels += near_edge;
      for (int ch = 0; ch < 3; ++ch) {
        const double e2 = std::pow(image.at(col, row, ch) - ref[ch], 2);
        all_diff2 += e2;
        all_norm2 += ref[ch] * ref[ch];
        if (near_edge) continue;
        diff2 += e2;
        norm2 += ref[ch] * ref[ch];
      }
      if ((x.head<2>() - 2 * occ_centre).norm() < 150) {  // deep umbra (shadow ~2x the size)
        umbra += image.at(col, row, 0);
        umbra_ref += ref[0];
      }
    }
  }
  const double l2 = std::sqrt(diff2 / norm2), all_l2 = std::sqrt(all_diff2 / all_norm2);
  std::printf(
      "GL vs CPU (shadowed scene): relative L2 %.5f %% away from shadow edges, %.3f %% "
      "over all pixels (%d of %d near an edge)\n",
      100 * l2, 100 * all_l2, edge_pixels, pixels * pixels);
  EXPECT_LE(l2, 1e-4);      // float arithmetic and bilinear weights only
  EXPECT_LE(all_l2, 0.10);  // edge pixels (~3 %): partial visibility of a light (1/9 of the sum)
  EXPECT_GT(all_l2, l2);
  EXPECT_EQ(umbra_ref, 0.0);
  EXPECT_LE(umbra, 1e-6 * norm2);  // the shadow is dark in GL too
}

TEST_F(PreviewSlabFiles, PartialSlabIsTheSumOfItsPositions) {
  const std::vector<std::pair<int, int>> subset = {{0, 0}, {2, 2}, {4, 1}, {1, 3}, {3, 4}};
  auto together = MakeRenderer();
  Upload(*together, subset);
  together->Render();
  const ImageF partial = together->Read();
  ImageF sum(partial.width, partial.height, 3);
  for (const auto& p : subset) {
    auto alone = MakeRenderer();
    Upload(*alone, {p});
    alone->Render();
    const ImageF one = alone->Read();
    for (size_t k = 0; k < sum.data.size(); ++k) sum.data[k] += one.data[k];
  }
  double norm = 0;
  for (float v : partial.data) norm += v;
  EXPECT_GT(norm, 0);
  EXPECT_LE(RelativeDifference(partial, sum), 1e-5);
}

TEST_F(PreviewSlabFiles, IncrementalPositionsEqualAFullRenderAndReuseShadowMaps) {
  auto live = MakeRenderer();
  const auto scanned = ScanSlabPositions(dir_.string(), info_);
  ASSERT_EQ(int(scanned.size()), info_.grid.count());
  // Arrive in three groups, like --watch; each Render adds only the new lights.
  size_t done = 0;
  for (size_t group_end : {size_t(7), size_t(8), scanned.size()}) {
    Upload(*live,
           std::vector<std::pair<int, int>>(scanned.begin() + done, scanned.begin() + group_end));
    EXPECT_EQ(live->Render(), int(group_end - done));
    done = group_end;
  }
  EXPECT_EQ(live->Render(), 0);
  auto full = MakeRenderer();
  EXPECT_EQ(int(LoadNewPositions(dir_.string(), info_, *full, 3).size()), info_.grid.count());
  full->Render();
  EXPECT_LE(RelativeDifference(live->Read(), full->Read()), 1e-5);
  // Moving the camera re-accumulates all lights but renders no shadow map again.
  const int shadow_renders = full->ShadowMapRenders();
  EXPECT_EQ(shadow_renders, info_.grid.count());
  SceneSetup moved = MakeSceneSetup("crypt", info_);
  moved.camera_yaw_deg += 20;
  full->SetCamera(OrbitCamera(moved, 1.0));
  EXPECT_EQ(full->Render(), info_.grid.count());
  EXPECT_EQ(full->ShadowMapRenders(), shadow_renders);
  // A new pose invalidates them.
  full->SetPose(PoseFromValues({0, 2500, 0, 90, 0, 0}));
  full->Render();
  EXPECT_EQ(full->ShadowMapRenders(), 2 * shadow_renders);
}

TEST_F(PreviewSlabFiles, SrgbeAccumulationStaysCloseToFloat) {
  RenderOptions packed;
  packed.srgbe = true;
  auto a = MakeRenderer();
  auto b = MakeRenderer(packed);
  Upload(*a, ScanSlabPositions(dir_.string(), info_));
  Upload(*b, ScanSlabPositions(dir_.string(), info_));
  a->Render();
  b->Render();
  const double error = RelativeDifference(b->Read(), a->Read());
  std::printf("sRGBE vs float accumulation: relative L2 %.4f %%\n", 100 * error);
  // Each pass re-encodes the sum (25 lights fit one pass here): ~1/255 relative per pass.
  EXPECT_LE(error, 0.01);
  EXPECT_GT(error, 0.0);  // it is really packed
}

// --view false-colour maps the irradiance before the materials: with every albedo 0.5 the normal
// view is 0.5 / pi of the unit-albedo one, pixel for pixel.
TEST_F(PreviewSlabFiles, UnitAlbedoIsTheIrradianceBeforeTheMaterials) {
  SceneSetup setup = MakeSceneSetup("crypt", info_);
  for (Eigen::Vector3f& albedo : setup.mesh.albedo) albedo = {0.5f, 0.5f, 0.5f};
  RenderOptions irradiance_view;
  irradiance_view.radiance_scale = 1;
  irradiance_view.unit_albedo = true;
  ImageF images[2];
  for (int k = 0; k < 2; ++k) {
    Renderer renderer(info_, 96, 96, k == 0 ? RenderOptions{} : irradiance_view);
    renderer.SetScene(setup.mesh);
    renderer.SetPose(setup.pose);
    renderer.SetCamera(OrbitCamera(setup, 1.0));
    Upload(renderer, ScanSlabPositions(dir_.string(), info_));
    renderer.Render();
    images[k] = renderer.Read();
  }
  for (float& v : images[0].data) v *= float(M_PI / 0.5);
  EXPECT_LE(RelativeDifference(images[0], images[1]), 1e-5);
  EXPECT_GT(*std::max_element(images[1].data.begin(), images[1].data.end()), 0);
}

TEST(PreviewCommandLine, SizeIsCheckedStrictly) {
  int w = 0, h = 0;
  EXPECT_TRUE(ParseSize("640x480", &w, &h));
  EXPECT_EQ(w, 640);
  EXPECT_EQ(h, 480);
  for (const char* bad : {"400x400junk", "400x", "x400", " 400x400", "400X400", "-4x400", "0x400",
                          "400x9000", "400x400x3", "+400x400", ""}) {
    EXPECT_FALSE(ParseSize(bad, &w, &h)) << bad;
  }
  testing::internal::CaptureStderr();
  const int code = RunPreviewWith(
      {"--slab", "/nonexistent-lumislab-slab", "--size", "400x400junk", "--out", "x.png"});
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(code, 2);
  EXPECT_NE(err.find("--size"), std::string::npos) << err;
  EXPECT_NE(err.find("400x400junk"), std::string::npos) << err;
}

// The false-colour PNG is the picture with its colour bar to the right (wider than --size); the
// EXR keeps the irradiance; a bad range or the window is refused (exit 2), nothing written.
TEST(PreviewCommandLine, FalseColourView) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("lumislab_false_colour_" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string slab = (dir / "slab").string(), png = (dir / "fc.png").string();
  WriteTruthSlab(DefaultScene().luminaire, DefaultSlabInfo(3, 3, 10, 40), slab, 2);
  EXPECT_EQ(RunPreviewWith({"--slab", slab, "--scene", "plane", "--size", "120x120", "--view",
                            "false-colour", "--false-colour-range", "0:2", "--out", png}),
            0);
  const cv::Mat picture = cv::imread(png);
  EXPECT_EQ(picture.rows, 120);
  EXPECT_EQ(picture.cols, 120 + BarPanelWidth(120));
  // The .exr is the irradiance, the same from OpenGL and from the CPU reference (at D = d both
  // are exact up to the bilinear texels, docs/method.md §4.5).
  const std::string gl = (dir / "gl.exr").string(), cpu = (dir / "cpu.exr").string();
  for (const auto& [out, extra] :
       {std::pair{gl, std::vector<std::string>{"--no-shadows"}},
        std::pair{cpu, std::vector<std::string>{"--reference", "--samples", "1"}}}) {
    std::vector<std::string> args = {"--slab", slab,     "--scene",      "plane", "--size",
                                     "60x60",  "--view", "false-colour", "--out", out};
    args.insert(args.end(), extra.begin(), extra.end());
    ASSERT_EQ(RunPreviewWith(args), 0) << extra[0];
  }
  const double error =
      CompareImages(ReadExr(gl, {"R", "G", "B"}), ReadExr(cpu, {"R", "G", "B"})).relative_l2;
  std::printf("false-colour irradiance, OpenGL vs reference: %.2e\n", error);
  EXPECT_LT(error, 2e-3);
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"--false-colour-range", "2:1"},
        {"--false-colour-range", "0:x"},
        {"--false-colour-range", "0:5", "--false-colour-scale", "log"},
        {"--view", "false-color"}}) {
    std::vector<std::string> args = {
        "--slab", slab,           "--scene", "plane",
        "--view", "false-colour", "--out",   (dir / "bad.png").string()};
    args.insert(args.end(), bad.begin(), bad.end());
    testing::internal::CaptureStderr();
    EXPECT_EQ(RunPreviewWith(args), 2) << bad[0];
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find(bad[0]), std::string::npos) << err;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad.png"));
  }
  std::filesystem::remove_all(dir);
}

TEST(PreviewCommandLine, HelpNamesLlvmpipeThreads) {
  testing::internal::CaptureStdout();
  EXPECT_EQ(RunPreviewWith({"--help"}), 0);
  const std::string help = testing::internal::GetCapturedStdout();
  EXPECT_NE(help.find("--threads"), std::string::npos);
  EXPECT_NE(help.find("LP_NUM_THREADS"), std::string::npos) << help;
  EXPECT_EQ(RunPreviewWith({"--slab", "x", "--threads", "-1", "--out", "x.png"}), 2);
}

}  // namespace
}  // namespace lumislab
