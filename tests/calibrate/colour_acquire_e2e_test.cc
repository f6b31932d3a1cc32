// lumislab-acquire synth (a scene with a blackbody emitter and a ColorChecker photo among its
// calibration captures) -> lumislab-calibrate [response] colour --out <dataset>: the fitted
// calib/colour.json gives the emitter's temperature from its RGB (truth/luminaire.json), for a
// linear 16-bit camera and for a JPEG camera linearised with its calibrated response.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "core/json.h"
#include "lib/photometry/colour.h"
#include "lib/synthetic/scene.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

int Run(const std::string& command_line) {
  const int status = std::system((command_line + " > /dev/null 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string Scene(const std::string& effects, const std::string& captures) {
  return R"({ "schema_version": 1,
  "setup": { "distance_mm": 750, "grid": {"nu": 2, "nv": 2, "spacing_mm": 5},
             "screen_mm": [1200, 1200] },
  "luminaire": { "emitters": [
      {"position_mm": [1.5, -2, -20], "intensity_w_sr": 1.2, "cct_k": 3000, "lobe_exponent": 6} ] },
  "camera": { "size_px": [640, 480], "focal_px": 600, "position_mm": [0, -300, 2400],
              "look_at_mm": [0, 0, 750] },
  "calibration_captures": )" +
         captures + R"(,
  "effects": )" +
         effects + " }";
}

// acquire, the calibrate steps; the CCT of the emitter's RGB through calib/colour.json.
ColourCalibration AcquireAndCalibrate(const std::string& name, const std::string& effects,
                                      const std::string& captures, bool calibrate_response) {
  const std::string dir = fs::path(::testing::TempDir()) /
                          ("lumislab_colour_e2e_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir + "/scene.json") << Scene(effects, captures);
  const std::string bin = LUMISLAB_BIN_DIR;
  const std::string ds = dir + "/ds";
  EXPECT_EQ(Run(bin + "/lumislab-acquire synth --scene " + dir + "/scene.json --out " + ds), 0);
  const JsonDocument manifest = JsonDocument::Load(ds + "/calibration/captures.json");
  if (calibrate_response) {
    // The response series of the capture, with the exposures its manifest states.
    std::string frames, exposures;
    const JsonView list = manifest.root()["response"];
    for (size_t k = 0; k < list.Size(); ++k) {
      frames += " " + ds + "/" + list[k]["file"].String();
      exposures += (k ? "," : "") + std::to_string(list[k]["exposure"].Number());
    }
    EXPECT_EQ(Run(bin + "/lumislab-calibrate response --dataset " + ds + " --frames" + frames +
                  " --exposures " + exposures),
              0);
    EXPECT_TRUE(fs::exists(ds + "/calib/response.json"));
  }
  const std::string chart = ds + "/" + manifest.root()["colour"]["file"].String();
  EXPECT_EQ(manifest.root()["colour"]["illuminant"].String(), "D65");
  EXPECT_EQ(Run(bin + "/lumislab-calibrate colour --photo " + chart + " --out " + ds), 0);
  // Again: the file exists, exit 2 without --force.
  EXPECT_EQ(Run(bin + "/lumislab-calibrate colour --photo " + chart + " --out " + ds), 2);
  const auto c = ColourCalibration::LoadFor(ds);
  EXPECT_TRUE(c);
  if (!c) return {};
  const Luminaire luminaire = LoadLuminaire(ds);
  EXPECT_EQ(luminaire.emitters.at(0).cct_k, 3000);
  const LightColour colour = ColourOfRgb(*c, luminaire.emitters[0].intensity_w_sr);
  EXPECT_NEAR(colour.cct.kelvin, 3000, 50) << name;
  const JsonDocument checks = JsonDocument::Load(ds + "/checks.json");
  EXPECT_NE(checks.raw().dump().find("colour.fit"), std::string::npos);
  std::printf("%s: Delta E*ab mean %.3f max %.3f; emitter 3000 K -> %.1f K\n", name.c_str(),
              c->mean_delta_e, c->max_delta_e, colour.cct.kelvin);
  return *c;
}

TEST(ColourAcquireEndToEnd, Linear16BitCamera) {
  const ColourCalibration c =
      AcquireAndCalibrate("linear", R"([{"type": "quantization", "bit_depth": 16},
          {"type": "sensor_noise", "seed": 3}, {"type": "vignetting", "k1": -0.1}])",
                          R"({"colour_chart": "D65"})", false);
  // Vignetting darkens the chart's corners: the fit's residual grows (0.6 without it).
  EXPECT_LT(c.mean_delta_e, 5);
}

TEST(ColourAcquireEndToEnd, JpegCameraThroughItsResponse) {
  // 8-bit JPEG through a gamma-2.2 curve with a shoulder: calibrate colour decodes the chart
  // through calib/response.json, recovered from the capture's bracketed series.
  const ColourCalibration c = AcquireAndCalibrate(
      "jpeg", R"([{"type": "response", "gamma": 2.2, "shoulder": 0.5, "quality": 95}])",
      R"({"colour_chart": "D65", "response_stops": [-3, -2, -1, 0, 1, 2]})", true);
  EXPECT_LT(c.mean_delta_e, 5);
}

}  // namespace
}  // namespace lumislab
