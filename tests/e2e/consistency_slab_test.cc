// Issue 28, slabs and exports, exposure advice, screen: the consistency checks that a slab's
// total light is positive in every stage that reads it ("slab.total_light"), that reconstruct's
// bracket-ratio advice is given only when it is right, that a JPEG dataset clipped at 1 is
// warned ("radiometry.saturation_level") and that a mirrored calibration board is noticed
// ("screen.board_mirrored"). Each check: a case where it fires and a legitimate one it passes.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "core/slab_compare.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::ReadBinaryFile;
using testing::RunToolIn;
using testing::WriteFile;

const char* kSmallCamera =
    R"({"size_px": [320, 240], "focal_px": 260, "position_mm": [0, -400, 2400],
        "look_at_mm": [0, 0, 750]})";

nlohmann::json ReadJson(const std::string& path) {
  return nlohmann::json::parse(ReadBinaryFile(path));
}

// The record of `check` by `stage` in <ds>/checks.json (null when missing).
nlohmann::json Record(const std::string& ds, const std::string& stage, const std::string& check) {
  if (!fs::exists(ds + "/checks.json")) return nullptr;
  const nlohmann::json j = ReadJson(ds + "/checks.json");
  if (!j["stages"].contains(stage)) return nullptr;
  for (const auto& r : j["stages"][stage]["checks"])
    if (r["check"] == check) return r;
  return nullptr;
}

class ConsistencySlab : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = testing::FreshDir(std::string("consistency_slab_") +
                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  testing::CommandResult Run(const std::string& tool, const std::string& args) {
    return RunToolIn(root_, tool, args, 120);
  }
  void Ok(const std::string& tool, const std::string& args) {
    const auto r = Run(tool, args);
    ASSERT_EQ(r.exit_code, 0) << tool << " " << args << "\n" << r.output;
  }
  // A 2 x 2 float capture of the default luminaire, screen calibrated.
  void SmallCapture(const std::string& ds) {
    WriteFile(root_ + "/scene.json", testing::SceneJson(2, 2, kSmallCamera, "[]"));
    Ok("lumislab-acquire",
       "synth --scene scene.json --out " + ds + " --photo-format float --truth-resolution 40");
    Ok("lumislab-calibrate", "screen --dataset " + ds);
  }
  std::string root_;
};

// Every photo's slide swapped (T+ read as T-): E = N - P, a slab of negative light.
void SwapSlides(const std::string& ds) {
  nlohmann::json d = ReadJson(ds + "/dataset.json");
  for (auto& p : d["photos"]) p["slide"] = p["slide"] == "p" ? "n" : "p";
  WriteFile(ds + "/dataset.json", d.dump(1));
}

