// A live acquisition: acquire writes positions one by one (--interval) while calibrate runs on
// the early calibration photo and reconstruct --watch turns each position into slab data as its
// photos arrive. The final slab equals the one made offline from the same photos.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <thread>

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

TEST(Live, WatchFollowsAnAcquisitionInProgress) {
  const std::string dir = FreshDir("live");
  WriteFile(dir + "/scene.json",
            SceneJson(3, 2,
                      R"({"size_px": [800, 600], "focal_px": 650, "position_mm": [0, -400, 2400],
                          "look_at_mm": [0, 0, 750]})",
                      "[]"));
  const std::string ds = dir + "/ds";
  testing::CommandResult acquire_result;
  std::atomic<bool> acquire_done{false};
  std::thread acquire([&] {
    acquire_result = RunTool("lumislab-acquire",
                             "synth --scene " + dir + "/scene.json --out " + ds + " --interval 1");
    acquire_done = true;
  });
  // The calibration photo comes first; calibrate as soon as dataset.json and it exist.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!(fs::exists(ds + "/dataset.json") && fs::exists(ds + "/photos/calib_0.png")) &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  auto r = RunTool("lumislab-calibrate", "screen --dataset " + ds);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The acquisition (6 positions, 1 s apart) is still running when the watch starts.
  const bool started_before_complete = !acquire_done;
  r = RunTool("lumislab-reconstruct", "--dataset " + ds + " --watch --resolution 100");
  acquire.join();
  ASSERT_EQ(acquire_result.exit_code, 0) << acquire_result.output;
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(started_before_complete);
  const SlabInfo info = SlabInfo::Load(ds + "/slab");
  EXPECT_TRUE(info.Complete());
  EXPECT_EQ(info.present.size(), 6u);

  // Offline, from the same photos, into another folder copy: identical slab.
  const std::string offline = dir + "/offline";
  fs::copy(ds, offline, fs::copy_options::recursive);
  fs::remove_all(offline + "/slab");
  r = RunTool("lumislab-reconstruct", "--dataset " + offline + " --resolution 100");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const SlabComparison c = CompareSlabs(ds + "/slab", offline + "/slab", 0.0);
  EXPECT_LE(c.max_relative_l2, 1e-6);
}

}  // namespace
}  // namespace lumislab
