// lumislab-acquire synth --camera-folder (docs/formats.md §4) writes a capture as a camera
// leaves it: camera/IMG_0001.TIF ... in capture order with EXIF, camera/BOARD.PNG, a setup.json
// with only what a lab knows, truth/, no dataset.json. `acquire import` (--order capture, from
// EXIF time and exposure, and --manifest) must give a dataset that reconstructs to the slab of
// the ordinary synth output of the same scene. And a `raw` dataset (DNG mosaics, decoded with
// the bilinear demosaic at full size) reconstructs close to truth/.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "core/dataset.h"
#include "core/slab_compare.h"
#include "lib/photo/exif.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::ReadBinaryFile;

class CameraFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = testing::FreshDir(std::string("camera_folder_") +
                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void Scene(const std::string& effects) {
    testing::WriteFile(root_ + "/scene.json",
                       testing::SceneJson(2, 2,
                                          R"({"size_px": [320, 240], "focal_px": 280,
                               "position_mm": [0, -200, 2400], "look_at_mm": [0, 0, 750]})",
                                          effects));
  }
  void Ok(const std::string& tool, const std::string& args) {
    const auto r = testing::RunToolIn(root_, tool, args, 120);
    ASSERT_EQ(r.exit_code, 0) << tool << " " << args << "\n" << r.output;
  }
  std::string root_;
};

TEST_F(CameraFolder, ImportGivesTheSlabOfTheOrdinaryCapture) {
  Scene(R"([{"type": "brackets", "stops": [-1, 0]}])");
  Ok("lumislab-acquire", "synth --scene scene.json --out normal --truth-resolution 40");
  Ok("lumislab-acquire",
     "synth --scene scene.json --out cam --truth-resolution 40 --camera-folder");
  EXPECT_FALSE(fs::exists(root_ + "/cam/dataset.json"));
  EXPECT_TRUE(fs::exists(root_ + "/cam/camera/BOARD.PNG"));
  const Dataset normal = Dataset::Load(root_ + "/normal");
  // The lab's setup: no radiometric scale, black level or transfer.
  nlohmann::json setup = nlohmann::json::parse(ReadBinaryFile(root_ + "/cam/setup.json"));
  EXPECT_EQ(setup["radiometry"], nlohmann::json::object());
  EXPECT_FALSE(setup.contains("photos"));
  // Photo k of the capture is IMG_<k+1>.TIF with EXIF: the exposure of normal's photo k, one
  // second after photo k - 1, one camera.
  ASSERT_EQ(normal.photos.size(), 16u);
  std::string previous;
  for (size_t k = 0; k < normal.photos.size(); ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "IMG_%04zu.TIF", k + 1);
    const PhotoExif exif = ReadPhotoExif(root_ + "/cam/camera/" + name);
    EXPECT_NEAR(*exif.RelativeExposure(), normal.photos[k].exposure, 1e-6) << name;
    ASSERT_TRUE(exif.date_time) << name;
    EXPECT_GT(*exif.date_time, previous) << name;
    previous = *exif.date_time;
    EXPECT_EQ(exif.model.value_or(""), "Synthetic camera");
  }
  // The lab calibrates the scale (here: the one synth chose), then imports by EXIF time, into
  // the capture's folder (truth/ beside dataset.json), and by a manifest.
  setup["radiometry"]["scale_w_m2"] = *normal.radiometric_scale;
  testing::WriteFile(root_ + "/setup.json", setup.dump(2));
  Ok("lumislab-acquire",
     "import --photos cam/camera --setup setup.json --out cam --order capture --brackets 2");
  std::string manifest = "i,j,slide,file\n";
  const Dataset by_time = Dataset::Load(root_ + "/cam");
  for (const PhotoEntry& e : by_time.photos)
    manifest += std::to_string(e.i) + "," + std::to_string(e.j) + "," + (e.positive ? "p" : "n") +
                "," + e.file + "\n";
  testing::WriteFile(root_ + "/captures.csv", manifest);
  Ok("lumislab-acquire",
     "import --photos cam/camera --setup setup.json --out by_manifest --manifest captures.csv");
  const Dataset by_manifest = Dataset::Load(root_ + "/by_manifest");
  ASSERT_EQ(by_time.photos.size(), normal.photos.size());
  ASSERT_EQ(by_manifest.photos.size(), normal.photos.size());
  for (size_t k = 0; k < normal.photos.size(); ++k) {
    const PhotoEntry &a = normal.photos[k], &b = by_time.photos[k], &m = by_manifest.photos[k];
    EXPECT_EQ(std::make_tuple(a.i, a.j, a.positive), std::make_tuple(b.i, b.j, b.positive));
    EXPECT_NEAR(b.exposure, a.exposure, 1e-6 * a.exposure) << b.file;
    EXPECT_EQ(std::make_tuple(b.file, b.exposure), std::make_tuple(m.file, m.exposure));
  }
  for (const std::string ds : {"normal", "cam"}) {
    Ok("lumislab-calibrate", "screen --dataset " + ds);
    Ok("lumislab-reconstruct", "--dataset " + ds + " --resolution 40");
  }
  // The same slab, up to the photos' precision (16-bit TIFF codes against half-float EXR).
  const SlabComparison c = CompareSlabs(root_ + "/cam/slab", root_ + "/normal/slab", 0.05);
  std::printf("camera folder vs ordinary capture: %s\n", c.Summary().c_str());
  EXPECT_EQ(c.positions.size(), 4u);
  EXPECT_LE(c.max_relative_l2, 2e-4);  // measured 5e-5
}

// raw: 14-bit DNG mosaics, decoded at full size with the bilinear demosaic: within 1 % relative
// L2 of truth/ (lit texels), like the ordinary capture, and within 0.5 % of its slab.
TEST_F(CameraFolder, RawDatasetReconstructsCloseToTruth) {
  Scene("[]");
  Ok("lumislab-acquire", "synth --scene scene.json --out normal --truth-resolution 40");
  Scene(R"([{"type": "raw"}])");
  Ok("lumislab-acquire", "synth --scene scene.json --out raw --truth-resolution 40");
  EXPECT_EQ(Dataset::Load(root_ + "/raw").photos[0].file, "photos/pos_0_0_p.dng");
  for (const std::string ds : {"normal", "raw"}) {
    Ok("lumislab-calibrate", "screen --dataset " + ds);
    Ok("lumislab-reconstruct", "--dataset " + ds + " --resolution 40");
  }
  const SlabComparison truth = CompareSlabs(root_ + "/raw/slab", root_ + "/raw/truth", 0.05);
  const SlabComparison normal = CompareSlabs(root_ + "/raw/slab", root_ + "/normal/slab", 0.05);
  std::printf("raw vs truth: %s\nraw vs ordinary capture: %s\n", truth.Summary().c_str(),
              normal.Summary().c_str());
  EXPECT_EQ(truth.positions.size(), 4u);
  EXPECT_LE(truth.max_relative_l2, 0.01);    // measured 0.52 %
  EXPECT_LE(normal.max_relative_l2, 0.005);  // measured 0.22 %
}

}  // namespace
}  // namespace lumislab
