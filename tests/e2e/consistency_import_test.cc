// What acquire import and watch check of a camera folder's photos against each other before any
// pixel is used (docs/verifies.md, "The photos of a capture"; acquire/capture_list.h,
// acquire/import.cc): one camera geometry (EXIF focal length and orientation) in every photo and
// the board photo (camera.same_geometry), the names' order against the EXIF times with watch
// --order name as with import (order.names_and_times), and the positions a manifest or pattern
// gives against the EXIF times (order.positions_and_times). The pixels do not matter here: the
// photos are tiny JPEGs carrying the EXIF a camera writes; the setup is a 2 x 2 synthetic one.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "lib/photo/camera_write.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::ReadBinaryFile;
using testing::RunToolIn;

class ConsistencyImport : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = testing::FreshDir(std::string("consistency_import_") +
                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
    testing::WriteFile(root_ + "/scene.json",
                       testing::SceneJson(2, 2,
                                          R"({"size_px": [160, 120], "focal_px": 140,
                               "position_mm": [0, -200, 2400], "look_at_mm": [0, 0, 750]})",
                                          "[]"));
    const auto r = RunToolIn(root_, "lumislab-acquire",
                             "synth --scene scene.json --out original --truth-resolution 20", 120);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    nlohmann::json setup = nlohmann::json::parse(ReadBinaryFile(root_ + "/original/dataset.json"));
    setup.erase("photos");
    setup.erase("synthetic");
    setup["calibration"]["photo"] = "BOARD.JPG";
    testing::WriteFile(root_ + "/setup.json", setup.dump(2));
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(root_);
  }

  // The k-th photo taken (0 ..  7; rows, p then n at each position) and its grid place.
  static int I(int k) { return (k / 2) % 2; }
  static int J(int k) { return k / 4; }
  static bool Positive(int k) { return k % 2 == 0; }

  // A camera folder: the eight photos of the 2 x 2 grid named IMG_0001.JPG ... (or by `name`)
  // in capture order, one a minute from 10:01, a 35 mm focal length, upright, and BOARD.JPG
  // (k = -1) taken at 10:00; `change` edits a photo's EXIF.
  void Folder(const std::string& folder, const std::function<void(int, PhotoExif&)>& change = {},
              const std::function<std::string(int)>& name = {}) {
    fs::create_directories(root_ + "/" + folder);
    const cv::Mat grey(24, 32, CV_8UC3, cv::Scalar(90, 90, 90));
    for (int k = -1; k < 8; ++k) {
      PhotoExif exif;
      exif.make = "Lumislab";
      exif.model = "Synthetic 1";
      exif.exposure_time = 1.0 / 30;
      exif.f_number = 8;
      exif.iso = 200;
      exif.focal_length = 35;
      exif.orientation = 1;
      char text[64];
      std::snprintf(text, sizeof text, "2026:12:01 10:%02d:00", k + 1);
      exif.date_time = text;
      if (change) change(k, exif);
      WriteJpeg(root_ + "/" + folder + "/" + (k < 0 ? "BOARD.JPG" : Name(k, name)), grey, 90, exif);
    }
  }
  static std::string Name(int k, const std::function<std::string(int)>& name) {
    if (name) return name(k);
    char text[32];
    std::snprintf(text, sizeof text, "IMG_%04d.JPG", k + 1);
    return text;
  }
  testing::CommandResult Acquire(const std::string& args) {
    return RunToolIn(root_, "lumislab-acquire", args, 60);
  }
  // The outcome of `check` in <ds>/checks.json's stage `stage` ("" when absent).
  std::string Outcome(const std::string& ds, const std::string& stage, const std::string& check) {
    const std::string text = ReadBinaryFile(root_ + "/" + ds + "/checks.json");
    if (text.empty()) return "";
    const nlohmann::json j = nlohmann::json::parse(text);
    if (!j["stages"].contains(stage)) return "";
    for (const auto& c : j["stages"][stage]["checks"])
      if (c["check"] == check) return c["outcome"];
    return "";
  }
  static void ExpectHas(const testing::CommandResult& r, const std::vector<std::string>& parts) {
    for (const auto& p : parts)
      EXPECT_NE(r.output.find(p), std::string::npos) << p << "\n" << r.output;
  }
  std::string root_;
};

// A legitimate folder: import and watch (--order name) pass it, the geometry and the order
// recorded as checked; so does a manifest that lists the photos as they were taken.
TEST_F(ConsistencyImport, LegitimateFolderPasses) {
  Folder("camera");
  auto r = Acquire("import --photos camera --setup setup.json --out ds --order name");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(Outcome("ds", "acquire import", "camera.same_geometry"), "passed");
  EXPECT_EQ(Outcome("ds", "acquire import", "order.names_and_times"), "passed");
  const nlohmann::json checks = nlohmann::json::parse(ReadBinaryFile(root_ + "/ds/checks.json"));
  EXPECT_NE(checks.dump().find("35 mm"), std::string::npos) << checks.dump(2);

  r = Acquire(
      "watch --photos camera --setup setup.json --out watched --order name --settle 0 "
      "--poll 0.05 --idle-timeout 10");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(Outcome("watched", "acquire watch", "camera.same_geometry"), "passed");
  EXPECT_EQ(Outcome("watched", "acquire watch", "order.names_and_times"), "passed");

  std::string manifest = "i,j,slide,file\n";
  for (int k = 0; k < 8; ++k)
    manifest += std::to_string(I(k)) + "," + std::to_string(J(k)) + "," +
                (Positive(k) ? "p," : "n,") + Name(k, {}) + "\n";
  testing::WriteFile(root_ + "/captures.csv", manifest);
  r = Acquire(
      "import --photos camera --setup setup.json --out by_manifest --manifest captures.csv");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(Outcome("by_manifest", "acquire import", "order.positions_and_times"), "passed");
}

