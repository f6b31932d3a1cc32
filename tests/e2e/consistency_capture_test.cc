// The photos of a capture checked against each other (docs/verifies.md, "The photos of a
// capture"; reconstruct/capture_checks.h, acquire/import.cc): a capture that does not add up is
// refused (exit 2 naming the photos), and a legitimate one passes untouched, its checks recorded
// as passed in checks.json. One small synthetic capture (3 x 2 positions, 320 x 240 16-bit PNG),
// laid out as a camera leaves it (IMG_0001.PNG ... in capture order, rows, p then n).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/dataset.h"
#include "core/slab_compare.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::ReadBinaryFile;
using testing::RunToolIn;

class ConsistencyCapture : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = testing::FreshDir(std::string("consistency_") +
                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
    testing::WriteFile(root_ + "/scene.json",
                       testing::SceneJson(3, 2,
                                          R"({"size_px": [320, 240], "focal_px": 280,
                               "position_mm": [0, -200, 2400], "look_at_mm": [0, 0, 750]})",
                                          R"([{"type": "quantization", "bit_depth": 16}])"));
    Ok("lumislab-acquire", "synth --scene scene.json --out original --truth-resolution 40");
    Ok("lumislab-calibrate", "screen --dataset original");
    const Dataset ds = Dataset::Load(root_ + "/original");
    for (int j = 0; j < ds.grid.nv; ++j)
      for (int i = 0; i < ds.grid.nu; ++i)
        for (const bool positive : {true, false})
          for (const auto& e : ds.PhotosOf(i, j))
            if (e.positive == positive) taken_.push_back(ds.PhotoPath(e.file));
    board_ = ds.PhotoPath(ds.calibration.photo);
    nlohmann::json setup = nlohmann::json::parse(ReadBinaryFile(root_ + "/original/dataset.json"));
    setup.erase("photos");
    setup.erase("synthetic");
    setup["calibration"]["photo"] = "BOARD.PNG";
    testing::WriteFile(root_ + "/setup.json", setup.dump(2));
  }
  // A camera folder holding `photos` named by `name_format` (1, 2, ...) and the board photo.
  void CameraFolder(const std::string& folder, const std::vector<std::string>& photos,
                    const char* name_format) {
    fs::create_directories(root_ + "/" + folder);
    for (size_t k = 0; k < photos.size(); ++k) {
      char name[32];
      std::snprintf(name, sizeof name, name_format, int(k + 1));
      fs::copy_file(photos[k], root_ + "/" + folder + "/" + name);
    }
    fs::copy_file(board_, root_ + "/" + folder + "/BOARD.PNG");
  }
  void Ok(const std::string& tool, const std::string& args) {
    const auto r = RunToolIn(root_, tool, args, 120);
    ASSERT_EQ(r.exit_code, 0) << tool << " " << args << "\n" << r.output;
  }
  // Imported (--order name), calibrated and reconstructed at 40 texels.
  void Chain(const std::string& folder, const std::string& ds) {
    Ok("lumislab-acquire", "import --photos " + folder + " --setup setup.json --out " + ds +
                               " --order name --exposure 1");
    fs::create_directories(root_ + "/" + ds + "/calib");
    fs::copy_file(root_ + "/original/calib/screen.json", root_ + "/" + ds + "/calib/screen.json");
  }
  // reconstruct refused: exit 2, the message holds every one of `parts`.
  std::string Refused(const std::string& ds, const std::vector<std::string>& parts) {
    const auto r = RunToolIn(root_, "lumislab-reconstruct", "--dataset " + ds + " --resolution 40");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    for (const auto& p : parts)
      EXPECT_NE(r.output.find(p), std::string::npos) << p << "\n" << r.output;
    return r.output;
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
  // The values of `check` in <ds>/checks.json's stage "reconstruct", as JSON text.
  std::string Values(const std::string& ds, const std::string& check) {
    const nlohmann::json j =
        nlohmann::json::parse(ReadBinaryFile(root_ + "/" + ds + "/checks.json"));
    for (const auto& c : j["stages"]["reconstruct"]["checks"])
      if (c["check"] == check) return c["values"].dump();
    return "";
  }
  std::string root_, board_;
  std::vector<std::string> taken_;  // the photos in the order they were taken
};

