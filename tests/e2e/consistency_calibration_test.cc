// The radiometric calibration products checked against their own frames and against physics
// (issue 28; calibrate/radiometric/calibration_checks.h, docs/verifies.md "Calibration"): the
// chain cases a lab makes by mistake are refused at the step that reads them (exit 2 naming the
// files and the measured number), and a legitimate chain passes every check with its Pass record
// in checks.json.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/json.h"
#include "core/screen_calibration.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::FreshDir;
using testing::ReadBinaryFile;
using testing::RunTool;
using testing::SceneJson;
using testing::WriteFile;

// 320 x 240 px behind the screen; the JPEG camera of tests/e2e/real_camera_chain.h (its lab, its
// dark signal, sensor noise, three brackets, a gamma-and-shoulder curve) with its calibration
// captures, a five-frame whole-stop response series.
const char* kCamera =
    R"({"size_px": [320, 240], "focal_px": 260, "position_mm": [0, -400, 2400],
        "look_at_mm": [0, 0, 750]})";
const char* kEffects = R"([
  {"type": "screen_gain", "amplitude": 0.15, "blobs": 6, "size_mm": 250, "seed": 2},
  {"type": "ambient", "level": 0.02}, {"type": "vignetting", "k1": -0.1},
  {"type": "dark", "black_level": 0.001, "dark_current": 0.0005, "hot_fraction": 0.0005,
   "hot_current": 0.5, "seed": 3},
  {"type": "sensor_noise", "full_well_e": 30000, "read_noise_e": 4, "seed": 11},
  {"type": "brackets", "stops": [-2, 0, 2]},
  {"type": "response", "curve": "gamma", "gamma": 2.2, "shoulder": 0.5, "quality": 95}])";
const char* kCaptures =
    R"({"dark_frames": 2, "dark_stops": [-2, 2], "flat_frames": 2, "flat_level": 0.5,
        "response_stops": [-2, -1, 0, 1, 2],
        "reference": {"position": [1, 1], "point_mm": [0, 0]}})";

class ConsistencyCalibration : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = FreshDir(std::string("consistency_calibration_") +
                    ::testing::UnitTest::GetInstance()->current_test_info()->name());
    WriteFile(dir_ + "/scene.json",
              SceneJson(3, 3, kCamera,
                        std::string(kEffects) + ", \"calibration_captures\": " + kCaptures));
    ds_ = dir_ + "/ds";
    const auto r = RunTool("lumislab-acquire", "synth --scene " + dir_ + "/scene.json --out " +
                                                   ds_ + " --truth-resolution 20");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // A JPEG camera clips at 0.95 of full scale (tests/e2e/real_camera_chain.h).
    nlohmann::json d = nlohmann::json::parse(ReadBinaryFile(ds_ + "/dataset.json"));
    d["radiometry"]["saturation_level"] = 0.95;
    WriteFile(ds_ + "/dataset.json", d.dump(2));
  }
  void TearDown() override {
    if (!HasFailure() && !std::getenv("LUMISLAB_KEEP_CASES")) fs::remove_all(dir_);
  }
  // The frames of one kind in the capture manifest (darkest first for the response series) and
  // their exposures.
  void Frames(const std::string& kind, std::vector<std::string>* files,
              std::vector<double>* exposures) const {
    const JsonDocument doc = JsonDocument::Load(ds_ + "/calibration/captures.json");
    const JsonView list = doc.root()[kind];
    for (size_t k = 0; k < list.Size(); ++k) {
      files->push_back(ds_ + "/" + list[k]["file"].String());
      exposures->push_back(list[k]["exposure"].Number());
    }
  }
  static std::string Args(const std::vector<std::string>& files,
                          const std::vector<double>& exposures) {
    std::string f, e;
    for (size_t k = 0; k < files.size(); ++k)
      f += " " + files[k], e += (k ? "," : "") + std::to_string(exposures[k]);
    return " --frames" + f + " --exposures " + e;
  }
  testing::CommandResult Calibrate(const std::string& step, const std::string& args) {
    return RunTool("lumislab-calibrate", step + " --force --dataset " + ds_ + args);
  }
  int Step(const std::string& kind) {
    std::vector<std::string> files;
    std::vector<double> exposures;
    Frames(kind, &files, &exposures);
    const auto r = Calibrate(kind, Args(files, exposures));
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return r.exit_code;
  }
  // calib/screen.json from the true camera, as tests/e2e/radiometry_test.cc (the screen step is
  // not what is checked here).
  void WriteTrueScreen() {
    const JsonDocument cam = JsonDocument::Load(ds_ + "/truth/camera.json");
    ScreenCalibration c;
    c.image_width = 320;
    c.image_height = 240;
    const std::vector<double> h = cam.root()["screen_from_image"].Numbers(9);
    for (int k = 0; k < 9; ++k) c.screen_from_image(k / 3, k % 3) = h[k];
    c.centre_px = {159.5, 119.5};
    c.scale_px = 200;
    fs::create_directories(ds_ + "/calib");
    c.Save(ds_ + "/calib/screen.json");
  }
  // The records of one stage in checks.json: id -> outcome.
  std::map<std::string, std::string> Outcomes(const std::string& stage) const {
    std::map<std::string, std::string> out;
    const nlohmann::json j = nlohmann::json::parse(ReadBinaryFile(ds_ + "/checks.json"));
    for (const auto& r : j["stages"][stage]["checks"]) out[r["check"]] = r["outcome"];
    return out;
  }
  std::string dir_, ds_;
};