TEST_F(ConsistencySlab, NegativeSlabIsRefusedByEveryStageThatReadsIt) {
  SmallCapture("ds");
  const std::string ds = root_ + "/ds";
  Ok("lumislab-reconstruct", "--dataset ds --resolution 40");
  const nlohmann::json good = Record(ds, "reconstruct", "slab.total_light");
  ASSERT_FALSE(good.is_null());
  EXPECT_EQ(good["outcome"], "passed");
  EXPECT_GT(good["values"]["total"].get<double>(), 0);
  // A legitimate slab passes every reader untouched. IES wants a lux slab (issue 29): the
  // capture has no lux meter reading, so its slab.json is relabelled (only the units check reads
  // it); --allow-partial: the screen saw a cone of the grid.
  const auto relabel_lux = [&] {
    nlohmann::json slab = ReadJson(ds + "/slab/slab.json");
    slab["units"] = "lux";
    WriteFile(ds + "/slab/slab.json", slab.dump(1));
  };
  relabel_lux();
  const std::string keywords = " --test T1 --lab L --manufacturer M --allow-partial";
  Ok("lumislab-export", "ies --slab ds --out good.ies" + keywords);
  EXPECT_EQ(Record(ds, "export ies", "farfield.negative_share")["outcome"], "passed");
  EXPECT_EQ(Record(ds, "export ies", "slab.total_light")["outcome"], "passed");

  // The slides swapped: reconstruct writes the positions as it goes, then its photo checks
  // (slides.sign, reconstruct/capture_checks.h) refuse the capture, naming the photos; the slab
  // left behind is one of negative light, which every reader refuses on its own.
  SwapSlides(ds);
  fs::remove_all(ds + "/slab");
  const auto r = Run("lumislab-reconstruct", "--dataset ds --resolution 40");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("the two slides look swapped"), std::string::npos) << r.output;
  EXPECT_EQ(Record(ds, "reconstruct", "slides.sign")["outcome"], "failed");
  relabel_lux();  // as above: the units are not what is checked here
  // Every reader refuses the slab.
  for (const std::string& args : std::vector<std::string>{
           "ies --slab ds --out x.ies" + keywords, "ldt --slab ds --out x.ldt" + keywords,
           "tm25 --slab ds --out x.ray --allow-partial", "polar --slab ds/slab --out x.svg",
           "irradiance --slab ds/slab --distance-mm 1000 --out "
           "x.png"}) {
    const auto e = Run("lumislab-export", args);
    EXPECT_EQ(e.exit_code, 2) << args << "\n" << e.output;
    EXPECT_NE(e.output.find("slab/slab.json: total light"), std::string::npos) << e.output;
  }
  for (const char* out : {"x.ies", "x.ldt", "x.ray", "x.svg", "x.png"})
    EXPECT_FALSE(fs::exists(root_ + "/" + out)) << out;
  EXPECT_EQ(Record(ds, "export tm25", "slab.total_light")["outcome"], "failed");
  for (const std::string view : {"", " --view false-colour"}) {
    const auto p =
        Run("lumislab-preview", "--slab ds/slab --scene plane --size 32x32 --out x.png" + view);
    EXPECT_EQ(p.exit_code, 2) << p.output;
    EXPECT_NE(p.output.find("slab/slab.json: total light"), std::string::npos) << p.output;
  }
  EXPECT_EQ(Record(ds, "preview", "slab.total_light")["outcome"], "failed");
}

// A JPEG camera with a dark offset the lab did not record (an empty setup.json radiometry), exact
// exposures in three brackets: the response curve fitted to its frames absorbs the offset and
// reads the codes below ~32 a few % low, which must not show as bracket ratios off by 4-8 %.
class JpegCamera : public ConsistencySlab {
 protected:
  void Capture() {
    WriteFile(root_ + "/scene.json",
              testing::SceneJson(2, 2, kSmallCamera,
                                 R"([{"type": "dark", "black_level": 0.005, "seed": 3},
          {"type": "brackets", "stops": [-1, 0, 1]},
          {"type": "response", "curve": "gamma", "gamma": 2.2, "shoulder": 0.5, "quality": 95}],
          "calibration_captures": {"response_stops": [-2, -1, 0, 1, 2]})"));
    Ok("lumislab-acquire", "synth --scene scene.json --out ds --truth-resolution 40");
    nlohmann::json d = ReadJson(root_ + "/ds/dataset.json");
    d["radiometry"] = {{"scale_w_m2", d["radiometry"]["scale_w_m2"]}};  // as a lab knows it
    WriteFile(root_ + "/ds/dataset.json", d.dump(1));
    const nlohmann::json frames = ReadJson(root_ + "/ds/calibration/captures.json")["response"];
    std::string files, exposures;
    for (const auto& f : frames) {
      files += " ds/" + f["file"].get<std::string>();
      exposures += (exposures.empty() ? "" : ",") + std::to_string(f["exposure"].get<double>());
    }
    Ok("lumislab-calibrate",
       "response --dataset ds --frames" + files + " --exposures " + exposures);
    Ok("lumislab-calibrate", "screen --dataset ds");
  }
  void SetDataset(const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json d = ReadJson(root_ + "/ds/dataset.json");
    edit(d);
    WriteFile(root_ + "/ds/dataset.json", d.dump(1));
  }
  // Reconstructs; the number of bracket-ratio warnings and the worst position's error.
  std::pair<int, double> Reconstruct(const std::string& ratios, std::string* output = nullptr) {
    const auto r = Run("lumislab-reconstruct",
                       "--dataset ds --resolution 40 --force --bracket-ratios " + ratios);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    if (output) *output = r.output;
    int advice = 0;
    for (size_t at = 0; (at = r.output.find("in the pixels", at)) != std::string::npos; ++at) {
      const size_t line = r.output.rfind('\n', at);
      advice += r.output.compare(line + 1, 30, "lumislab-reconstruct: warning:") == 0;
    }
    const SlabComparison c = CompareSlabs(root_ + "/ds/slab", root_ + "/ds/truth");
    return {advice, c.max_relative_l2};
  }
};

