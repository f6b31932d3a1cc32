// lumislab-acquire import and watch on the folders a lab really has (docs/formats.md §3):
// unpadded camera counters (gphoto2's %n: capt1 ... capt18) in numeric order, a manifest that
// can never complete the grid, the dataset folder used as the photo folder, and a photo deleted
// during a capture. The test plays the camera with the photos of a synthetic 3 x 3 capture.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "acquire/import.h"
#include "core/dataset.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::ReadBinaryFile;
using testing::ToolProcess;
using testing::WaitUntil;

constexpr double kWaitS = 60;  // deadline of any wait for the tool (a failure, not a timing)

class WatchSafety : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = testing::FreshDir(std::string("watch_safety_") +
                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
    testing::WriteFile(root_ + "/scene.json",
                       testing::SceneJson(3, 3,
                                          R"({"size_px": [160, 120], "focal_px": 140,
                               "position_mm": [0, -200, 2400], "look_at_mm": [0, 0, 750]})",
                                          "[]"));
    Ok("lumislab-acquire", "synth --scene scene.json --out original --truth-resolution 8");
    original_ = Dataset::Load(root_ + "/original");
    // Capture order (rows, p then n): photo k is the slide of position k / 2 of the scan.
    for (int q = 0; q < original_.grid.count(); ++q) {
      const int i = q % original_.grid.nu, j = q / original_.grid.nu;
      for (const bool positive : {true, false})
        for (const auto& e : original_.PhotosOf(i, j))
          if (e.positive == positive) sources_.push_back(original_.PhotoPath(e.file));
    }
    ASSERT_EQ(sources_.size(), 18u);
    nlohmann::json setup = nlohmann::json::parse(ReadBinaryFile(root_ + "/original/dataset.json"));
    setup.erase("photos");
    setup.erase("synthetic");
    setup["calibration"]["photo"] = "BOARD.PNG";
    testing::WriteFile(root_ + "/setup.json", setup.dump(2));
    fs::create_directories(root_ + "/camera");
  }
  void Ok(const std::string& tool, const std::string& args) {
    const auto r = testing::RunToolIn(root_, tool, args, 120);
    ASSERT_EQ(r.exit_code, 0) << tool << " " << args << "\n" << r.output;
  }
  // gphoto2's %n names: capt1.exr ... capt18.exr (photo k is capt<k + first>.exr).
  static std::string Name(size_t k, int first = 1, const std::string& stem = "capt") {
    return stem + std::to_string(k + size_t(first)) + ".exr";
  }
  // Photo k arrives as careful tools write: a temporary name, then a rename.
  void Deliver(size_t k, const std::string& name, const std::string& folder = "camera") const {
    const std::string tmp = root_ + "/" + folder + "/." + name + ".tmp";
    fs::copy_file(sources_[k], tmp);
    fs::rename(tmp, root_ + "/" + folder + "/" + name);
  }
  void DeliverBoard(const std::string& folder = "camera") const {
    fs::copy_file(original_.PhotoPath(original_.calibration.photo),
                  root_ + "/" + folder + "/BOARD.PNG");
  }
  std::unique_ptr<ToolProcess> StartWatch(const std::string& args) const {
    std::vector<std::string> argv = {"watch", "--setup", "setup.json", "--poll", "0.05"};
    std::istringstream more(args);
    for (std::string a; more >> a;) argv.push_back(a);
    return std::make_unique<ToolProcess>(root_, "lumislab-acquire", argv, root_ + "/watch.log");
  }
  // Runs a watch to its end; its exit code.
  int Watch(const std::string& args) const {
    const auto watch = StartWatch(args);
    EXPECT_TRUE(watch->WaitFor(kWaitS)) << Log();
    return watch->exit_code();
  }
  std::string Log() const { return ReadBinaryFile(root_ + "/watch.log"); }
  // Each photo of dataset.json at the place of the capture order its name gives.
  void ExpectCaptureOrder(const std::string& dataset, int first, const std::string& stem) const {
    const Dataset ds = Dataset::Load(root_ + "/" + dataset);
    ASSERT_EQ(ds.photos.size(), 18u);
    for (size_t k = 0; k < 18; ++k) {
      const std::string name = Name(k, first, stem);
      const auto e = std::find_if(ds.photos.begin(), ds.photos.end(),
                                  [&](const PhotoEntry& p) { return p.file == name; });
      ASSERT_NE(e, ds.photos.end()) << name;
      EXPECT_EQ(std::make_pair(e->i, e->j), ScanPosition(ds.grid, "rows", int(k / 2))) << name;
      EXPECT_EQ(e->positive, k % 2 == 0) << name;
    }
  }

  std::string root_;
  Dataset original_;
  std::vector<std::string> sources_;  // photo k of the capture order
};

