// The preview's shortcuts (docs/method.md §4.2, "Faster frames") against the full render on the
// slab-files fixture (preview_slab_files.h): off is the full per-position render bit for bit, each
// stays within its bound; shadow culling, the shadow scissor and tiled light culling keep the
// image; coarse shading and reprojection stay within 1 %, also through live positions, a resize,
// source changes, merging and many lights.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/slab.h"
#include "lib/lightfield/camera.h"
#include "lib/lightfield/light_field.h"
#include "lib/lightfield/scene_setup.h"
#include "lib/lightfield/scenes.h"
#include "lib/synthetic/truth.h"
#include "preview/config.h"
#include "preview/renderer.h"
#include "preview_slab_files.h"

namespace lumislab {
namespace {

// The shortcuts of docs/method.md §4.2 ("Faster frames"): off is the full per-position render
// bit for bit (also after they were on), each stays within its bound of it.
TEST_F(PreviewSlabFiles, ShortcutsStayWithinTheirBoundsAndOffIsTheFullRender) {
  auto full = MakeRenderer();
  Upload(*full, ScanSlabPositions(dir_.string(), info_));
  full->Render();
  const ImageF reference = full->Read();
  auto render = [&](const RenderOptions& options, ShortcutState* state = nullptr) {
    auto r = MakeRenderer();
    Upload(*r, ScanSlabPositions(dir_.string(), info_));
    r->SetOptions(options);
    r->Render();
    if (state) *state = r->shortcuts();
    // Back to off in the same renderer: the full render again, exactly.
    r->SetOptions(RenderOptions{});
    r->Render();
    EXPECT_EQ(r->Read().data, reference.data);
    r->SetOptions(options);
    r->Render();
    return r->Read();
  };
  // Sharing within a tiny shift keeps every position's own map: the same image.
  RenderOptions share;
  share.shadow_share_texels = 1e-3;
  ShortcutState state;
  EXPECT_EQ(render(share, &state).data, reference.data);
  EXPECT_EQ(state.shadow_group, 1);
  EXPECT_GT(state.z_min, 500);  // the crypt seen from the default pose: walls metres away
  EXPECT_LT(state.z_max, 10000);
  // Edges moved by up to 2 shadow texels: blocks share maps; the image moves in the penumbrae
  // (measured 1.4 % here; 2.9 % on the bench's 400 x 400 crypt at 300 texels).
  share.shadow_share_texels = 2;
  const ImageF shared = render(share, &state);
  EXPECT_GT(state.shadow_group, 1);
  EXPECT_LE(state.shadow_shift, 2);
  EXPECT_GT(RelativeDifference(shared, reference), 0);
  EXPECT_LE(RelativeDifference(shared, reference), 0.05);
  // Merged lights: the derived depth bound moves with the error bound; within it the image is
  // within the bound (no shadows: the texture and spot-factor part the bound covers).
  RenderOptions no_shadows;
  no_shadows.shadows = false;
  auto flat = MakeRenderer(no_shadows);
  Upload(*flat, ScanSlabPositions(dir_.string(), info_));
  flat->Render();
  const ImageF flat_reference = flat->Read();
  std::vector<double> z_times_bound;  // z_G = r (d sum|grad E'| / P + 5) / bound
  for (double bound : {0.02, 0.3}) {
    RenderOptions merge = no_shadows;
    merge.merge_group = 2;
    merge.merge_error = bound;
    auto r = MakeRenderer(merge);
    Upload(*r, ScanSlabPositions(dir_.string(), info_));
    r->Render();
    // 5 x 5 in blocks of 2: four 2 x 2, four 2 x 1 at the edges (the corner 1 x 1 is no block).
    EXPECT_EQ(r->shortcuts().merged_lights, 8);
    z_times_bound.push_back(r->shortcuts().z_merge * bound);
    EXPECT_LE(RelativeDifference(r->Read(), flat_reference), bound);
  }
  EXPECT_NEAR(z_times_bound[0], z_times_bound[1], 1e-9 * z_times_bound[0]);
  // The command line's default without shadows (MergeGroup: 2 x 2, bound 0.05) is within 1 %.
  PreviewConfig config;
  config.shadows = false;
  const SceneSetup setup = MakeSceneSetup("crypt", info_);
  const RenderOptions defaults = MakeRenderOptions(config, setup);
  EXPECT_EQ(defaults.merge_group, 2);
  auto r = MakeRenderer(defaults);
  Upload(*r, ScanSlabPositions(dir_.string(), info_));
  r->Render();
  EXPECT_GT(r->shortcuts().merged_lights, 0);
  const double error = RelativeDifference(r->Read(), flat_reference);
  std::printf("merged lights at the default bound: z_G %.0f mm, %.3g relative L2\n",
              r->shortcuts().z_merge, error);
  EXPECT_LE(error, 0.01);
  config.shadows = true;
  EXPECT_EQ(MakeRenderOptions(config, setup).merge_group, 1);
}

// Shadow maps of the faces turned to the light only (the command line's default for closed
// rooms): the crypt keeps its shadows and moves by less than 1 % (culling the other side, the
// room's walls, moved it by 3.7 % on the bench's 400 x 400 crypt).
TEST_F(PreviewSlabFiles, ShadowCullKeepsTheImage) {
  RenderOptions cull, no_shadows;
  cull.shadow_cull = true;
  no_shadows.shadows = false;
  auto all = MakeRenderer();
  auto culled = MakeRenderer(cull);
  auto flat = MakeRenderer(no_shadows);
  for (Renderer* r : {all.get(), culled.get(), flat.get()}) {
    Upload(*r, ScanSlabPositions(dir_.string(), info_));
    r->Render();
  }
  const double error = RelativeDifference(culled->Read(), all->Read());
  const double shadows = RelativeDifference(flat->Read(), all->Read());
  std::printf(
      "shadow maps of the lit faces only: relative L2 %.4f %% (shadows themselves %.1f %%)\n",
      100 * error, 100 * shadows);
  EXPECT_LE(error, 0.01);
  EXPECT_GT(shadows, 0.1);
  PreviewConfig config;
  EXPECT_TRUE(MakeRenderOptions(config, MakeSceneSetup("crypt", info_)).shadow_cull);
  EXPECT_FALSE(MakeRenderOptions(config, MakeSceneSetup("plane", info_)).shadow_cull);
  config.shadow_cull = false;
  EXPECT_FALSE(MakeRenderOptions(config, MakeSceneSetup("crypt", info_)).shadow_cull);
}

// Shadow maps drawn only where each position's E' is not zero (RenderOptions::shadow_scissor):
// the same image, bit for bit, with the cubic filter and PCF (the widest lookups) and in sRGBE,
// over two views, with the maps drawn in one layered draw or one by one; fewer map texels drawn; a
// position replaced by one with a wider E' gets its map redrawn, and the image equals a fresh
// render.
TEST_F(PreviewSlabFiles, ShadowScissorKeepsTheImageBitForBit) {
  const SceneSetup setup = MakeSceneSetup("crypt", info_);
  const auto positions = ScanSlabPositions(dir_.string(), info_);
  for (bool srgbe : {false, true}) {
    RenderOptions on;
    on.shadow_cull = true;
    on.shadow_pcf = true;
    on.srgbe = srgbe;
    on.texture_filter = TextureFilter::kCubic;
    RenderOptions off = on;
    off.shadow_scissor = false;
    // One of them draws its maps one at a time (the path of drivers without layered drawing).
    (srgbe ? on : off).layered_shadow_maps = false;
    auto scissored = MakeRenderer(on), whole = MakeRenderer(off);
    SceneSetup view = setup;
    for (double yaw : {0.0, 8.0}) {
      view.camera_yaw_deg = setup.camera_yaw_deg + yaw;
      ExpectSameImage(*scissored, *whole, view, positions,
                      "sRGBE " + std::to_string(srgbe) + ", yaw " + std::to_string(yaw));
    }
    std::printf("shadow scissor: %lld of %lld map texels drawn\n", scissored->ShadowTexelsDrawn(),
                whole->ShadowTexelsDrawn());
    EXPECT_LT(scissored->ShadowTexelsDrawn(), 0.8 * whole->ShadowTexelsDrawn());
  }
  // A position first uploaded with E' only in a small patch, then replaced by its full E'.
  RenderOptions options;
  options.shadow_cull = true;
  auto live = MakeRenderer(options), fresh = MakeRenderer(options);
  Upload(*live, positions);
  const int i = info_.grid.nu / 2, j = info_.grid.nv / 2;
  const ImageF full = ReadIntensity(dir_.string(), info_, i, j);
  const ImageF patch = CentrePatch(full);
  live->SetPosition(i, j, patch);
  live->Render();
  const int renders = live->ShadowMapRenders();
  live->SetPosition(i, j, full);
  live->Render();
  EXPECT_EQ(live->ShadowMapRenders(), renders + 1);  // that map, wider
  Upload(*fresh, positions);
  fresh->Render();
  EXPECT_EQ(live->Read().data, fresh->Read().data);
}

// Light culling by tiles leaves a light out only where its E' is 0: the same image bit for bit,
// with every shortcut (merged lights have their own lists, coarse shading and reprojection shade
// their listed pixels through the tiles' lists) and without, in float and sRGBE.
TEST_F(PreviewSlabFiles, TiledLightsKeepTheImageBitForBit) {
  const SceneSetup setup = MakeSceneSetup("crypt", info_);
  const auto positions = ScanSlabPositions(dir_.string(), info_);
  for (bool fast : {false, true}) {
    for (bool srgbe : {false, true}) {
      RenderOptions on;
      on.shadow_cull = true;
      on.shadow_pcf = true;
      on.srgbe = srgbe;
      on.texture_filter = srgbe ? TextureFilter::kCubic : TextureFilter::kBilinear;
      if (fast) {
        on.merge_group = 2;
        on.merge_error = 0.05;
        on.shadows = srgbe;  // merged lights with and without their members' shadows
        on.coarse_tolerance = 0.1;
        on.reproject_tolerance = 0.1;
      }
      RenderOptions off = on;
      off.tiled_lights = false;
      auto tiled = MakeRenderer(on), untiled = MakeRenderer(off);
      SceneSetup view = setup;
      for (double yaw : {0.0, 3.0, 6.0}) {  // the later views reproject with the shortcuts
        view.camera_yaw_deg = setup.camera_yaw_deg + yaw;
        ExpectSameImage(*tiled, *untiled, view, positions,
                        "shortcuts " + std::to_string(fast) + ", sRGBE " + std::to_string(srgbe) +
                            ", yaw " + std::to_string(yaw));
      }
      if (fast) {
        EXPECT_GT(tiled->shortcuts().merged_lights, 0);
      }
      // Culled: the crypt's tiles list ~60 % of the lights (corner positions light a corner).
      const double listed = tiled->ListedLightFraction();
      std::printf("tiled lights: %.1f %% of the lights listed per tile\n", 100 * listed);
      EXPECT_GT(listed, 0.05);
      EXPECT_LT(listed, 0.9);
      EXPECT_EQ(untiled->ListedLightFraction(), 1);
    }
  }
  // A position live: its lists follow its support when it is replaced by a wider E'.
  RenderOptions options;
  auto live = MakeRenderer(options), fresh = MakeRenderer(options);
  Upload(*live, positions);
  live->Render();
  const int i = 0, j = 0;
  const ImageF full = ReadIntensity(dir_.string(), info_, i, j);
  const ImageF patch = CentrePatch(full);
  live->SetPosition(i, j, patch);
  live->Render();
  live->SetPosition(i, j, full);
  live->Render();
  Upload(*fresh, positions);
  fresh->Render();
  EXPECT_EQ(live->Read().data, fresh->Read().data);
}

// Coarse shading and reprojection (docs/method.md §4.2, "Faster frames") against the full
// per-position render of the same view: within 1 %, not identical (they really interpolate), the
// tolerance matters, and reprojection never reuses sums that a pose, a scene or a replaced
// position made stale.
TEST_F(PreviewSlabFiles, CoarseShadingAndReprojectionStayWithinOnePercent) {
  const SceneSetup setup = MakeSceneSetup("crypt", info_);
  const auto positions = ScanSlabPositions(dir_.string(), info_);
  SceneSetup moved = setup;
  auto exact_at = [&](const SceneSetup& view, const RenderOptions& options = {}) {
    auto r = MakeRenderer(options);
    Upload(*r, positions);
    r->SetCamera(OrbitCamera(view, 1.0));
    r->Render();
    return r->Read();
  };
  const ImageF reference = exact_at(setup);
  std::vector<double> coarse_errors;
  for (double tolerance : {0.1, 10.0}) {
    RenderOptions coarse;
    coarse.coarse_tolerance = tolerance;
    auto r = MakeRenderer(coarse);
    Upload(*r, positions);
    r->Render();
    coarse_errors.push_back(RelativeDifference(r->Read(), reference));
  }
  std::printf("coarse shading: relative L2 %.3f %% (tolerance 0.1), %.3f %% (10)\n",
              100 * coarse_errors[0], 100 * coarse_errors[1]);
  EXPECT_GT(coarse_errors[0], 0);
  EXPECT_LE(coarse_errors[0], 0.01);
  EXPECT_GT(coarse_errors[1], 1.5 * coarse_errors[0]);

  RenderOptions reuse;
  reuse.reproject_tolerance = 0.1;
  auto r = MakeRenderer(reuse);
  Upload(*r, positions);
  r->Render();
  EXPECT_EQ(r->Read().data, reference.data);  // the first view is shaded in full
  for (int step = 1; step <= 3; ++step) {
    moved.camera_yaw_deg = setup.camera_yaw_deg + 2 * step;
    r->SetCamera(OrbitCamera(moved, 1.0));
    EXPECT_EQ(r->Render(), 0);  // every light came from the source view
    const double error = RelativeDifference(r->Read(), exact_at(moved));
    const double listed = r->shortcuts().reprojected_exact;
    std::printf("reprojected %d degrees: relative L2 %.3f %%, %.1f %% of the pixels exact\n",
                2 * step, 100 * error, 100 * listed);
    EXPECT_GT(error, 0);
    EXPECT_LE(error, 0.01);
    EXPECT_GT(listed, 0);
    EXPECT_LT(listed, 0.5);
  }
  // A position replaced, then a camera move: the last view's sums are stale, the view is shaded
  // anew.
  ImageF brighter = ReadIntensity(dir_.string(), info_, 2, 2);
  for (float& v : brighter.data) v *= 3;
  r = MakeRenderer(reuse);
  Upload(*r, positions);
  r->Render();
  r->SetPosition(2, 2, brighter);
  moved.camera_yaw_deg = setup.camera_yaw_deg + 2;
  r->SetCamera(OrbitCamera(moved, 1.0));
  r->Render();
  auto replaced = MakeRenderer();
  Upload(*replaced, positions);
  replaced->SetPosition(2, 2, brighter);
  replaced->SetCamera(OrbitCamera(moved, 1.0));
  replaced->Render();
  EXPECT_EQ(r->Read().data, replaced->Read().data);
  // A new pose: nothing is reused either.
  const Eigen::Isometry3d pose = PoseFromValues({0, 2500, 0, 90, 0, 0});
  r->SetPose(pose);
  r->Render();
  replaced->SetPose(pose);
  replaced->Render();
  EXPECT_EQ(r->Read().data, replaced->Read().data);
  // The command line's defaults: coarse shading in a room with shadows only (the plane's
  // irradiance is a measurement), reprojection everywhere; a value given is taken.
  PreviewConfig config;
  const SceneSetup plane = MakeSceneSetup("plane", info_);
  EXPECT_EQ(MakeRenderOptions(config, setup).coarse_tolerance, 0.1);
  EXPECT_EQ(MakeRenderOptions(config, plane).coarse_tolerance, 0);
  EXPECT_EQ(MakeRenderOptions(config, plane).reproject_tolerance, 0.1);
  config.coarse_tolerance = 0.2;
  EXPECT_EQ(MakeRenderOptions(config, plane).coarse_tolerance, 0.2);
  config.coarse_tolerance = -1;
  config.shadows = false;
  EXPECT_EQ(MakeRenderOptions(config, setup).coarse_tolerance, 0);
}

// Live mode with reprojection: the positions that arrive after a camera move are added to the
// reused sums of the earlier ones.
TEST_F(PreviewSlabFiles, ReprojectionAddsPositionsThatArriveAfterTheMove) {
  const auto positions = ScanSlabPositions(dir_.string(), info_);
  const size_t half = positions.size() / 2;
  RenderOptions reuse;
  reuse.reproject_tolerance = 0.1;
  auto live = MakeRenderer(reuse);
  Upload(*live, std::vector<std::pair<int, int>>(positions.begin(), positions.begin() + half));
  EXPECT_EQ(live->Render(), int(half));
  SceneSetup moved = MakeSceneSetup("crypt", info_);
  moved.camera_yaw_deg += 2;
  live->SetCamera(OrbitCamera(moved, 1.0));
  Upload(*live, std::vector<std::pair<int, int>>(positions.begin() + half, positions.end()));
  EXPECT_EQ(live->Render(), int(positions.size() - half));  // only the new ones shaded here
  EXPECT_GT(live->shortcuts().reprojected_exact, 0);
  auto full = MakeRenderer();
  Upload(*full, positions);
  full->SetCamera(OrbitCamera(moved, 1.0));
  full->Render();
  const double error = RelativeDifference(live->Read(), full->Read());
  EXPECT_GT(error, 0);
  EXPECT_LE(error, 0.01);
  // sRGBE accumulation takes the same paths: within its own packing error of float.
  RenderOptions packed = reuse;
  packed.srgbe = true;
  packed.coarse_tolerance = 0.1;
  auto p = MakeRenderer(packed);
  Upload(*p, positions);
  p->Render();
  p->SetCamera(OrbitCamera(moved, 1.0));
  p->Render();
  EXPECT_GT(p->shortcuts().reprojected_exact, 0);
  EXPECT_LE(RelativeDifference(p->Read(), full->Read()), 0.015);
}

// Reprojection across the renderer's other paths: a resize (new, undefined targets: nothing is
// reused), a move so far that the source is replaced (its textures change roles a second time),
// merged lights with coarse shading, and more lights than one pass holds (81: two batches over
// one list).
TEST_F(PreviewSlabFiles, ReprojectionThroughResizeSourceChangesMergingAndManyLights) {
  const auto positions = ScanSlabPositions(dir_.string(), info_);
  const SceneSetup setup = MakeSceneSetup("crypt", info_);
  RenderOptions reuse;
  reuse.reproject_tolerance = 0.1;
  auto r = MakeRenderer(reuse);
  Upload(*r, positions);
  r->Render();
  SceneSetup moved = setup;
  moved.camera_yaw_deg += 2;
  r->Resize(80, 72);
  r->SetCamera(OrbitCamera(moved, 1.0));
  r->Render();
  EXPECT_EQ(r->shortcuts().reprojected_exact, 0);  // shaded in full, nothing reused
  {
    Renderer fresh(info_, 80, 72, RenderOptions{});
    fresh.SetScene(setup.mesh);
    fresh.SetPose(setup.pose);
    fresh.SetCamera(OrbitCamera(moved, 1.0));
    Upload(fresh, positions);
    fresh.Render();
    EXPECT_EQ(r->Read().data, fresh.Read().data);
  }
  // Far moves: the source is replaced after one that lists over a quarter of the pixels.
  r->Resize(96, 96);
  auto exact_at = [&](const SceneSetup& view, const RenderOptions& options) {
    auto e = MakeRenderer(options);
    Upload(*e, positions);
    e->SetCamera(OrbitCamera(view, 1.0));
    e->Render();
    return e->Read();
  };
  bool replaced = false;
  for (double yaw : {0.0, 2.0, 10.0, 12.0, 14.0}) {
    moved.camera_yaw_deg = setup.camera_yaw_deg + yaw;
    r->SetCamera(OrbitCamera(moved, 1.0));
    r->Render();
    replaced |= r->shortcuts().reprojected_exact > 0.25;
    // 0.65-0.9 % after 2-6 degrees (the test above); 8 degrees from the source at 96 x 96: 1.0 %.
    EXPECT_LE(RelativeDifference(r->Read(), exact_at(moved, RenderOptions{})), 0.015) << yaw;
  }
  EXPECT_TRUE(replaced);
  EXPECT_GT(r->shortcuts().reprojected_exact, 0);  // 14: from the source shaded at 12
  EXPECT_LT(r->shortcuts().reprojected_exact, 0.25);
  // Merged lights (no shadows) with coarse shading and reprojection: within the merged lights'
  // own error (0.83 %, the shortcuts' test) plus a little.
  RenderOptions merged = reuse;
  merged.shadows = false;
  merged.merge_group = 2;
  merged.merge_error = 0.05;
  merged.coarse_tolerance = 0.1;
  RenderOptions flat;
  flat.shadows = false;
  auto m = MakeRenderer(merged);
  Upload(*m, positions);
  m->Render();
  // (At 96 x 96 a 2 degree move lists about a quarter of the pixels: the next view may be shaded
  // in full, so each move starts from a view shaded in full.)
  for (double yaw : {2.0, 4.0}) {
    moved.camera_yaw_deg = setup.camera_yaw_deg + yaw - 2;
    m->SetCamera(OrbitCamera(moved, 1.0));
    m->SetOptions(merged);  // drops the source: this view is shaded in full
    m->Render();
    EXPECT_EQ(m->shortcuts().reprojected_exact, 0);
    moved.camera_yaw_deg = setup.camera_yaw_deg + yaw;
    m->SetCamera(OrbitCamera(moved, 1.0));
    m->Render();
    EXPECT_GT(m->shortcuts().reprojected_exact, 0);
    EXPECT_LE(RelativeDifference(m->Read(), exact_at(moved, flat)), 0.015) << yaw;
  }
  // 9 x 9 positions: two light passes (64 + 17) over coarse shading's and reprojection's lists.
  const std::filesystem::path many = dir_.string() + "_81";
  std::filesystem::remove_all(many);
  const SlabInfo info81 = DefaultSlabInfo(9, 9, 5, 40);
  WriteTruthSlab(DefaultScene().luminaire, info81, many.string(), 2);
  const SceneSetup setup81 = MakeSceneSetup("crypt", info81);
  auto render81 = [&](const RenderOptions& options, const std::vector<double>& yaws) {
    Renderer r81(info81, 96, 96, options);
    r81.SetScene(setup81.mesh);
    r81.SetPose(setup81.pose);
    for (const auto& [i, j] : ScanSlabPositions(many.string(), info81))
      r81.SetPosition(i, j, ReadIntensity(many.string(), info81, i, j));
    SceneSetup view = setup81;
    for (double yaw : yaws) {
      view.camera_yaw_deg = setup81.camera_yaw_deg + yaw;
      r81.SetCamera(OrbitCamera(view, 1.0));
      r81.Render();
    }
    return r81.Read();
  };
  RenderOptions both = reuse;
  both.coarse_tolerance = 0.1;
  const ImageF exact81 = render81({}, {2});
  RenderOptions coarse;
  coarse.coarse_tolerance = 0.1;
  const double coarse81 = RelativeDifference(render81(coarse, {2}), exact81);
  const double reused81 = RelativeDifference(render81(reuse, {0, 2}), exact81);
  const double error81 = RelativeDifference(render81(both, {0, 2}), exact81);
  std::printf(
      "81 positions: relative L2 coarse shading %.3f %%, reprojection %.3f %%, both %.3f %%\n",
      100 * coarse81, 100 * reused81, 100 * error81);
  // A batch lost or counted twice moves the image by 17/81 or 64/81. Coarse shading's own error
  // is larger on this 96 x 96 image of a 9 x 9 grid (1.8-2.1 %, nearly the same at tolerance
  // 0.01: the penumbrae's steps, one per position, are finer than two pixels here; 0.3-0.6 % on
  // the bench's 400 x 400 rooms).
  EXPECT_GT(coarse81, 0);
  EXPECT_LE(coarse81, 0.03);
  EXPECT_GT(reused81, 0);
  EXPECT_LE(reused81, 0.01);
  EXPECT_LE(error81, 0.03);
  std::filesystem::remove_all(many);
}

}  // namespace
}  // namespace lumislab
