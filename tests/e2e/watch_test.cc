// lumislab-acquire watch (docs/formats.md §3): a camera folder filled while the tool watches it,
// the way tethering software fills it. The test plays the camera: it drops the photos of a
// synthetic capture into the folder one position at a time (one of them written slowly under
// its final name, as a plain copy does, plus files with temporary names), and checks that
// dataset.json grows by whole positions, that the slowly written file is not read before it is
// complete, that `reconstruct --watch` follows live to the slab of the original photos, and
// that the final dataset.json is the one `import` writes for the finished folder. Stop signals,
// the idle timeout and bad photos end the watch with the codes of docs/architecture.md §7.2, naming
// the file.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/dataset.h"
#include "core/slab.h"
#include "core/slab_compare.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::ReadBinaryFile;
using testing::ToolProcess;
using testing::WaitUntil;

constexpr double kWaitS = 60;  // deadline of any wait for the tool (a failure, not a timing)

class Watch : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = testing::FreshDir(std::string("watch_") +
                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
    testing::WriteFile(root_ + "/scene.json",
                       testing::SceneJson(2, 2,
                                          R"({"size_px": [320, 240], "focal_px": 280,
                               "position_mm": [0, -200, 2400], "look_at_mm": [0, 0, 750]})",
                                          "[]"));
    Ok("lumislab-acquire", "synth --scene scene.json --out original --truth-resolution 40");
    original_ = Dataset::Load(root_ + "/original");
    // What the camera will write, in capture order (rows, p then n): IMG_0001.EXR, ...
    for (int q = 0; q < original_.grid.count(); ++q) {
      const int i = q % original_.grid.nu, j = q / original_.grid.nu;
      for (const bool positive : {true, false})
        for (const auto& e : original_.PhotosOf(i, j))
          if (e.positive == positive) sources_.push_back(original_.PhotoPath(e.file));
    }
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
  std::string Name(size_t k) const {
    char name[32];
    std::snprintf(name, sizeof name, "IMG_%04zu.EXR", k + 1);
    return name;
  }
  // Photo k arrives as careful tools write: a temporary name, then a rename.
  void Deliver(size_t k) const {
    const std::string tmp = root_ + "/camera/." + Name(k) + ".tmp";
    fs::copy_file(sources_[k], tmp);
    fs::rename(tmp, root_ + "/camera/" + Name(k));
  }
  void DeliverBoard() const {
    fs::copy_file(original_.PhotoPath(original_.calibration.photo), root_ + "/camera/BOARD.PNG");
  }
  // Photos dataset.json lists now (-1 while there is none).
  int Listed() const {
    const std::string text = ReadBinaryFile(root_ + "/ds/dataset.json");
    if (text.empty()) return -1;
    return int(nlohmann::json::parse(text)["photos"].size());
  }
  std::unique_ptr<ToolProcess> StartWatch(const std::string& extra) const {
    std::vector<std::string> args = {"watch", "--photos", "camera",  "--setup", "setup.json",
                                     "--out", "ds",       "--order", "name",    "--exposure",
                                     "1",     "--poll",   "0.05"};
    std::istringstream more(extra);
    for (std::string a; more >> a;) args.push_back(a);
    return std::make_unique<ToolProcess>(root_, "lumislab-acquire", args, root_ + "/watch.log");
  }
  std::string Log() const { return ReadBinaryFile(root_ + "/watch.log"); }

  std::string root_;
  Dataset original_;
  std::vector<std::string> sources_;  // photo k of the capture order
};