// capt1 ... capt18 (and IMG_9 ... IMG_26, across a change of digit count) are in numeric order
// for import and watch alike: the same dataset.json, every slide at its place.
TEST_F(WatchSafety, UnpaddedCountersSortNumerically) {
  for (const auto& [stem, first] :
       {std::make_pair(std::string("capt"), 1), std::make_pair(std::string("IMG_"), 9)}) {
    fs::remove_all(root_ + "/camera");
    fs::remove_all(root_ + "/imported");
    fs::remove_all(root_ + "/watched");
    fs::create_directories(root_ + "/camera");
    for (size_t k = 0; k < sources_.size(); ++k) Deliver(k, Name(k, first, stem));
    DeliverBoard();
    Ok("lumislab-acquire",
       "import --photos camera --setup setup.json --out imported --order name --exposure 1");
    ExpectCaptureOrder("imported", first, stem);
    EXPECT_EQ(Watch("--photos camera --out watched --order name --exposure 1 --settle 0 "
                    "--idle-timeout 20"),
              0)
        << Log();
    EXPECT_EQ(ReadBinaryFile(root_ + "/watched/dataset.json"),
              ReadBinaryFile(root_ + "/imported/dataset.json"))
        << stem;
  }
}

// A manifest without a row for one slide can never complete the grid: watch refuses it at once
// (exit 2, nothing written), with import's message naming the manifest and the position.
TEST_F(WatchSafety, ManifestThatCannotCompleteTheGridIsRefusedAtOnce) {
  std::string manifest = "i,j,slide,file,exposure\n";
  for (size_t k = 0; k + 1 < sources_.size(); ++k) {  // the last photo (2, 2, n) has no row
    const auto [i, j] = ScanPosition(original_.grid, "rows", int(k / 2));
    manifest += std::to_string(i) + "," + std::to_string(j) + "," + (k % 2 == 0 ? "p" : "n") + "," +
                Name(k) + ",1\n";
  }
  testing::WriteFile(root_ + "/captures.csv", manifest);
  for (size_t k = 0; k < sources_.size(); ++k) Deliver(k, Name(k));
  DeliverBoard();
  const std::string message =
      "captures.csv: rows: expected 1 row(s) for slide n at every position of the setup's grid, "
      "got 0 at position (2, 2)";
  const auto import = testing::RunToolIn(
      root_, "lumislab-acquire",
      "import --photos camera --setup setup.json --out imported --manifest captures.csv", 60);
  EXPECT_EQ(import.exit_code, 2) << import.output;
  EXPECT_NE(import.output.find(message), std::string::npos) << import.output;
  // No idle timeout: before, this watch waited forever.
  const auto watch = StartWatch("--photos camera --out watched --manifest captures.csv");
  ASSERT_TRUE(watch->WaitFor(kWaitS)) << Log();
  EXPECT_EQ(watch->exit_code(), 2) << Log();
  EXPECT_NE(Log().find(message), std::string::npos) << Log();
  EXPECT_FALSE(fs::exists(root_ + "/watched/dataset.json"));
}

// --photos F --out F: dataset.json, written into the photo folder, is not a photo (in name order
// it would take the place after the last photo); import --force reads the folder the same way.
TEST_F(WatchSafety, DatasetFolderAsPhotoFolder) {
  const auto watch = StartWatch(
      "--photos camera --out camera --order name --exposure 1 --settle 0.1 --idle-timeout 20");
  ASSERT_TRUE(WaitUntil([&] { return fs::exists(root_ + "/camera/dataset.json"); }, kWaitS))
      << Log();
  for (size_t k = 0; k < sources_.size(); ++k) Deliver(k, Name(k));
  DeliverBoard();
  ASSERT_TRUE(watch->WaitFor(kWaitS)) << Log();
  EXPECT_EQ(watch->exit_code(), 0) << Log();
  const Dataset ds = Dataset::Load(root_ + "/camera");
  EXPECT_FALSE(ds.Partial());
  EXPECT_EQ(ds.photo_folder, "");
  ExpectCaptureOrder("camera", 1, "capt");
  const std::string watched = ReadBinaryFile(root_ + "/camera/dataset.json");
  Ok("lumislab-acquire",
     "import --photos camera --setup setup.json --out camera --order name --exposure 1 --force");
  EXPECT_EQ(ReadBinaryFile(root_ + "/camera/dataset.json"), watched);
}

// A photo taken and then deleted during the capture ends the watch with exit 2 naming it, and
// the capture is never called complete without it.
TEST_F(WatchSafety, DeletedPhotoIsAnErrorNotComplete) {
  const auto watch = StartWatch(
      "--photos camera --out ds --order name --exposure 1 --settle 0.1 --idle-timeout 20");
  for (size_t k = 0; k < 4; ++k) Deliver(k, Name(k));
  ASSERT_TRUE(
      WaitUntil([&] { return Log().find("2/9 positions complete") != std::string::npos; }, kWaitS))
      << Log();
  fs::remove(root_ + "/camera/" + Name(1));
  for (size_t k = 4; k < sources_.size(); ++k) Deliver(k, Name(k));
  DeliverBoard();
  ASSERT_TRUE(watch->WaitFor(kWaitS)) << Log();
  EXPECT_EQ(watch->exit_code(), 2) << Log();
  EXPECT_NE(Log().find("camera/" + Name(1) + ": photo"), std::string::npos) << Log();
  EXPECT_NE(Log().find("gone"), std::string::npos) << Log();
  EXPECT_TRUE(Dataset::Load(root_ + "/ds").Partial());
}

}  // namespace
}  // namespace lumislab