// The legitimate chain: response, dark, flat and scale each pass their checks untouched.
TEST_F(ConsistencyCalibration, LegitimateChainPassesEveryCheck) {
  ASSERT_EQ(Step("response"), 0);
  ASSERT_EQ(Step("dark"), 0);
  WriteTrueScreen();
  ASSERT_EQ(Step("flat"), 0);
  const auto r = Calibrate("scale", " --reference " + ds_ + "/truth/reference.json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
  using Map = std::map<std::string, std::string>;
  EXPECT_EQ(Outcomes("calibrate response"), (Map{{"response.exposure_order", "passed"},
                                                 {"response.fit_explains_frames", "passed"}}));
  EXPECT_EQ(Outcomes("calibrate dark"), (Map{{"dark.is_dark", "passed"}}));
  EXPECT_EQ(Outcomes("calibrate flat"),
            (Map{{"flat.has_signal", "passed"}, {"flat.is_flat", "passed"}}));
  EXPECT_EQ(Outcomes("calibrate scale"), (Map{{"scale.point_lit", "passed"},
                                              {"scale.brackets_agree", "passed"},
                                              {"scale.matches_dataset", "passed"}}));
  // The ratios the data imply, per consecutive pair, in response.json's report.
  const nlohmann::json report =
      nlohmann::json::parse(ReadBinaryFile(ds_ + "/calib/response.json"))["report"];
  ASSERT_EQ(report["pairs"].size(), 4u);
  for (const auto& p : report["pairs"])
    EXPECT_NEAR(p["implied_ratio"].get<double>() / p["stated_ratio"].get<double>(), 1, 0.03) << p;
}

// Frames in a shell glob's order (ev+0, ev+1, ev+2, ev-1, ev-2) with --exposures in stop order:
// refused at the response, naming the two files, their stated exposures and the implied order.
TEST_F(ConsistencyCalibration, GlobOrderedResponseSeriesIsRefused) {
  std::vector<std::string> files;
  std::vector<double> exposures;
  Frames("response", &files, &exposures);  // stops -2 .. 2
  std::vector<std::string> glob = files;
  std::sort(glob.begin(), glob.end());  // '+' sorts before '-'
  ASSERT_NE(glob, files);
  const auto r = Calibrate("response", Args(glob, exposures));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("[response.exposure_order]"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("exposure: stated"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("the order (darkest first) " + files[0] + ", " + files[1]),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(ds_ + "/calib/response.json"));
  EXPECT_EQ(Outcomes("calibrate response")["response.exposure_order"], "failed");
}

// The order kept but the last frame's exposure stated a stop too long: no curve explains the
// frames with these exposures.
TEST_F(ConsistencyCalibration, MisstatedExposureIsRefusedByTheFit) {
  std::vector<std::string> files;
  std::vector<double> exposures;
  Frames("response", &files, &exposures);
  exposures.back() *= 2;
  const auto r = Calibrate("response", Args(files, exposures));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(files.back() + ": exposure"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("[response.fit_explains_frames]"), std::string::npos) << r.output;
}

// Slide photos, or an all-white frame, given as dark frames; a dark frame given as a flat.
TEST_F(ConsistencyCalibration, LightIsNotADarkFrameAndDarkIsNotAFlat) {
  const nlohmann::json d = nlohmann::json::parse(ReadBinaryFile(ds_ + "/dataset.json"));
  const std::string slide = ds_ + "/" + d["photos"][0]["file"].get<std::string>();
  auto r = Calibrate("dark", " --frames " + slide + " --exposures 1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(slide + ": pixel data"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("[dark.is_dark]"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(ds_ + "/calib/dark.json"));
  std::vector<std::string> files;
  std::vector<double> exposures;
  Frames("flat", &files, &exposures);
  r = Calibrate("dark", " --frames " + files[0] + " --exposures 1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(files[0] + ": "), std::string::npos) << r.output;
  // A dark frame as a flat: no light.
  files.clear(), exposures.clear();
  Frames("dark", &files, &exposures);
  WriteTrueScreen();
  r = Calibrate("flat", " --frames " + files[0] + " --exposures 1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(files[0] + ": pixel data"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("[flat.has_signal]"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(ds_ + "/calib/flat.json"));
}

// A meter reading taken where the photos see no light of the luminaire: the scale would be
// their noise.
TEST_F(ConsistencyCalibration, ScaleAtAnUnlitPointIsRefused) {
  WriteTrueScreen();
  const auto r = Calibrate("scale",
                           " --position 1,1 --point-mm 500,-500 --reading-p 1 "
                           "--reading-n 0.5");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("command line: point_mm"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("[scale.point_lit]"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(ds_ + "/calib/scale.json"));
}

// The refusals inside the fits are recorded in checks.json as failed checks of their stage, as
// the checks after them are: a response series with nothing that changes over it (one frame
// given twice: response.samples), a flat frame with the screen clipped (the longest bracket of a
// slide photo: flat.clipped), and a scale whose photos through T+ are darker than through T-
// (the slides swapped in dataset.json at the reference position: scale.point_lit).
TEST_F(ConsistencyCalibration, RefusalsInsideTheFitsAreRecorded) {
  std::vector<std::string> files;
  std::vector<double> exposures;
  Frames("response", &files, &exposures);
  auto r = Calibrate("response", " --frames " + files[2] + " " + files[2] + " --exposures 1,2");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(files[2] + ": frames: expected at least 20 pixels"), std::string::npos)
      << r.output;
  EXPECT_EQ(Outcomes("calibrate response")["response.samples"], "failed");

  WriteTrueScreen();
  nlohmann::json d = nlohmann::json::parse(ReadBinaryFile(ds_ + "/dataset.json"));
  std::string longest;
  double longest_exposure = 0;
  for (const auto& e : d["photos"])
    if (e["i"] == 1 && e["j"] == 1 && e["slide"] == "p" &&
        e["exposure"].get<double>() > longest_exposure)
      longest_exposure = e["exposure"], longest = ds_ + "/" + e["file"].get<std::string>();
  r = Calibrate("flat", " --frames " + longest + " --exposures 1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(longest + ": pixel data: expected a flat frame with at most 0.1 %"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(Outcomes("calibrate flat")["flat.clipped"], "failed");

  for (auto& e : d["photos"])
    if (e["i"] == 1 && e["j"] == 1) e["slide"] = e["slide"] == "p" ? "n" : "p";
  WriteFile(ds_ + "/dataset.json", d.dump(2));
  r = Calibrate("scale", " --position 1,1 --point-mm 0,0 --reading-p 1 --reading-n 0.5");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("command line: point_mm: expected a point where the photos through T+ "
                          "are brighter"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(Outcomes("calibrate scale")["scale.point_lit"], "failed");
  EXPECT_FALSE(fs::exists(ds_ + "/calib/scale.json"));
}

}  // namespace
}  // namespace lumislab