// The legitimate capture passes untouched, its checks recorded; camera counters without zero
// padding (capt1 ... capt12, gphoto2's %n) sort as numbers and give the same slab as padded
// names.
TEST_F(ConsistencyCapture, LegitimateCapturePassesAndUnpaddedNamesGiveTheSameSlab) {
  CameraFolder("padded", taken_, "IMG_%04d.PNG");
  CameraFolder("unpadded", taken_, "capt%d.png");
  Chain("padded", "a");
  Chain("unpadded", "b");
  Ok("lumislab-reconstruct", "--dataset a --resolution 40");
  Ok("lumislab-reconstruct", "--dataset b --resolution 40");
  const SlabComparison c = CompareSlabs(root_ + "/b/slab", root_ + "/a/slab", 0.0);
  EXPECT_EQ(c.positions.size(), 6u);
  EXPECT_LE(c.max_relative_l2, 1e-7);
  for (const char* ds : {"a", "b"}) {
    EXPECT_EQ(Outcome(ds, "reconstruct", "slides.sign"), "passed") << ds;
    EXPECT_EQ(Outcome(ds, "reconstruct", "positions.shift"), "passed") << ds;
    EXPECT_EQ(Outcome(ds, "reconstruct", "positions.distinct"), "passed") << ds;
    std::printf("legitimate: %s\n", Values(ds, "positions.distinct").c_str());
  }
}

// One stray test shot before the capture and the last photo never taken: the count is right, so
// --order name imports it with every photo one place late, which pairs T- of one position with
// T+ of the next at every position. reconstruct refuses it (slides.sign), naming the photos.
TEST_F(ConsistencyCapture, StrayFirstPhotoAndMissingLastOneAreRefused) {
  std::vector<std::string> photos = {taken_[1]};  // a test shot: any photo of the screen
  photos.insert(photos.end(), taken_.begin(), taken_.end() - 1);
  CameraFolder("camera", photos, "IMG_%04d.PNG");
  Chain("camera", "ds");
  Refused("ds", {"slides look swapped", "camera/IMG_", "shifted by one photo", "[slides.sign]"});
  EXPECT_EQ(Outcome("ds", "reconstruct", "slides.sign"), "failed");
  // Run again (the slab is on disk): still refused, the positions read back.
  Refused("ds", {"slides look swapped"});
  // One photo more than the capture: import names the candidates for a stray shot.
  fs::copy_file(taken_.back(), root_ + "/camera/IMG_0013.PNG");
  const auto r = RunToolIn(root_, "lumislab-acquire",
                           "import --photos camera --setup setup.json --out ds2 --order name "
                           "--exposure 1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("stray test shot? (the first photo is IMG_0001.PNG, the last "
                          "IMG_0013.PNG)"),
            std::string::npos)
      << r.output;
}

// dataset.json with p and n exchanged at one position: refused naming both photos.
TEST_F(ConsistencyCapture, SwappedSlidesInDatasetJsonAreRefused) {
  nlohmann::json json = nlohmann::json::parse(ReadBinaryFile(root_ + "/original/dataset.json"));
  // The position with the most light: (1, 0) or (1, 1) (the emitters sit near the grid's
  // centre); swapping both is what a hand-written dataset.json may do.
  for (auto& p : json["photos"])
    if (p["i"] == 1) p["slide"] = p["slide"] == "p" ? "n" : "p";
  fs::create_directories(root_ + "/swapped/calib");
  fs::copy_file(root_ + "/original/calib/screen.json", root_ + "/swapped/calib/screen.json");
  for (const auto& e : fs::directory_iterator(root_ + "/original/photos"))
    fs::create_directories(root_ + "/swapped/photos"),
        fs::copy_file(e.path(), root_ + "/swapped/photos/" + e.path().filename().string());
  fs::copy_file(board_, root_ + "/swapped/" + fs::path(board_).filename().string());
  testing::WriteFile(root_ + "/swapped/dataset.json", json.dump(1));
  Refused("swapped", {"slides look swapped", "pos_1_", "(slide p)", "(slide n)"});
  EXPECT_EQ(Outcome("swapped", "reconstruct", "slides.sign"), "failed");
}

// dataset.json with two neighbouring positions' photos exchanged: the light moves against the
// grid between them, a warning (positions.shift), the slab still written.
TEST_F(ConsistencyCapture, NeighboursExchangedWarn) {
  std::vector<std::string> photos = taken_;
  std::swap(photos[0], photos[2]), std::swap(photos[1], photos[3]);  // (0, 0) <-> (1, 0)
  CameraFolder("camera", photos, "IMG_%04d.PNG");
  Chain("camera", "ds");
  const auto r = RunToolIn(root_, "lumislab-reconstruct", "--dataset ds --resolution 40");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("moves against the grid"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(0, 0) -> (1, 0)"), std::string::npos) << r.output;
  EXPECT_EQ(Outcome("ds", "reconstruct", "positions.shift"), "warning");
}

// Position (1, 0) photographed twice and (2, 0) never: the count is right, so --order name
// gives (2, 0) the second shots of (1, 0). Shot again, with the sensor's noise, or the same files
// listed twice, the two slab images differ far less than neighbours do: warned
// (positions.distinct), naming both positions' photos.
TEST_F(ConsistencyCapture, APositionShotTwiceIsNoticed) {
  std::vector<std::string> photos = taken_;
  fs::create_directories(root_ + "/again");
  for (int k = 0; k < 2; ++k) {  // (1, 0)'s p and n photographed again: 0.2 % brighter, noisy
    cv::Mat again = cv::imread(taken_[2 + k], cv::IMREAD_UNCHANGED), noise(again.size(), CV_32FC3);
    ASSERT_FALSE(again.empty());
    again.convertTo(again, CV_32FC3, 1.002);
    cv::randn(noise, 0, 30);  // codes of 65535
    again += noise;
    again.convertTo(again, CV_16UC3);
    photos[4 + k] = root_ + "/again/" + std::to_string(k) + ".png";
    ASSERT_TRUE(cv::imwrite(photos[4 + k], again));
  }
  CameraFolder("twice", photos, "IMG_%04d.PNG");
  Chain("twice", "ds");
  const auto r = RunToolIn(root_, "lumislab-reconstruct", "--dataset ds --resolution 40");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("positions (1, 0) ("), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("photographed twice"), std::string::npos) << r.output;
  EXPECT_EQ(Outcome("ds", "reconstruct", "positions.distinct"), "warning");
  std::printf("shot twice: %s\n", Values("ds", "positions.distinct").c_str());

  photos[4] = taken_[2], photos[5] = taken_[3];
  CameraFolder("copies", photos, "IMG_%04d.PNG");
  Chain("copies", "ds2");
  Ok("lumislab-reconstruct", "--dataset ds2 --resolution 40");
  EXPECT_EQ(Outcome("ds2", "reconstruct", "positions.distinct"), "warning");
  std::printf("listed twice: %s\n", Values("ds2", "positions.distinct").c_str());
}