TEST_F(Watch, FollowsTheCaptureAsPhotosArrive) {
  const auto watch = StartWatch("--settle 0.8 --idle-timeout 30");
  // dataset.json at once: the setup, no photos, every position missing.
  ASSERT_TRUE(WaitUntil([&] { return Listed() == 0; }, kWaitS)) << Log();
  const Dataset empty = Dataset::Load(root_ + "/ds");
  EXPECT_EQ(empty.missing_positions.size(), 4u);
  EXPECT_EQ(empty.photo_folder, "../camera");
  // reconstruct --watch follows the growing dataset (the screen calibration of the original).
  Ok("lumislab-calibrate", "screen --dataset original");
  fs::create_directories(root_ + "/ds/calib");
  fs::copy_file(root_ + "/original/calib/screen.json", root_ + "/ds/calib/screen.json");
  testing::CommandResult live;
  std::thread reconstruct([&] {
    live = testing::RunToolIn(root_, "lumislab-reconstruct",
                              "--dataset ds --watch --resolution 40 --poll 0.05 --idle-timeout 30",
                              kWaitS);
  });

  DeliverBoard();
  Deliver(0);
  EXPECT_EQ(Listed(), 0) << "a position with one slide is not complete";
  Deliver(1);
  ASSERT_TRUE(WaitUntil([&] { return Listed() == 2; }, kWaitS)) << Log();

  // Photo 2 is copied slowly under its final name: 6 chunks, 0.1 s apart (less than the settle
  // time, 0.8 s). Read before it is whole, it would be refused (exit 2) or misplaced.
  const std::string bytes = ReadBinaryFile(sources_[2]);
  {
    std::ofstream out(root_ + "/camera/" + Name(2), std::ios::binary);
    for (size_t c = 0; c < 6; ++c) {
      out.write(bytes.data() + c * bytes.size() / 6,
                std::streamsize((c + 1) * bytes.size() / 6 - c * bytes.size() / 6));
      out.flush();
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      EXPECT_TRUE(watch->Running()) << Log();
    }
  }
  Deliver(3);
  ASSERT_TRUE(WaitUntil([&] { return Listed() == 4; }, kWaitS)) << Log();
  // Names a download or an editor uses while writing are never taken (in name order they would
  // take the next places of the capture, or be refused as no image).
  testing::WriteFile(root_ + "/camera/IMG_0005.EXR.part", "half a photo");
  testing::WriteFile(root_ + "/camera/~IMG_0006.EXR", "a lock file");
  for (size_t k = 4; k < sources_.size(); ++k) Deliver(k);
  // Complete: the watch ends by itself.
  ASSERT_TRUE(watch->WaitFor(kWaitS));
  EXPECT_EQ(watch->exit_code(), 0) << Log();
  reconstruct.join();
  ASSERT_EQ(live.exit_code, 0) << live.output;
  const Dataset done = Dataset::Load(root_ + "/ds");
  EXPECT_FALSE(done.Partial());
  EXPECT_EQ(done.photos.size(), 8u);

  // The same folder imported at once gives the same dataset.json, and the live slab is the
  // original photos' slab.
  Ok("lumislab-acquire",
     "import --photos camera --setup setup.json --out imported --order name --exposure 1");
  EXPECT_EQ(ReadBinaryFile(root_ + "/ds/dataset.json"),
            ReadBinaryFile(root_ + "/imported/dataset.json"));
  Ok("lumislab-reconstruct", "--dataset original --resolution 40");
  const SlabComparison c = CompareSlabs(root_ + "/ds/slab", root_ + "/original/slab", 0.0);
  EXPECT_EQ(c.positions.size(), 4u);
  EXPECT_LE(c.max_relative_l2, 1e-7);
}

// SIGINT and SIGTERM end a watch within a second (it waits in 50 ms slices), exit 1, with
// dataset.json as the last complete position left it; the same command goes on. The idle
// timeout ends it the same way.
TEST_F(Watch, StopsOnSignalAndIdleTimeout) {
  for (const int signal : {SIGINT, SIGTERM}) {
    const auto watch = StartWatch("--settle 0.2");
    if (signal == SIGINT) {
      Deliver(0);
      Deliver(1);
    }
    // The second run starts over and takes the two photos again.
    ASSERT_TRUE(WaitUntil([&] { return Log().find("1/4 positions complete") != std::string::npos; },
                          kWaitS))
        << Log();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // waiting now
    const auto start = std::chrono::steady_clock::now();
    ASSERT_TRUE(watch->Signal(signal));
    ASSERT_TRUE(watch->WaitFor(kWaitS));
    const double stop_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(stop_s, 1.0) << signal;
    EXPECT_EQ(watch->exit_code(), 1) << Log();
    EXPECT_NE(Log().find("interrupted: the dataset is partial (3 position(s) missing"),
              std::string::npos)
        << Log();
    EXPECT_EQ(Dataset::Load(root_ + "/ds").missing_positions.size(), 3u);
    EXPECT_EQ(testing::CountTemporaryFiles(root_ + "/ds"), 0);
  }
  const auto idle = StartWatch("--settle 0.2 --idle-timeout 0.5");
  ASSERT_TRUE(idle->WaitFor(kWaitS));
  EXPECT_EQ(idle->exit_code(), 1) << Log();
  EXPECT_NE(Log().find("no new file for"), std::string::npos) << Log();
}

// A file that has settled and is bad ends the watch with exit 2 naming it: not an image (or cut
// short), another image size, a photo more than the grid holds.
TEST_F(Watch, BadPhotoIsRefusedNamingIt) {
  const auto refused = [&](const std::string& what) {
    const auto watch = StartWatch("--settle 0.2 --idle-timeout 20");
    EXPECT_TRUE(watch->WaitFor(kWaitS));
    EXPECT_EQ(watch->exit_code(), 2) << Log();
    EXPECT_NE(Log().find(what), std::string::npos) << Log();
  };
  Deliver(0);
  testing::WriteFile(root_ + "/camera/" + Name(1), "not an image\n");
  refused("camera/" + Name(1));
  // A photo cut short (a copy that stopped half way).
  const std::string bytes = ReadBinaryFile(sources_[1]);
  testing::WriteBinaryFile(root_ + "/camera/" + Name(1), bytes.substr(0, bytes.size() / 2));
  refused("camera/" + Name(1));
  // Another size: a photo of another camera among them.
  fs::remove(root_ + "/camera/" + Name(1));
  testing::WriteFile(root_ + "/scene2.json",
                     testing::SceneJson(2, 2,
                                        R"({"size_px": [160, 120], "focal_px": 140,
                               "position_mm": [0, -200, 2400], "look_at_mm": [0, 0, 750]})",
                                        "[]"));
  Ok("lumislab-acquire", "synth --scene scene2.json --out other --truth-resolution 8");
  fs::copy_file(root_ + "/other/photos/pos_0_0_n.exr", root_ + "/camera/" + Name(1));
  refused("camera/" + Name(1) + ": image size: expected \"320 x 240 px\"");
}

}  // namespace
}  // namespace lumislab
