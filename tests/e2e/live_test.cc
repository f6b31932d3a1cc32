// A live acquisition, driven step by step so that nothing depends on who wins a race: the test
// hands the photos of one position at a time to a running `reconstruct --watch` (written under a
// temporary name and renamed, as acquire does) and waits for that position, and only that one,
// to appear in the slab before it hands over the next. Every wait has a deadline and the watcher
// has an idle timeout, so a failure ends the test instead of hanging it. The final slab equals
// the one reconstructed offline from the same photos.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <thread>

#include "core/dataset.h"
#include "core/slab.h"
#include "core/slab_compare.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::FreshDir;
using testing::RunTool;
using testing::SceneJson;
using testing::WriteFile;

using testing::WaitUntil;

// Moves the photos of (i, j) from `from` into `to` the way a capture writes them: a temporary
// name in the same folder, then a rename.
void DeliverPhotos(const Dataset& from, const std::string& to, int i, int j) {
  for (const auto& e : from.PhotosOf(i, j)) {
    const fs::path final_path = fs::path(to) / e.file;
    const fs::path tmp = final_path.parent_path() / ("." + final_path.filename().string());
    fs::copy_file(from.Path(e.file), tmp);
    fs::rename(tmp, final_path);
  }
}

TEST(Live, WatchFollowsPositionsAsTheirPhotosArrive) {
  const std::string dir = FreshDir("live");
  WriteFile(dir + "/scene.json",
            SceneJson(3, 2,
                      R"({"size_px": [800, 600], "focal_px": 650, "position_mm": [0, -400, 2400],
                          "look_at_mm": [0, 0, 750]})",
                      "[]"));
  // The photos, made beforehand; the live folder starts with dataset.json and the calibration.
  const std::string source = dir + "/source";
  auto r = RunTool("lumislab-acquire", "synth --scene " + dir + "/scene.json --out " + source);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunTool("lumislab-calibrate", "screen --dataset " + source);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Dataset photos = Dataset::Load(source);
  const std::string live = dir + "/live";
  fs::create_directories(live + "/photos");
  fs::copy(source + "/calib", live + "/calib");
  fs::copy(source + "/truth", live + "/truth");
  fs::copy_file(source + "/dataset.json", live + "/dataset.json");

  testing::CommandResult watch;
  std::thread watcher([&] {
    watch = RunTool("lumislab-reconstruct", "--dataset " + live +
                                                " --watch --resolution 100 --poll 0.05"
                                                " --idle-timeout 60");
  });
  const std::string slab = live + "/slab";
  for (int q = 0; q < photos.grid.count(); ++q) {
    const int i = q % photos.grid.nu, j = q / photos.grid.nu;
    // Nothing of (i, j) before its photos are there.
    EXPECT_FALSE(fs::exists(SlabPositionPath(slab, i, j))) << i << "," << j;
    DeliverPhotos(photos, live, i, j);
    EXPECT_TRUE(WaitUntil([&] { return fs::exists(SlabPositionPath(slab, i, j)); }, 60))
        << "position " << i << "," << j << " never reached the slab";
    EXPECT_EQ(ScanSlabPositions(slab, SlabInfo::Load(slab)).size(), size_t(q + 1));
  }
  watcher.join();  // the watcher ends by itself once the grid is complete (or times out)
  ASSERT_EQ(watch.exit_code, 0) << watch.output;
  const SlabInfo info = SlabInfo::Load(slab);
  EXPECT_TRUE(info.Complete());
  EXPECT_EQ(info.present.size(), 6u);

  // Offline, from the same photos: the same slab.
  r = RunTool("lumislab-reconstruct", "--dataset " + source + " --resolution 100");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const SlabComparison c = CompareSlabs(slab, source + "/slab", 0.0);
  EXPECT_EQ(c.positions.size(), 6u);
  EXPECT_LE(c.max_relative_l2, 1e-6);
}

// acquire --interval writes dataset.json and the calibration photo first and the positions one
// by one; a watcher started at any moment ends with the complete slab (bounded by its idle
// timeout).
TEST(Live, IntervalAcquisitionEndsWithACompleteSlab) {
  const std::string dir = FreshDir("live_interval");
  WriteFile(dir + "/scene.json",
            SceneJson(2, 2,
                      R"({"size_px": [640, 480], "focal_px": 520, "position_mm": [0, -400, 2400],
                          "look_at_mm": [0, 0, 750]})",
                      "[]"));
  const std::string ds = dir + "/ds";
  testing::CommandResult acquire;
  std::thread acquirer([&] {
    acquire = RunTool("lumislab-acquire",
                      "synth --scene " + dir + "/scene.json --out " + ds + " --interval 0.3");
  });
  ASSERT_TRUE(WaitUntil(
      [&] { return fs::exists(ds + "/dataset.json") && fs::exists(ds + "/photos/calib_0.png"); },
      60));
  auto r = RunTool("lumislab-calibrate", "screen --dataset " + ds);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = RunTool("lumislab-reconstruct",
              "--dataset " + ds + " --watch --resolution 60 --poll 0.05 --idle-timeout 60");
  acquirer.join();
  ASSERT_EQ(acquire.exit_code, 0) << acquire.output;
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(SlabInfo::Load(ds + "/slab").Complete());
}

}  // namespace
}  // namespace lumislab