// The zoom touched before the fifth photo, the camera's orientation sensor turning the third,
// and a board photo at another focal length: each refused naming the photo, the field and both
// values, and recorded as failed where the dataset folder exists.
TEST_F(ConsistencyImport, AnotherFocalLengthOrOrientationIsRefused) {
  Folder("zoom", [](int k, PhotoExif& e) {
    if (k == 4) e.focal_length = 50;
  });
  fs::create_directories(root_ + "/ds_zoom");
  auto r = Acquire("import --photos zoom --setup setup.json --out ds_zoom --order name");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  ExpectHas(r, {"zoom/IMG_0005.JPG: EXIF focal length: expected 35 mm as in zoom/IMG_0001.JPG",
                "got 50 mm", "[camera.same_geometry]"});
  EXPECT_EQ(Outcome("ds_zoom", "acquire import", "camera.same_geometry"), "failed");
  EXPECT_FALSE(fs::exists(root_ + "/ds_zoom/dataset.json"));

  Folder("turned", [](int k, PhotoExif& e) {
    if (k == 2) e.orientation = 3;
  });
  r = Acquire("import --photos turned --setup setup.json --out ds_turned --order name");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  ExpectHas(r, {"turned/IMG_0003.JPG: EXIF orientation: expected 1 (upright)",
                "got 3 (turned 180 degrees)"});

  Folder("board", [](int k, PhotoExif& e) {
    if (k < 0) e.focal_length = 50;
  });
  r = Acquire("import --photos board --setup setup.json --out ds_board --order name");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  ExpectHas(r, {"board/BOARD.JPG: EXIF focal length: expected 35 mm", "got 50 mm"});
}

// watch --order name checks the names against the EXIF times as import does (one
// implementation, acquire/capture_list.h NameTimeOrder): the third and fourth photos taken were
// given each other's names.
TEST_F(ConsistencyImport, WatchByNameRefusesTimesThatRunBackwards) {
  Folder("camera", {}, [](int k) {
    const int named = k == 2 ? 3 : k == 3 ? 2 : k;
    char text[32];
    std::snprintf(text, sizeof text, "IMG_%04d.JPG", named + 1);
    return std::string(text);
  });
  const auto r = Acquire(
      "watch --photos camera --setup setup.json --out ds --order name --settle 0 --poll 0.05 "
      "--idle-timeout 10");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  ExpectHas(r, {"camera/IMG_0004.JPG: EXIF DateTimeOriginal: expected 2026:12:01 10:04:00",
                "taken after IMG_0003.JPG", "[order.names_and_times]"});
  EXPECT_EQ(Outcome("ds", "acquire watch", "order.names_and_times"), "failed");
}

// The positions a manifest or a pattern gives, against the EXIF times, slide by slide: a
// manifest whose rows give two positions each other's files, and a pattern capture scanned
// serpentine imported with --scan rows, warn (exit 0: the rows need not be in capture order);
// the same pattern with --scan serpentine passes.
TEST_F(ConsistencyImport, PositionsAgainstExifTimesWarn) {
  Folder("camera");
  std::string manifest = "i,j,slide,file\n";
  for (int k = 0; k < 8; ++k) {
    const int file = k == 2 ? 4 : k == 4 ? 2 : k;  // positions (1, 0) and (0, 1), slide p
    manifest += std::to_string(I(k)) + "," + std::to_string(J(k)) + "," +
                (Positive(k) ? "p," : "n,") + Name(file, {}) + "\n";
  }
  testing::WriteFile(root_ + "/captures.csv", manifest);
  auto r = Acquire("import --photos camera --setup setup.json --out ds --manifest captures.csv");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ExpectHas(r, {"[order.positions_and_times]", "camera/IMG_0003.JPG: EXIF time 2026:12:01 10:03:00",
                "captures.csv lists before it"});
  EXPECT_EQ(Outcome("ds", "acquire import", "order.positions_and_times"), "warning");

  // Serpentine: the second row of positions taken right to left.
  Folder("serpentine", {}, [](int k) {
    const int i = J(k) == 1 ? 1 - I(k) : I(k);
    return "pos_" + std::to_string(i) + "_" + std::to_string(J(k)) + "_" +
           (Positive(k) ? "p" : "n") + ".JPG";
  });
  r = Acquire(
      "import --photos serpentine --setup setup.json --out rows --pattern "
      "pos_{i}_{j}_{slide}.JPG");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ExpectHas(r, {"[order.positions_and_times]", "the scan (--scan rows) takes before it"});
  r = Acquire(
      "import --photos serpentine --setup setup.json --out serp --pattern "
      "pos_{i}_{j}_{slide}.JPG --scan serpentine");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(Outcome("serp", "acquire import", "order.positions_and_times"), "passed");
}

}  // namespace
}  // namespace lumislab
