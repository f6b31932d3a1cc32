// The preview tests' GL context and slab-files fixture: a 5 x 5 truth slab of the default
// luminaire written to a temporary folder, renderers of the crypt scene over it, and the image
// comparisons (preview_test.cc, preview_shortcuts_test.cc).
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
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
#include "preview/gl_context.h"
#include "preview/renderer.h"

namespace lumislab {

// One OSMesa context for the whole test executable (never destroyed: GL state outlives tests).
inline OffscreenContext& Context() {
  static OffscreenContext* context = new OffscreenContext(16, 16);
  return *context;
}

class PreviewSlabFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    Context();
    dir_ = std::filesystem::temp_directory_path() /
           ("lumislab_preview_test_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    info_ = DefaultSlabInfo(5, 5, 5, 60);
    WriteTruthSlab(DefaultScene().luminaire, info_, dir_.string(), 2);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::unique_ptr<Renderer> MakeRenderer(const RenderOptions& options = {}) {
    const SceneSetup setup = MakeSceneSetup("crypt", info_);
    auto renderer = std::make_unique<Renderer>(info_, 96, 96, options);
    renderer->SetScene(setup.mesh);
    renderer->SetPose(setup.pose);
    renderer->SetCamera(OrbitCamera(setup, 1.0));
    return renderer;
  }
  // Uploads positions (i, j) from the files.
  void Upload(Renderer& r, const std::vector<std::pair<int, int>>& positions) {
    for (const auto& [i, j] : positions) {
      r.SetPosition(i, j, ReadIntensity(dir_.string(), info_, i, j));
    }
  }
  // Renders one view with both renderers (uploading the positions into one still empty) and
  // expects their images equal bit for bit and not black.
  void ExpectSameImage(Renderer& a, Renderer& b, const SceneSetup& view,
                       const std::vector<std::pair<int, int>>& positions, const std::string& what) {
    for (Renderer* r : {&a, &b}) {
      if (r->PositionCount() == 0) Upload(*r, positions);
      r->SetCamera(OrbitCamera(view, 1.0));
      r->Render();
    }
    const ImageF image_a = a.Read(), image_b = b.Read();
    double norm = 0;
    for (float v : image_b.data) norm += v;
    EXPECT_GT(norm, 0) << what;
    EXPECT_EQ(image_a.data, image_b.data) << what;
  }
  // E' with only a 3 x 3 patch at the centre of the texture left of `full` (a narrower support).
  static ImageF CentrePatch(const ImageF& full) {
    ImageF patch(full.width, full.height, 3);
    for (int y = full.height / 2; y < full.height / 2 + 3; ++y) {
      for (int x = full.width / 2; x < full.width / 2 + 3; ++x) {
        for (int c = 0; c < 3; ++c) patch.at(x, y, c) = full.at(x, y, c);
      }
    }
    return patch;
  }
  static double RelativeDifference(const ImageF& a, const ImageF& b) {
    double diff2 = 0, norm2 = 0;
    for (size_t k = 0; k < a.data.size(); ++k) {
      diff2 += std::pow(double(a.data[k]) - b.data[k], 2);
      norm2 += double(b.data[k]) * b.data[k];
    }
    return std::sqrt(diff2 / norm2);
  }

  std::filesystem::path dir_;
  SlabInfo info_;
};

}  // namespace lumislab
