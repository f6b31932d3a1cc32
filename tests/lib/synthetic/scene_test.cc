// Scene files: every bad field is reported with the file and the field (exit 2), and the
// analytic luminaire and camera behave as their formulas say.
#include "lib/synthetic/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>

#include "core/error.h"
#include "core/geometry.h"
#include "lib/synthetic/camera.h"
#include "lib/synthetic/luminaire.h"
#include "lib/synthetic/spectral.h"

namespace lumislab {
namespace {

// The default scene with one textual replacement, parsed under the name "scene.json".
std::string ParseError(const std::string& from, const std::string& to) {
  std::string text = DefaultSceneJson();
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  try {
    ParseScene(text, "scene.json");
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no error for " << to;
  return "";
}

TEST(SceneFile, DefaultSceneIsValid) {
  const SynthScene s = DefaultScene();
  EXPECT_EQ(s.grid.nu, 9);
  EXPECT_EQ(s.grid.nv, 7);
  EXPECT_DOUBLE_EQ(s.grid.spacing_mm, 5);
  EXPECT_DOUBLE_EQ(s.distance_mm, 750);
  ASSERT_EQ(s.luminaire.emitters.size(), 2u);
  EXPECT_EQ(s.camera.width, 1600);
  EXPECT_TRUE(s.effects.empty());
  EXPECT_EQ(s.PhotoExtension(), "exr");
  // The checkerboard fits on the screen and is centred.
  EXPECT_LE(s.calibration.squares_x * s.calibration.square_mm, s.screen_w_mm);
  EXPECT_NEAR(s.calibration.origin_mm.x() + 0.5 * s.calibration.squares_x * s.calibration.square_mm,
              0, 1e-9);
}

// An emitter's measured distribution (an IES or EULUMDAT file) instead of cos^n: exactly one of
// the two, the file named when it is bad.
TEST(SceneFile, EmitterWithABlackbodySpectrum) {
  // "cct_k": the emitter's RGB is the synthetic camera's of a blackbody of that radiant
  // intensity; the other emitter keeps its RGB, and the default scene (no cct_k) is unchanged.
  std::string text = DefaultSceneJson();
  const std::string rgb = "\"intensity_w_sr\": [1.0, 0.9, 0.8]";
  text.replace(text.find(rgb), rgb.size(), "\"intensity_w_sr\": 2, \"cct_k\": 3000");
  const SynthScene scene = ParseScene(text, "scene.json");
  const Emitter& e = scene.luminaire.emitters[0];
  EXPECT_EQ(e.cct_k, 3000);
  EXPECT_EQ(e.radiant_w_sr, 2);
  EXPECT_NEAR((e.intensity_w_sr - 2 * BlackbodyRgbPerWatt(3000)).norm(), 0, 1e-12);
  EXPECT_GT(e.intensity_w_sr.x(), e.intensity_w_sr.z());  // 3000 K: red above blue
  EXPECT_EQ(scene.luminaire.emitters[1].cct_k, 0);
  EXPECT_EQ(DefaultScene().luminaire.emitters[0].intensity_w_sr, Eigen::Vector3d(1.0, 0.9, 0.8));
  EXPECT_NE(ParseError(rgb, rgb + ", \"cct_k\": 3000").find("intensity_w_sr"), std::string::npos);
  EXPECT_NE(ParseError(rgb, "\"intensity_w_sr\": 1, \"cct_k\": 500").find("cct_k"),
            std::string::npos);
}

TEST(SceneFile, MeasuredDistributionEmitters) {
  const std::string ies = std::string(LUMISLAB_SOURCE_DIR) + "/tests/data/ies/7.ies";
  const std::string measured =
      "\"distribution\": {\"file\": \"" + ies + "\", \"rotation_deg\": [0, 0, 90]}";
  std::string text = DefaultSceneJson();
  text.replace(text.find("\"lobe_exponent\": 8"), 18, measured);
  const SynthScene scene = ParseScene(text, "scene.json");
  const Emitter& e = scene.luminaire.emitters[0];
  ASSERT_TRUE(e.measured);
  // 7.ies is axial: its intensity over its peak (269 cd at gamma 0), whatever the rotation.
  EXPECT_NEAR(e.Shape(Eigen::Vector3d(0, 0, 1)), 1, 1e-12);
  const double g = 30 * 3.14159265358979 / 180;
  EXPECT_NEAR(e.Shape(Eigen::Vector3d(std::sin(g), 0, std::cos(g))), 200.0 / 269,
              1e-9);  // 200 cd at 30 degrees
  EXPECT_EQ(e.Shape(Eigen::Vector3d(0, 0, -1)), 0);
  EXPECT_NE(ParseError("\"lobe_exponent\": 8", measured + ", \"lobe_exponent\": 8")
                .find("luminaire.emitters[0]: expected exactly one of lobe_exponent, distribution"),
            std::string::npos);
  EXPECT_NE(ParseError("\"lobe_exponent\": 8", "\"distribution\": {\"file\": \"none.ies\"}")
                .find("none.ies: photometric file not found"),
            std::string::npos);
  EXPECT_NE(ParseError("\"lobe_exponent\": 8",
                       "\"distribution\": {\"file\": \"" + ies + "\", \"rotate\": 1}")
                .find("luminaire.emitters[0].distribution.rotate: expected file or rotation_deg"),
            std::string::npos);
}

// The reader's side of the C convention (docs/formats.md §17, "Orientation"): a file whose only
// bright direction is C = 90, gamma = 45 lights the luminaire frame's -y side, not +y; C = 0 is
// +x. The rotation then turns the file's frame: Rz(90) takes its -y (C = 90) to +x.
TEST(SceneFile, MeasuredDistributionsCNinetyIsMinusY) {
  const std::string ies = ::testing::TempDir() + "/c90_lobe.ies";
  {
    std::ofstream out(ies);
    out << "IESNA:LM-63-2002\n[TEST] c90\nTILT=NONE\n1 -1 1 3 5 1 2 0 0 0\n1 1 0\n0 45 90\n"
        << "0 90 180 270 360\n10 10 10\n10 100 10\n10 10 10\n10 10 10\n10 10 10\n";
  }
  const double s = std::sqrt(0.5);
  const MeasuredLobe lobe = MeasuredLobe::Load(ies, Eigen::Vector3d::Zero());
  EXPECT_NEAR(lobe.Shape(Eigen::Vector3d(0, -s, s)), 1, 1e-12);
  EXPECT_NEAR(lobe.Shape(Eigen::Vector3d(0, s, s)), 0.1, 1e-12);
  EXPECT_NEAR(lobe.Shape(Eigen::Vector3d(s, 0, s)), 0.1, 1e-12);
  const MeasuredLobe turned = MeasuredLobe::Load(ies, Eigen::Vector3d(0, 0, 90));
  EXPECT_NEAR(turned.Shape(Eigen::Vector3d(s, 0, s)), 1, 1e-12);
  EXPECT_NEAR(turned.Shape(Eigen::Vector3d(0, -s, s)), 0.1, 1e-12);
}

TEST(SceneFile, BadFieldsNameFileAndField) {
  EXPECT_EQ(ParseError("\"lobe_exponent\": 8", "\"lobe_exponent\": \"x\""),
            "scene.json: luminaire.emitters[0].lobe_exponent: expected number in [0, 1e+06], got "
            "\"x\"");
  EXPECT_NE(ParseError("\"lobe_exponent\": 3", "\"lobe_exponent\": -1")
                .find("luminaire.emitters[1].lobe_exponent: expected number in [0, 1e+06], got -1"),
            std::string::npos);
  EXPECT_NE(ParseError("\"nu\": 9", "\"nu\": -3").find("scene.json: setup.grid.nu"),
            std::string::npos);
  EXPECT_NE(ParseError("\"focal_px\": 1300", "\"focal_px\": 0").find("camera.focal_px"),
            std::string::npos);
  EXPECT_NE(ParseError("\"size_px\": [1600, 1200]", "\"size_px\": [1600]").find("size_px[1]"),
            std::string::npos);
  EXPECT_NE(ParseError("\"intensity_w_sr\": [1.0, 0.9, 0.8]", "\"intensity_w_sr\": [1, -1, 1]")
                .find("luminaire.emitters[0].intensity_w_sr[1]"),
            std::string::npos);
  EXPECT_NE(ParseError("\"distance_mm\": 750", "\"distance_mm\": null").find("setup.distance_mm"),
            std::string::npos);
  EXPECT_NE(ParseError("\"schema_version\": 1", "\"schema_version\": 7").find("schema_version"),
            std::string::npos);
  // A camera in the screen plane cannot photograph it.
  EXPECT_NE(ParseError("\"position_mm\": [0, -400, 2400]", "\"position_mm\": [0, -400, 750]")
                .find("camera.position_mm"),
            std::string::npos);
}

TEST(SceneFile, EmitterMustBeBehindS) {
  const std::string msg = ParseError("[1.5, -2, -20]", "[1.5, -2, 0]");
  EXPECT_NE(msg.find("scene.json: luminaire.emitters[0].position_mm"), std::string::npos) << msg;
  EXPECT_NE(msg.find("z < 0"), std::string::npos) << msg;
  EXPECT_NE(ParseError("[-3, 1, -12]", "[-3, 1, 5]").find("emitters[1].position_mm"),
            std::string::npos);
}

TEST(SceneFile, UnknownEffectAndBadParameters) {
  std::string msg = ParseError("\"effects\": []", "\"effects\": [{\"type\": \"lens_flare\"}]");
  EXPECT_NE(msg.find("scene.json: effects[0].type"), std::string::npos) << msg;
  EXPECT_NE(msg.find("lens_flare"), std::string::npos) << msg;
  msg = ParseError("\"effects\": []",
                   "\"effects\": [{\"type\": \"sensor_noise\"}, "
                   "{\"type\": \"quantization\", \"bit_depth\": 4}]");
  EXPECT_NE(msg.find("effects[1].bit_depth"), std::string::npos) << msg;
  msg = ParseError("\"effects\": []",
                   "\"effects\": [{\"type\": \"sensor_noise\", \"full_wel_e\": 100}]");
  EXPECT_NE(msg.find("effects[0].full_wel_e"), std::string::npos) << msg;
  msg = ParseError("\"effects\": []", "\"effects\": [{\"full_well_e\": 100}]");
  EXPECT_NE(msg.find("effects[0].type"), std::string::npos) << msg;
}

TEST(SceneFile, MissingFileIsBadInput) {
  try {
    LoadScene("/nonexistent/lumislab/scene.json");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/lumislab/scene.json"), std::string::npos);
  }
}

// E = I0 cos^(n+1) / r^2 (r in m), evaluated independently of the library's code path.
TEST(Luminaire, PlaneIrradianceIsInverseSquareCosineLaw) {
  Luminaire lum;
  lum.emitters.push_back({{2, -1, -30}, {1.5, 1.0, 0.5}, 4});
  const double d = 750, x = 310, y = -120;
  const double dx = x - 2, dy = y + 1, dz = d + 30;
  const double r = std::sqrt(dx * dx + dy * dy + dz * dz);
  const double cos_m = dz / r;
  const Eigen::Vector3d e = lum.PlaneIrradiance(x, y, d);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(e[c],
                lum.emitters[0].intensity_w_sr[c] * std::pow(cos_m, 5) / std::pow(r / 1000, 2),
                1e-12 * e[c]);
  // On the axis of an isotropic emitter: I0 / r^2.
  Luminaire iso;
  iso.emitters.push_back({{0, 0, -250}, {1, 1, 1}, 0});
  EXPECT_NEAR(iso.PlaneIrradiance(0, 0, 750)[0], 1.0, 1e-12);
  // Nothing behind the emitter.
  EXPECT_EQ(iso.PlaneIrradiance(10, 10, -300)[0], 0.0);
}

// The filtered irradiance weighs each emitter's ray by Phi~ where it crosses S, and the slides
// split it into peak (E+ - E-).
TEST(Luminaire, FilteredIrradianceUsesTheRayThroughS) {
  Luminaire lum;
  lum.emitters.push_back({{0, 0, -20}, {1, 1, 1}, 2});
  const DualFilter f = DualFilter::Truncated(1);
  const double h = 5, d = 750;
  // The ray to (s, t) crosses S at (s, t) * 20 / 770.
  const Eigen::Vector2d c(5, -2.5);
  const double s = 200, t = -60;
  const double u = s * 20 / 770, v = t * 20 / 770;
  const double r = std::sqrt(s * s + t * t + 770.0 * 770.0);
  const double expected =
      f.Eval2D((u - c.x()) / h, (v - c.y()) / h) * std::pow(770 / r, 3) / std::pow(r / 1000, 2);
  ASSERT_NE(expected, 0.0);
  EXPECT_NEAR(lum.FilteredIrradiance(f, h, c, d, s, t)[0], expected, 1e-12 * std::abs(expected));
  Eigen::Vector3d plus, minus;
  lum.SlideIrradiance(f, f.Peak2D(), h, c, d, s, t, &plus, &minus);
  EXPECT_NEAR(f.Peak2D() * (plus[0] - minus[0]), expected, 1e-12 * std::abs(expected));
  EXPECT_TRUE(plus[0] == 0 || minus[0] == 0);  // one emitter: one slide
}

TEST(Camera, UprightPinholeWithCentredPrincipalPoint) {
  CameraSpec spec;
  spec.width = 1600;
  spec.height = 1200;
  spec.focal_px = 1300;
  spec.position_mm = {0, -400, 2400};
  spec.look_at_mm = {0, 0, 750};
  const PinholeCamera cam(spec);
  const Eigen::Vector2d centre = cam.Project(spec.look_at_mm);
  EXPECT_NEAR(centre.x(), 799.5, 1e-9);
  EXPECT_NEAR(centre.y(), 599.5, 1e-9);
  // Lab +y is up in the image; seen from behind the screen, lab +x is to the right.
  EXPECT_LT(cam.Project({0, 100, 750}).y(), centre.y());
  EXPECT_GT(cam.Project({100, 0, 750}).x(), centre.x());
  // Focal length: a point 1 mm off the axis at distance D, perpendicular to it, is f / D px away.
  const Eigen::Vector3d axis = (spec.look_at_mm - spec.position_mm).normalized();
  const Eigen::Vector3d side(1, 0, 0);
  const double dist = (spec.look_at_mm - spec.position_mm).norm();
  EXPECT_NEAR((cam.Project(spec.look_at_mm + side) - centre).norm(), 1300 / dist, 1e-9);
  EXPECT_NEAR(side.dot(axis), 0, 1e-12);
  // The plane homography agrees with ray casting.
  const Eigen::Matrix3d h = cam.ScreenFromImage(750);
  for (const Eigen::Vector2d& px : {Eigen::Vector2d(10, 20), Eigen::Vector2d(1500.5, 1100)}) {
    Eigen::Vector2d xy;
    ASSERT_TRUE(cam.PlanePoint(px.x(), px.y(), 750, &xy));
    const Eigen::Vector3d s = h * Eigen::Vector3d(px.x(), px.y(), 1);
    EXPECT_NEAR((s.head<2>() / s.z() - xy).norm(), 0, 1e-9);
    EXPECT_NEAR((cam.Project({xy.x(), xy.y(), 750}) - px).norm(), 0, 1e-9);
  }
}

}  // namespace
}  // namespace lumislab

namespace lumislab {
namespace {

// The built-in full-sphere luminaire turned into an orientation (docs/formats.md §19): the
// intensity towards R w of the turned luminaire is the luminaire's towards w, its emitters sit
// at R (x - centre) + centre', and a turn that brings one in front of S is refused.
TEST(SceneFile, FullSphereLuminaireTurnsIntoOrientations) {
  const SynthScene scene = LoadScene("full-sphere");
  const Luminaire& lum = scene.luminaire;
  EXPECT_EQ(lum.centre_mm, Eigen::Vector3d(0, 0, -8));
  const auto intensity = [](const Luminaire& l, const Eigen::Vector3d& w) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const Emitter& e : l.emitters) sum += e.Intensity(w);
    return sum;
  };
  // Light in every direction, behind S included.
  for (const Eigen::Vector3d& w :
       {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(1, 0, 0),
        Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, -1, 0)})
    EXPECT_GT(intensity(lum, w).sum(), 0.5) << w.transpose();
  const Eigen::Matrix3d r = RotationZyxDegrees({10, 120, -30});
  const Luminaire turned = lum.Turned(r, {0, 0, -60});
  for (int k = 0; k < 50; ++k) {
    const Eigen::Vector3d w =
        Eigen::Vector3d(std::sin(k * 1.3), std::cos(k * 0.7), std::sin(k * 2.1)).normalized();
    EXPECT_TRUE(intensity(turned, r * w).isApprox(intensity(lum, w), 1e-12)) << w.transpose();
  }
  for (size_t k = 0; k < lum.emitters.size(); ++k)
    EXPECT_TRUE(turned.emitters[k].position_mm.isApprox(
        r * (lum.emitters[k].position_mm - lum.centre_mm) + Eigen::Vector3d(0, 0, -60)));
  EXPECT_THROW(lum.Turned(r, {0, 0, 0}), Error);
  // The default scene's emitters keep their +z lobes: nothing behind S.
  for (const Emitter& e : DefaultScene().luminaire.emitters)
    EXPECT_EQ(e.Intensity({0.1, 0, -1}).sum(), 0);
}

}  // namespace
}  // namespace lumislab
