// lib/photometry/colour.h: CIE tables, Planck, chromaticity, CCT and Duv against published
// values, and calib/colour.json's loader.
#include "lib/photometry/colour.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.h"

namespace lumislab {
namespace {

TEST(Colour, TablesAgreeWithPublishedWhitePoints) {
  // CIE 15:2004 Table T.3 (2-degree): D65 (0.31272, 0.32903), D50 (0.34567, 0.35851); from the
  // 5 nm tables over 380 - 780 nm within 2e-4.
  const Eigen::Vector2d d65 = XyzToXy(SpectrumToXyz(IlluminantD65()));
  const Eigen::Vector2d d50 = XyzToXy(SpectrumToXyz(IlluminantD50()));
  EXPECT_NEAR(d65.x(), 0.31272, 2e-4);
  EXPECT_NEAR(d65.y(), 0.32903, 2e-4);
  EXPECT_NEAR(d50.x(), 0.34567, 2e-4);
  EXPECT_NEAR(d50.y(), 0.35851, 2e-4);
  // Illuminant A is Planck at 2856 K: (0.44757, 0.40745).
  const Eigen::Vector2d a = PlanckianXy(2856);
  EXPECT_NEAR(a.x(), 0.44757, 2e-4);
  EXPECT_NEAR(a.y(), 0.40745, 2e-4);
  // An equal-energy spectrum is at (1/3, 1/3) and has 683 x mean(V) lm/W.
  const Spectrum flat = Spectrum::Ones();
  EXPECT_NEAR(XyzToXy(SpectrumToXyz(flat)).x(), 1.0 / 3, 2e-4);
  EXPECT_NEAR(LuminousEfficacy(flat), 683 * Cmf1931().col(1).mean(), 1e-9);
}

TEST(Colour, CctOfThePlanckianLocusIsItsTemperature) {
  for (double t = 1500; t <= 20000; t *= 1.17) {
    const Cct cct = CctFromXy(PlanckianXy(t));
    EXPECT_NEAR(cct.kelvin, t, 1e-4 * t) << t;
    EXPECT_NEAR(cct.duv, 0, 1e-6) << t;
  }
  // Off the locus along the isotemperature line: the same CCT, Duv the distance.
  const Eigen::Vector2d uv = XyToUv1960(PlanckianXy(4000));
  const Eigen::Vector2d uv2 = XyToUv1960(PlanckianXy(4001));
  const Eigen::Vector2d tangent = (uv2 - uv).normalized();
  const Eigen::Vector2d normal(-tangent.y(), tangent.x());  // towards larger v
  const Eigen::Vector2d off = uv + 0.01 * (normal.y() > 0 ? normal : -normal);
  const double d = 2 * off.x() - 8 * off.y() + 4;  // (u, v) -> (x, y), CIE 1960 inverse
  const Cct cct = CctFromXy({3 * off.x() / d, 2 * off.y() / d});
  EXPECT_NEAR(cct.kelvin, 4000, 2);
  EXPECT_NEAR(cct.duv, 0.01, 1e-5);
}

// Issue 29 red team: a colour.json swapping X and Z gave "CCT 1.684e+04 K" at Duv 0.0965. CCT is
// defined within |Duv| <= 0.05 (CIE 15, ANSI C78.377): beyond, kelvin NaN and Duv kept.
TEST(Colour, NoCctFarOffTheLocus) {
  const Eigen::Vector2d uv = XyToUv1960(PlanckianXy(4000));
  const Eigen::Vector2d uv2 = XyToUv1960(PlanckianXy(4001));
  const Eigen::Vector2d tangent = (uv2 - uv).normalized();
  Eigen::Vector2d normal(-tangent.y(), tangent.x());
  if (normal.y() < 0) normal = -normal;
  auto at = [&](double duv) {
    const Eigen::Vector2d off = uv + duv * normal;
    const double d = 2 * off.x() - 8 * off.y() + 4;
    return CctFromXy({3 * off.x() / d, 2 * off.y() / d});
  };
  EXPECT_NEAR(at(0.049).kelvin, 4000, 3);
  for (double duv : {0.051, -0.051, 0.0965}) {
    const Cct c = at(duv);
    EXPECT_TRUE(std::isnan(c.kelvin)) << duv << ": " << c.kelvin;
    EXPECT_NEAR(c.duv, duv, 1e-4);
  }
}

TEST(Colour, CctOfDaylightIsThePublishedOne) {
  // D65: CCT 6504 K, Duv +0.0032 (CIE 15; ANSI C78.377 sign, above the locus).
  const Cct d65 = CctFromXy(XyzToXy(SpectrumToXyz(IlluminantD65())));
  EXPECT_NEAR(d65.kelvin, 6504, 5);
  EXPECT_NEAR(d65.duv, 0.0032, 3e-4);
  EXPECT_TRUE(std::isnan(CctFromXy({0.15, 0.06}).kelvin));  // deep blue: no CCT
}

TEST(Colour, LabOfTheWhiteIsL100) {
  const Eigen::Vector3d white = SpectrumToXyz(IlluminantD50());
  EXPECT_NEAR((XyzToLab(white, white) - Eigen::Vector3d(100, 0, 0)).norm(), 0, 1e-9);
  // ColorChecker's white 9.5 under D50: Ohta's sample L* 95.5, the newer charts' published 96.5
  // (X-Rite, BabelColor).
  const Spectrum patch = ColorCheckerReflectance(18).cwiseProduct(IlluminantD50());
  EXPECT_NEAR(XyzToLab(SpectrumToXyz(patch), white).x(), 96.5, 1.5);
  EXPECT_STREQ(ColorCheckerPatchName(18), "white 9.5 (.05 D)");
}

TEST(Colour, CalibrationFileLoadsAndRefusesBadMatrices) {
  const auto dir = std::filesystem::temp_directory_path() / "lumislab_colour_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "calib");
  EXPECT_FALSE(ColourCalibration::LoadFor(dir.string()));
  const std::string path = (dir / "calib" / "colour.json").string();
  auto write = [&](const std::string& matrix) {
    std::ofstream(path) << R"({"schema_version": 1, "rgb_to_xyz": )" << matrix
                        << R"(, "chart": "ColorChecker Classic 24", "illuminant": "D65",
                              "residual_delta_e": {"mean": 1.5, "max": 4}})";
  };
  write("[[0.5, 0.3, 0.2], [0.2, 0.7, 0.1], [0.0, 0.1, 0.9]]");
  const auto c = ColourCalibration::LoadFor(dir.string());
  ASSERT_TRUE(c);
  EXPECT_DOUBLE_EQ(c->rgb_to_xyz(1, 1), 0.7);
  EXPECT_NEAR(c->LuminanceWeights().sum(), 1, 1e-12);
  EXPECT_DOUBLE_EQ(c->max_delta_e, 4);
  write("[[0.5, 0.3, 0.2], [0.5, 0.3, 0.2], [0.0, 0.1, 0.9]]");
  try {
    ColourCalibration::Load(path);
    FAIL() << "a singular matrix was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("rgb_to_xyz"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace lumislab