TEST_F(JpegCamera, BracketAdviceOnlyWhenTheExposuresAreOff) {
  if (testing::kSanitized) GTEST_SKIP() << "accuracy run: the Release build's";
  Capture();
  // Empty radiometry: clipped at 1, which JPEG's coding spreads below code 255 (measured: worst
  // position 4.1 % from truth at 1, 1.7 % at 0.95): warned and recorded.
  std::string output;
  const auto at_one = Reconstruct("recorded", &output);
  EXPECT_NE(output.find("[radiometry.saturation_level]"), std::string::npos) << output;
  EXPECT_EQ(Record(root_ + "/ds", "reconstruct", "radiometry.saturation_level")["outcome"],
            "warning");
  SetDataset([](nlohmann::json& d) { d["radiometry"]["saturation_level"] = 0.95; });
  const auto exact = Reconstruct("recorded", &output);
  EXPECT_EQ(Record(root_ + "/ds", "reconstruct", "radiometry.saturation_level")["outcome"],
            "passed");
  std::printf("JPEG camera, exact exposures: worst position %.4f at saturation 1, %.4f at 0.95\n",
              at_one.second, exact.second);
  EXPECT_LT(exact.second, 0.7 * at_one.second);
  // Exact exposures: no advice (before the estimate kept to codes >= 32: 36 warnings of -50 %).
  EXPECT_EQ(exact.first, 0) << output;
  EXPECT_EQ(Record(root_ + "/ds", "reconstruct", "brackets.recorded_ratios")["outcome"], "passed");
  // The long bracket labelled 2.2 where it was 2 (10 % off): advised, and the advice helps.
  SetDataset([](nlohmann::json& d) {
    for (auto& p : d["photos"])
      if (p["exposure"].get<double>() == 2.0) p["exposure"] = 2.2;
  });
  const auto off = Reconstruct("recorded");
  // The advice is recorded too (the dataset's report, not only the log).
  EXPECT_EQ(Record(root_ + "/ds", "reconstruct", "brackets.recorded_ratios")["outcome"], "warning");
  const auto followed = Reconstruct("estimated");
  std::printf("exposures 10 %% off: %d warnings, worst position %.4f recorded, %.4f estimated\n",
              off.first, off.second, followed.second);
  EXPECT_GT(off.first, 0);
  EXPECT_LT(followed.second, 0.5 * off.second);
  EXPECT_LT(followed.second, 1.2 * exact.second);
}

// The board photo turned over left to right: the board as the camera sees it pinned mirrored.
TEST_F(ConsistencySlab, MirroredBoardIsNoticed) {
  SmallCapture("ds");
  const std::string ds = root_ + "/ds";
  EXPECT_EQ(Record(ds, "calibrate screen", "screen.board_mirrored")["outcome"], "passed");
  const std::string board = ds + "/photos/calib_0.png";
  cv::Mat photo = cv::imread(board, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(photo.empty());
  cv::flip(photo, photo, 1);
  ASSERT_TRUE(cv::imwrite(board, photo));
  const auto r = Run("lumislab-calibrate", "screen --dataset ds --force");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("[screen.board_mirrored]"), std::string::npos) << r.output;
  const nlohmann::json record = Record(ds, "calibrate screen", "screen.board_mirrored");
  EXPECT_EQ(record["outcome"], "warning");
  EXPECT_EQ(record["values"]["handedness"], 1);
}

}  // namespace
}  // namespace lumislab
