// lumislab-preview's backends, tone-map flags, the headless command line the window prints, and
// the window itself under Xvfb with its Dear ImGui panel (skipped where xvfb-run is missing).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <sstream>

#include "core/error.h"
#include "core/exr_io.h"
#include "lib/lightfield/light_field.h"
#include "lib/lightfield/tone_map.h"
#include "lib/synthetic/truth.h"
#include "preview/cli.h"
#include "preview_test_util.h"

namespace lumislab {
namespace {

namespace fs = std::filesystem;

// A small exact slab of the built-in luminaire (5x5 positions, 60^2 texels), written once into
// a scratch folder that is removed at exit.
struct ScratchFolder {
  fs::path path =
      fs::temp_directory_path() / ("lumislab_window_test_" + std::to_string(::getpid()));
  ~ScratchFolder() { fs::remove_all(path); }
};

const std::string& TestSlab() {
  static const ScratchFolder scratch;
  static const std::string dir = [] {
    const fs::path d = scratch.path;
    fs::remove_all(d);
    WriteTruthSlab(DefaultScene().luminaire, DefaultSlabInfo(5, 5, 5, 60), (d / "slab").string(),
                   2);
    return (d / "slab").string();
  }();
  return dir;
}

std::string Scratch(const std::string& name) {
  return (fs::path(TestSlab()).parent_path() / name).string();
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

cv::Mat ReadRgbPng(const std::string& path) {
  cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
  return bgr;  // compared with each other only: channel order does not matter
}

// Each tone setting given on the command line is the one the PNG is made with: the PNG equals
// ToneMapToSrgb8 of the EXR of the same render under that setting.
TEST(PreviewToneMapFlags, PngIsTheExrThroughTheChosenToneMapping) {
  const std::string exr = Scratch("tone.exr");
  const std::vector<std::string> base = {"--slab", TestSlab(), "--scene",
                                         "crypt",  "--size",   "64x48"};
  auto with = [&](std::vector<std::string> extra, const std::string& out) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    args.insert(args.end(), {"--out", out});
    return RunPreviewWith(args);
  };
  ASSERT_EQ(with({}, exr), 0);
  const ImageF image = ReadExr(exr, {"R", "G", "B"});
  struct Case {
    std::vector<std::string> flags;
    ToneMapping tone;
  };
  const std::vector<Case> cases = {
      {{"--tone-map", "linear", "--auto-exposure", "p99"},
       {0, AutoExposure::kP99, ToneCurve::kLinear}},
      {{"--tone-map", "filmic", "--auto-exposure", "lit", "--exposure", "1.5"},
       {1.5, AutoExposure::kLit, ToneCurve::kFilmic}},
      {{"--tone-map", "linear", "--no-auto-exposure", "--exposure", "20"},
       {20, AutoExposure::kOff, ToneCurve::kLinear}},
      {{}, ToneMapping{}},  // the defaults: filmic, lit
  };
  std::vector<std::vector<uint8_t>> pictures;
  for (const Case& c : cases) {
    const std::string png = Scratch("tone.png");
    ASSERT_EQ(with(c.flags, png), 0);
    const cv::Mat bgr = ReadRgbPng(png);
    ASSERT_EQ(bgr.cols, 64);
    const std::vector<uint8_t> expected = ToneMapToSrgb8(image, c.tone);
    int mismatched = 0;
    for (int y = 0; y < bgr.rows; ++y)
      for (int x = 0; x < bgr.cols; ++x)
        for (int ch = 0; ch < 3; ++ch)
          mismatched += bgr.at<cv::Vec3b>(y, x)[2 - ch] != expected[(size_t(y) * 64 + x) * 3 + ch];
    EXPECT_EQ(mismatched, 0) << c.flags.size();
    pictures.push_back(expected);
  }
  EXPECT_NE(pictures[0], pictures[1]);  // the settings do change the picture
  EXPECT_NE(pictures[1], pictures[3]);
}

TEST(PreviewToneMapFlags, BadValuesAreRefusedNamingTheOption) {
  const std::string out = Scratch("bad.png");
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--tone-map", "aces"}, "--tone-map"},
      {{"--auto-exposure", "mean"}, "--auto-exposure"},
      {{"--exposure", "100"}, "--exposure"},
      {{"--camera", "0,95,3000,0,0,0"}, "pitch"},
      {{"--camera", "0,10,0,0,0,0"}, "distance"},
      {{"--backend", "vulkan"}, "--backend"},
      {{"--window", "--backend", "osmesa"}, "--window"},
      {{"--reference", "--backend", "egl"}, "--backend egl"},
  };
  for (const auto& [extra, named] : cases) {
    std::vector<std::string> args = {"--slab", TestSlab(), "--size", "8x8", "--out", out};
    args.insert(args.end(), extra.begin(), extra.end());
    testing::internal::CaptureStderr();
    const int code = RunPreviewWith(args);
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_EQ(code, 2) << extra[0] << " " << err;
    EXPECT_NE(err.find(named), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(out));
  }
}

// Every setting the window changes comes back from the command line it prints.
TEST(PreviewCommandLine, HeadlessCommandLineParsesBackToTheSameSettings) {
  PreviewConfig config;
  config.slab_dir = "/data/my slab";  // quoted
  config.scene.name = "cloister";
  config.scene.pose = {250, 2300, -150.5, 90, 12.25, -30};
  config.camera = {35, 38, 3900, 0, 500, -12.5};
  config.width = 640;
  config.height = 360;
  config.tone = {-1.5, AutoExposure::kP99, ToneCurve::kLinear};
  config.shadows = false;
  config.shadow_size = 1024;
  config.shadow_pcf = true;
  config.shadow_cull = false;
  config.shadow_share = 0.75;
  config.merge_group = 3;
  config.merge_error = 0.25;
  config.coarse_tolerance = 0.125;
  config.reproject_tolerance = 0;
  config.srgbe = true;
  config.texture_filter = TextureFilter::kCubic;
  const std::string line = HeadlessCommandLine(config, "out.png");
  // Split like a shell: words, or '...' as one.
  std::vector<std::string> words;
  std::smatch m;
  std::string rest = line;
  while (std::regex_search(rest, m, std::regex("'([^']*)'|(\\S+)"))) {
    words.push_back(m[1].matched ? m[1].str() : m[2].str());
    rest = m.suffix();
  }
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  PreviewConfig back;
  bool write_test_slab = true;
  ASSERT_FALSE(ParsePreviewCommandLine(int(argv.size()), argv.data(), back, &write_test_slab))
      << line;
  EXPECT_FALSE(write_test_slab);
  EXPECT_EQ(back.slab_dir, config.slab_dir);
  EXPECT_EQ(back.scene.name, "cloister");
  EXPECT_EQ(back.scene.pose, config.scene.pose);
  EXPECT_EQ(back.camera, config.camera);
  EXPECT_EQ(back.width, 640);
  EXPECT_EQ(back.height, 360);
  EXPECT_EQ(back.tone.exposure_stops, -1.5);
  EXPECT_EQ(back.tone.auto_exposure, AutoExposure::kP99);
  EXPECT_EQ(back.tone.curve, ToneCurve::kLinear);
  EXPECT_FALSE(back.shadows);
  EXPECT_EQ(back.shadow_size, 1024);
  EXPECT_TRUE(back.shadow_pcf);
  EXPECT_FALSE(back.shadow_cull);
  EXPECT_EQ(back.shadow_share, 0.75);
  EXPECT_EQ(back.merge_group, 3);
  EXPECT_EQ(back.merge_error, 0.25);
  EXPECT_EQ(back.coarse_tolerance, 0.125);
  EXPECT_EQ(back.reproject_tolerance, 0);
  EXPECT_TRUE(back.srgbe);
  EXPECT_EQ(back.texture_filter, TextureFilter::kCubic);
  EXPECT_EQ(back.out, "out.png");
  EXPECT_EQ(back.backend, Backend::kOsmesa);
}

bool HasGpuDevice() {
  if (fs::exists("/dev/nvidia0")) return true;
  if (fs::is_directory("/dev/dri"))
    for (const auto& entry : fs::directory_iterator("/dev/dri"))
      if (entry.path().filename().string().rfind("renderD", 0) == 0) return true;
  return false;
}

// --backend egl: on a GPU, the same picture as OSMesa; without one, exit 1 with a message that
// says so (Mesa's EGL offers its software device here, which --backend egl does not take).
TEST(PreviewBackend, EglRendersOnAGpuAndSaysSoWithoutOne) {
  const std::string osmesa = Scratch("osmesa.exr"), egl = Scratch("egl.exr");
  const std::vector<std::string> base = {"--slab", TestSlab(), "--scene",
                                         "crypt",  "--size",   "96x64"};
  auto run = [&](const std::string& backend, const std::string& out) {
    std::vector<std::string> args = base;
    args.insert(args.end(), {"--backend", backend, "--out", out});
    return RunPreviewWith(args);
  };
  if (!HasGpuDevice()) {
    testing::internal::CaptureStderr();
    const int code = run("egl", egl);
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_EQ(code, 1) << err;
    EXPECT_TRUE(err.find("EGL found no GPU") != std::string::npos ||
                err.find("libEGL.so.1") != std::string::npos)
        << err;
    EXPECT_FALSE(fs::exists(egl));
    GTEST_SKIP() << "no GPU (/dev/nvidia0, /dev/dri/renderD*): --backend egl refused as it "
                    "should be; the EGL render itself was not compared";
  }
  ASSERT_EQ(run("osmesa", osmesa), 0);
  ASSERT_EQ(run("egl", egl), 0);
  const ImageDifference d =
      CompareImages(ReadExr(egl, {"R", "G", "B"}), ReadExr(osmesa, {"R", "G", "B"}));
  RecordProperty("egl_vs_osmesa_relative_l2", std::to_string(d.relative_l2));
  EXPECT_LT(d.relative_l2, 1e-2);  // shadow-map rasterisation differs along shadow edges
}

// The window under Xvfb: the screenshot holds the panel (it differs from the picture where the
// panel is) and, beside it, exactly the PNG of the headless command line the window logs.
TEST(PreviewWindow, ScreenshotShowsThePanelAndTheHeadlessPicture) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is missing (Debian: xvfb)";
  const std::string shot = Scratch("window.png"), log = Scratch("window.log");
  // Under the sanitizers: no leak check for the window's process. Under Xvfb it ends with 2 x 56
  // bytes allocated by a library that was unloaded before exit (the GL driver stack the GLFW
  // window loads at run time; lumislab's binary stays loaded and would be named), an "<unknown
  // module>" that no suppression in fuzz/sanitizers/lsan.supp can match. ASan's other checks stay
  // on, and lumislab's own allocations are leak-checked through OSMesa in the other preview tests.
  const std::string no_leak_check =
#ifdef LUMISLAB_SANITIZED
      "ASAN_OPTIONS=\"$ASAN_OPTIONS:detect_leaks=0\" ";
#else
      "";
#endif
  const std::string command =
      "cd " + fs::path(shot).parent_path().string() + " && " + no_leak_check +
      "xvfb-run -a -s '-screen 0 800x600x24' " LUMISLAB_BIN_DIR
      "/lumislab-preview --window --slab " +
      TestSlab() + " --scene crypt --size 640x480 --screenshot " + shot + " > " + log + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << ReadText(log);
  const std::string text = ReadText(log);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(text, m, std::regex("the same picture headless: (.*)"))) << text;
  // Render it headless (the log's command, with our output path).
  std::istringstream words(m[1].str());
  std::vector<std::string> args;
  for (std::string w; words >> w;) args.push_back(w);
  ASSERT_GE(args.size(), 3u);
  ASSERT_EQ(args[args.size() - 2], "--out");
  const std::string headless = Scratch("headless.png");
  args.back() = headless;
  args.erase(args.begin());  // the program name
  ASSERT_EQ(RunPreviewWith(args), 0);
  const cv::Mat window = ReadRgbPng(shot), picture = ReadRgbPng(headless);
  ASSERT_EQ(window.cols, 640);
  ASSERT_EQ(window.rows, 480);
  ASSERT_EQ(picture.size, window.size);
  // Right of the panel (about 420 pixels wide): the same picture; on it: not. The command line
  // carries the pose and camera to 6 significant digits, and the crypt's default luminaire pose
  // has ry = 90 degrees, where rx and rz trade places (gimbal lock): the pose read back differs
  // in the last float bits, which moves a few pixels by one code.
  const cv::Rect right(470, 0, 170, 480), panel(16, 16, 300, 300);
  cv::Mat right_diff;
  cv::absdiff(window(right), picture(right), right_diff);
  double max_diff = 0;
  cv::minMaxLoc(right_diff.reshape(1), nullptr, &max_diff);
  EXPECT_LE(max_diff, 1);
  EXPECT_LT(cv::countNonZero(right_diff.reshape(1)), int(right_diff.total()) / 100);
  EXPECT_GT(cv::countNonZero(picture(right).reshape(1)), 1000);  // the scene is lit there
  cv::Mat diff;
  cv::absdiff(window(panel), picture(panel), diff);
  EXPECT_GT(cv::countNonZero(diff.reshape(1)), 300 * 300 / 4);  // the panel is drawn
}

}  // namespace
}  // namespace lumislab
