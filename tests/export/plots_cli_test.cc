// lumislab-export irradiance and polar (export/cli_plots.h, docs/method.md §4.9) on an exact
// slab of the built-in synthetic luminaire: the plane's irradiance at D = d against the
// luminaire's own, the pictures' sizes and contents, and bad input (exit 2, nothing written).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "export/cli.h"
#include "export/cli_plots.h"
#include "lib/lightfield/false_colour.h"
#include "lib/synthetic/truth.h"

namespace lumislab {
namespace {

// lumislab-export in this process, as its main runs it (export/cli.h).
int RunExportWith(std::vector<std::string> args) {
  args.insert(args.begin(), "lumislab-export");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  return RunMain("export", [&] { return RunExport(int(argv.size()), argv.data()); });
}

class ExportPlots : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::filesystem::temp_directory_path() / ("lumislab_plots_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir_);
    WriteTruthSlab(DefaultScene().luminaire, DefaultSlabInfo(9, 7, 5, 60), Slab(), 2);
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(dir_); }
  static std::string Slab() { return (dir_ / "slab").string(); }
  static std::string Out(const std::string& name) { return (dir_ / name).string(); }
  static std::filesystem::path dir_;
};
std::filesystem::path ExportPlots::dir_;

// At D = d the exact model gives the luminaire's irradiance where the grid covers it
// (docs/method.md §4.5): the centre of the plane within 0.5 % (bilinear texels of 20 mm).
TEST_F(ExportPlots, IrradianceOnThePlaneAtD) {
  const std::string exr = Out("e.exr"), png = Out("e.png");
  ASSERT_EQ(RunExportWith({"irradiance", "--slab", Slab(), "--distance-mm", "750", "--extent-mm",
                           "200", "--size", "41", "--samples", "1", "--out", exr}),
            0);
  const ImageF e = ReadExr(exr, {"R", "G", "B"});
  ASSERT_EQ(e.width, 41);
  const Eigen::Vector3d truth = DefaultScene().luminaire.PlaneIrradiance(0, 0, 750);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(e.at(20, 20, c) / truth[c], 1, 5e-3) << c;
  ASSERT_EQ(RunExportWith({"irradiance", "--slab", Slab(), "--distance-mm", "1500", "--size", "64",
                           "--scale", "log", "--out", png}),
            0);
  const cv::Mat picture = cv::imread(png);
  EXPECT_EQ(picture.rows, 120);  // the bar panel's minimum height
  EXPECT_EQ(picture.cols, 64 + BarPanelWidth(64));
}

// Issue 29 red team: planes near S had negative lux written (min -1.6e6 lx at 2 mm, -16341 at
// 20 mm). Below 2 (K + 2) h = 30 mm (h 5, K 1): exit 2 naming --distance-mm, nothing written;
// below 3 (K + 2) h = 45 mm: written with a warning (docs/method.md §4.9 "Planes near S").
TEST_F(ExportPlots, PlanesNearSAreRefusedOrWarned) {
  for (const char* d : {"2", "20", "29"}) {
    const std::string out = Out(std::string("near") + d + ".exr");
    EXPECT_EQ(RunExportWith({"irradiance", "--slab", Slab(), "--distance-mm", d, "--extent-mm",
                             "60", "--size", "16", "--samples", "1", "--out", out}),
              2)
        << d;
    EXPECT_FALSE(std::filesystem::exists(out)) << d;
  }
  const std::string out = Out("near40.exr");
  testing::internal::CaptureStderr();
  const int code =
      RunExportWith({"irradiance", "--slab", Slab(), "--distance-mm", "40", "--extent-mm", "60",
                     "--size", "16", "--samples", "1", "--out", out});
  const std::string err = testing::internal::GetCapturedStderr();
  ASSERT_EQ(code, 0) << err;
  EXPECT_NE(err.find("nearer S than the exact model is trusted"), std::string::npos) << err;
  EXPECT_EQ(ReadExr(out, {"R", "G", "B"}).width, 16);
}

TEST_F(ExportPlots, PolarPlotSvgAndPng) {
  const std::string svg = Out("p.svg"), png = Out("p.png");
  ASSERT_EQ(RunExportWith({"polar", "--slab", Slab(), "--gamma-step", "5", "--out", svg}), 0);
  const std::string text = ReadTextFile(svg);
  EXPECT_EQ(text.rfind("<svg", 0), 0u);
  EXPECT_NE(text.find("C0\u2013C180"), std::string::npos);
  EXPECT_NE(text.find("C90\u2013C270"), std::string::npos);
  EXPECT_NE(text.find("I in W/sr"), std::string::npos);  // a truth slab is W/m^2
  EXPECT_NE(text.find("to 35\u00B0"), std::string::npos) << "seen up to 35 of 5-degree steps";
  ASSERT_EQ(RunExportWith({"polar", "--slab", Slab(), "--out", png, "--size", "300"}), 0);
  EXPECT_EQ(cv::imread(png).cols, 300);
}

// Issue 29: polar and irradiance take the dataset folder like ies, ldt and tm25 (the folder
// holding slab/), and an existing output is exit 2 naming it unless --force (it was replaced
// silently).
TEST_F(ExportPlots, DatasetFolderAndExistingOutput) {
  const std::string svg = Out("d.svg"), png = Out("d.png");
  ASSERT_EQ(RunExportWith({"polar", "--slab", dir_.string(), "--gamma-step", "10", "--out", svg}),
            0);
  ASSERT_EQ(RunExportWith({"irradiance", "--slab", dir_.string(), "--distance-mm", "1500", "--size",
                           "32", "--samples", "1", "--out", png}),
            0);
  const std::string before = ReadTextFile(svg);
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"polar", "--slab", Slab(), "--gamma-step", "5", "--out", svg},
           {"irradiance", "--slab", Slab(), "--distance-mm", "750", "--size", "32", "--out",
            png}}) {
    testing::internal::CaptureStderr();
    EXPECT_EQ(RunExportWith(args), 2) << args[0];
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find(args.back() + ": exists (--force rewrites it)"), std::string::npos) << err;
  }
  EXPECT_EQ(ReadTextFile(svg), before);
  EXPECT_EQ(
      RunExportWith({"polar", "--slab", Slab(), "--gamma-step", "5", "--out", svg, "--force"}), 0);
  EXPECT_NE(ReadTextFile(svg), before);
}

TEST_F(ExportPlots, BadInputIsExit2AndWritesNothing) {
  const std::string out = Out("bad.png");
  // Each with what its message must name.
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"irradiance", "--slab", Slab(), "--distance-mm", "0", "--out", out}, "--distance-mm"},
      {{"irradiance", "--slab", Slab(), "--distance-mm", "750", "--range", "5:1", "--out", out},
       "--range"},
      {{"irradiance", "--slab", Slab(), "--distance-mm", "750", "--out", Out("bad.jpg")},
       "bad.jpg"},
      {{"irradiance", "--slab", Out("nothing"), "--distance-mm", "750", "--out", out}, "nothing"},
      {{"polar", "--slab", Slab(), "--out", Out("bad.pdf")}, "bad.pdf"},
      {{"polar", "--slab", Slab(), "--gamma-step", "0", "--out", out}, "--gamma-step"}};
  for (const auto& [args, named] : cases) {
    testing::internal::CaptureStderr();
    EXPECT_EQ(RunExportWith(args), 2) << named;
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find(named), std::string::npos) << err;
  }
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(Out("bad.jpg")));
}

}  // namespace
}  // namespace lumislab