// A bracket of two exposures per slide made from the capture (the photo and a copy at a quarter
// of its values): recorded in the right order it passes (brackets.exposure_order recorded as
// passed); with the two exposures exchanged in the manifest it is refused naming both photos.
TEST_F(ConsistencyCapture, BracketWithItsExposuresExchangedIsRefused) {
  fs::create_directories(root_ + "/bracket");
  std::string right = "i,j,slide,file,exposure\n", wrong = right;
  const Dataset ds = Dataset::Load(root_ + "/original");
  for (const PhotoEntry& e : ds.photos) {
    const std::string stem =
        "pos" + std::to_string(e.i) + std::to_string(e.j) + (e.positive ? "p" : "n");
    const cv::Mat full = cv::imread(ds.PhotoPath(e.file), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(full.empty()) << e.file;
    cv::Mat quarter;
    full.convertTo(quarter, full.type(), 0.25);
    cv::imwrite(root_ + "/bracket/" + stem + "_long.png", full);
    cv::imwrite(root_ + "/bracket/" + stem + "_short.png", quarter);
    const std::string row =
        std::to_string(e.i) + "," + std::to_string(e.j) + "," + (e.positive ? "p" : "n") + ",";
    right += row + stem + "_long.png,4\n" + row + stem + "_short.png,1\n";
    wrong += row + stem + "_long.png," + (e.i == 1 && e.j == 0 ? "1" : "4") + "\n" + row + stem +
             "_short.png," + (e.i == 1 && e.j == 0 ? "4" : "1") + "\n";
  }
  fs::copy_file(board_, root_ + "/bracket/BOARD.PNG");
  testing::WriteFile(root_ + "/right.csv", right);
  testing::WriteFile(root_ + "/wrong.csv", wrong);
  for (const char* name : {"right", "wrong"}) {
    Ok("lumislab-acquire", std::string("import --photos bracket --setup setup.json --out ") + name +
                               " --manifest " + name + ".csv");
    fs::create_directories(root_ + "/" + name + "/calib");
    fs::copy_file(root_ + "/original/calib/screen.json", root_ + "/" + name + "/calib/screen.json");
  }
  Ok("lumislab-reconstruct", "--dataset right --resolution 40");
  EXPECT_EQ(Outcome("right", "reconstruct", "brackets.exposure_order"), "passed");
  EXPECT_EQ(Outcome("right", "reconstruct", "slides.sign"), "passed");
  Refused("wrong", {"bracket/pos10p_short.png: exposure", "bracket/pos10p_long.png",
                    "the longer exposure is the darker photo", "[brackets.exposure_order]"});
  EXPECT_EQ(Outcome("wrong", "reconstruct", "brackets.exposure_order"), "failed");
}

// A photo of another size among the capture's (another camera, or a crop): refused naming it.
TEST_F(ConsistencyCapture, PhotoOfAnotherSizeIsRefused) {
  std::vector<std::string> photos = taken_;
  const cv::Mat full = cv::imread(taken_[7], cv::IMREAD_UNCHANGED);
  cv::Mat smaller;
  cv::resize(full, smaller, cv::Size(300, 225), 0, 0, cv::INTER_AREA);
  photos[7] = root_ + "/other_camera.png";
  cv::imwrite(photos[7], smaller);
  CameraFolder("camera", photos, "IMG_%04d.PNG");
  Chain("camera", "ds");
  Refused("ds", {"camera/IMG_0008.PNG", "300"});
}

}  // namespace
}  // namespace lumislab
