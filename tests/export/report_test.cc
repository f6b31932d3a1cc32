// lumislab-export report (export/report.h): its numbers against the synthetic truth of the default
// luminaire (beam angle within 0.5 degrees, zonal lumens within 1 %), what the HTML states (a
// partial cone's coverage, no colour calibration, uncertainty, no network reference), the output
// rules, and the browser check: headless Chromium prints it to PDF and screenshots a page that is
// not blank (skipped, saying so, where Debian's chromium is not installed).
#include "export/report.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calibrate/colour/colour_calibrator.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/log.h"
#include "core/slab_light.h"
#include "export/cli.h"
#include "export/report_svg.h"
#include "export/report_uncertainty.h"
#include "lib/photo/photo_write.h"
#include "lib/synthetic/spectral.h"
#include "lib/synthetic/truth.h"

namespace lumislab {
namespace {

namespace fs = std::filesystem;

// lumislab-export in this process, as its main runs it (export/cli.h).
int RunExportWith(std::vector<std::string> args) {
  args.insert(args.begin(), "lumislab-export");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  return RunMain("export", [&] { return RunExport(int(argv.size()), argv.data()); });
}

// The default scene's emitters 1 and 1.5 mm behind S (as tests/export/export_formats_test.cc:
// the far field's parallax error is then 0.1 %) on a 9 x 7 grid at 48 texels.
class ExportReport : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("lumislab_report_" + std::to_string(getpid()));
    fs::create_directories(dir_);
    luminaire_ = DefaultScene().luminaire;
    luminaire_.emitters[0].position_mm.z() = -1;
    luminaire_.emitters[1].position_mm.z() = -1.5;
    WriteTruthSlab(luminaire_, DefaultSlabInfo(9, 7, 5, 48), (dir_ / "ds/slab").string(), 2);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static std::string Out(const std::string& name) { return (dir_ / name).string(); }
  static ReportOptions Options() {
    ReportOptions o;
    o.slab = (dir_ / "ds").string();
    o.out = Out("r.html");
    o.plane_size = 61;
    return o;
  }
  // The luminance-weighted axial intensities and exponents: I(gamma) = sum I0 cos^n gamma.
  static std::vector<std::pair<double, double>> Lobes() {
    std::vector<std::pair<double, double>> lobes;
    for (const Emitter& e : luminaire_.emitters)
      lobes.push_back({Rec709Weights().dot(e.intensity_w_sr), e.lobe_exponent});
    return lobes;
  }
  static double TruthIntensity(double gamma_deg) {
    double sum = 0;
    for (const auto& [i0, n] : Lobes()) sum += i0 * std::pow(std::cos(gamma_deg * kPi / 180), n);
    return sum;
  }
  static double TruthZone(double lo, double hi) {
    double sum = 0;
    for (const auto& [i0, n] : Lobes())
      sum +=
          2 * kPi * i0 *
          (std::pow(std::cos(lo * kPi / 180), n + 1) - std::pow(std::cos(hi * kPi / 180), n + 1)) /
          (n + 1);
    return sum;
  }
  static fs::path dir_;
  static Luminaire luminaire_;
};
fs::path ExportReport::dir_;
Luminaire ExportReport::luminaire_;

// The beam angle across C0-C180 and C90-C270 against the truth's (the lobes are axially
// symmetric: 2 x the gamma where I falls to half), and the 10-degree zones the capture saw whole
// against their closed form.
TEST_F(ExportReport, NumbersMatchTheSyntheticTruth) {
  const ReportData r = MakeReportData(Options(), 2);
  double lo = 0, hi = 90;  // bisection: I(gamma) = I(0) / 2
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (TruthIntensity(mid) > 0.5 * TruthIntensity(0) ? lo : hi) = mid;
  }
  const double beam = 2 * lo;
  ASSERT_GE(r.summary.spreads.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    std::printf("beam %s: %.3f deg, truth %.3f deg\n", k ? "C90-C270" : "C0-C180",
                r.summary.spreads[k].beam_deg, beam);
    EXPECT_NEAR(r.summary.spreads[k].beam_deg, beam, 0.5);
  }
  EXPECT_GT(r.seen_cone_deg, 30);
  int zones = 0;
  for (const ZonalFlux& z : r.summary.zones) {
    if (z.gamma_hi_deg > r.seen_cone_deg) break;
    const double truth = TruthZone(z.gamma_lo_deg, z.gamma_hi_deg);
    std::printf("zone %g-%g: %.5g W, truth %.5g W\n", z.gamma_lo_deg, z.gamma_hi_deg, z.flux,
                truth);
    EXPECT_NEAR(z.flux / truth, 1, 0.01) << z.gamma_lo_deg;
    ++zones;
  }
  EXPECT_GE(zones, 3);
  EXPECT_NEAR(r.flux_in_cone / TruthZone(0, r.seen_cone_deg), 1, 0.01);
  EXPECT_NEAR(r.summary.peak / TruthIntensity(0), 1, 0.01);
  // The near-field table at D = d: the slab's axial illuminance is the luminaire's own.
  ASSERT_EQ(r.planes.size(), 3u);
  EXPECT_NEAR(r.planes[0].distance_mm, 750, 1e-9);
  EXPECT_NEAR(r.planes[2].distance_mm, 3000, 1e-9);
  const double e_truth = Rec709Weights().dot(luminaire_.PlaneIrradiance(0, 0, 750));
  EXPECT_NEAR(r.planes[0].centre_slab / e_truth, 1, 0.01);
  EXPECT_GT(r.uncertainty.FluxExpanded(), 0);
}

// The HTML: self-contained, the partial cone stated (not refused), the colour section's
// placeholder, units, and the output rules (an existing file: exit 2 unless --force).
TEST_F(ExportReport, HtmlStatesCoverageAndIsSelfContained) {
  const std::string html = Out("h.html");
  ASSERT_EQ(RunExportWith({"report", "--slab", (dir_ / "ds").string(), "--out", html,
                           "--plane-size", "41", "--input-watts", "2"}),
            0);
  const std::string text = ReadTextFile(html);
  for (const char* needle :
       {"Flux in the measured cone", "Coverage", "Beam / field angle C0\u2013C180",
        "NEMA beam type", "CIE flux code", "C15\u2013C195", "C165\u2013C345", "Zonal lumens",
        "Polar diagram", "Iso-candela", "Illuminance on planes", "Near-field advantage",
        "Candela table", "Uncertainty", "No colour calibration", "@page", "data:image/png;base64,",
        "+x (C0)", "W/sr"})
    EXPECT_NE(text.find(needle), std::string::npos) << needle;
  // Efficacy needs lm: a W/m^2 slab says so instead of printing lm/W.
  EXPECT_NE(text.find("not photometric units"), std::string::npos);
  for (const char* external : {"<script", "src=\"http", "href=\"http", "url(http", "@import"})
    EXPECT_EQ(text.find(external), std::string::npos) << external;
  EXPECT_EQ(RunExportWith({"report", "--slab", (dir_ / "ds").string(), "--out", html}), 2);
  EXPECT_EQ(RunExportWith({"report", "--slab", (dir_ / "ds").string(), "--out", Out("x.pdf")}), 2);
}

// Issue 29 red team, planes near S and a W/m^2 slab: --distances-mm 20 (below 2 (K + 2) h = 30
// mm) is exit 2 naming it, nothing written; 40 mm (below 3 (K + 2) h) is drawn with a warning at
// that plane. The title says radiometric, and --per-klm's being ignored is in the HTML.
TEST_F(ExportReport, NearPlanesRadiometricTitleAndPerKlmNote) {
  const std::string html = Out("near.html");
  EXPECT_EQ(RunExportWith({"report", "--slab", (dir_ / "ds").string(), "--out", html,
                           "--plane-size", "16", "--distances-mm", "20,750"}),
            2);
  EXPECT_FALSE(fs::exists(html));
  ReportOptions o = Options();
  o.plane_size = 16;
  o.distances_mm = {40, 750};
  o.per_klm = true;
  const ReportData r = MakeReportData(o, 2);
  ASSERT_EQ(r.planes.size(), 2u);
  EXPECT_NE(r.planes[0].note.find("nearer S than the exact model is trusted"), std::string::npos)
      << r.planes[0].note;
  EXPECT_EQ(r.planes[1].note, "");
  const std::string text = ReportHtml(r);
  EXPECT_NE(text.find("Warning: the plane at 40 mm"), std::string::npos);
  EXPECT_NE(text.find("Radiometric report"), std::string::npos);
  EXPECT_EQ(text.find("Photometric report"), std::string::npos);
  EXPECT_NE(text.find("--per-klm is ignored"), std::string::npos);
}

// --pdf without a Chromium to run: exit 1 naming what to install, the HTML written.
TEST_F(ExportReport, PdfWithoutChromiumSaysWhatToInstall) {
  setenv("LUMISLAB_CHROMIUM", "/nonexistent/chromium", 1);
  const int code = RunExportWith({"report", "--slab", (dir_ / "ds").string(), "--out",
                                  Out("p.html"), "--pdf", Out("p.pdf"), "--plane-size", "21"});
  unsetenv("LUMISLAB_CHROMIUM");
  EXPECT_EQ(code, 1);
  EXPECT_TRUE(fs::exists(Out("p.html")));
  EXPECT_FALSE(fs::exists(Out("p.pdf")));
}

bool HaveChromium() { return std::system("command -v chromium >/dev/null 2>&1") == 0; }

// The browser check: Chromium prints the report to PDF, and a screenshot of its first screen
// is not blank (over 3 % of its pixels not white, and their grey levels spread).
TEST_F(ExportReport, ChromiumPrintsAndRendersIt) {
  if (!HaveChromium())
    GTEST_SKIP() << "chromium is not installed (Debian's chromium: scripts/setup.sh installs it)";
  const std::string html = Out("c.html"), pdf = Out("c.pdf"), png = Out("c.png");
  ASSERT_EQ(RunExportWith({"report", "--slab", (dir_ / "ds").string(), "--out", html, "--pdf", pdf,
                           "--plane-size", "41"}),
            0);
  const std::string bytes = ReadTextFile(pdf);
  EXPECT_EQ(bytes.rfind("%PDF", 0), 0u);
  const std::string command =
      "chromium --headless --no-sandbox --disable-gpu --hide-scrollbars "
      "--window-size=900,1270 --screenshot=" +
      png + " file://" + html + " >/dev/null 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0);
  const cv::Mat shot = cv::imread(png);
  ASSERT_FALSE(shot.empty());
  EXPECT_EQ(shot.cols, 900);
  cv::Mat gray;
  cv::cvtColor(shot, gray, cv::COLOR_BGR2GRAY);
  const double ink = double(cv::countNonZero(gray < 250)) / gray.total();
  cv::Scalar mean, stddev;
  cv::meanStdDev(gray, mean, stddev);
  std::printf("screenshot: %.1f %% of pixels not white, grey std %.1f\n", 100 * ink, stddev[0]);
  EXPECT_GT(ink, 0.03);
  EXPECT_GT(stddev[0], 10);
  // LUMISLAB_REPORT_KEEP=<folder>: the report, its PDF and the screenshot are copied there (how
  // docs/images/report_page1.png is made).
  if (const char* keep = std::getenv("LUMISLAB_REPORT_KEEP"))
    for (const std::string& f : {html, pdf, png})
      fs::copy_file(f, fs::path(keep) / fs::path(f).filename(),
                    fs::copy_options::overwrite_existing);
}

// The plane pictures' orientation: one emitter 40 mm towards +x and 30 mm towards +y lights the
// plane's right and upper part (+x right, +y up, row 0 on top), as the axes say.
TEST(ExportReportPlanes, PlusXRightAndPlusYUp) {
  const fs::path dir =
      fs::temp_directory_path() / ("lumislab_report_xy_" + std::to_string(getpid()));
  Luminaire luminaire;
  Emitter e;
  e.position_mm = {40, 30, -1};
  e.intensity_w_sr = {1, 1, 1};
  e.lobe_exponent = 2;
  luminaire.emitters.push_back(e);
  WriteTruthSlab(luminaire, DefaultSlabInfo(9, 7, 20, 48), (dir / "slab").string(), 2);
  ReportOptions o;
  o.slab = (dir / "slab").string();
  o.out = (dir / "r.html").string();
  o.plane_size = 41;
  o.distances_mm = {750};
  const ReportData r = MakeReportData(o, 2);
  const ReportPlane& p = r.planes.at(0);
  double sum = 0, sx = 0, sy = 0;
  for (int y = 0; y < p.size; ++y)
    for (int x = 0; x < p.size; ++x) {
      const double v = p.luminance[size_t(y) * p.size + x];
      sum += v;
      sx += v * ((x + 0.5) / p.size - 0.5) * p.extent_mm;
      sy += v * (0.5 - (y + 0.5) / p.size) * p.extent_mm;  // row 0 on top: +y up
    }
  std::printf("centroid on the plane: %.1f, %.1f mm\n", sx / sum, sy / sum);
  EXPECT_GT(sx / sum, 10);  // 21 mm: the square ends at +-600 mm, pulling it in
  EXPECT_GT(sy / sum, 8);   // 16 mm
  fs::remove_all(dir);
}

// The uncertainty: the planner's terms, and calib/scale.json's bracket agreement through
// (Y+ - Y-): values 10, 10.2, 9.8 (standard error of the mean 0.115) and 2, 2 (0) give
// 0.1155 / 8 = 1.44 %.
TEST(ExportReportUncertainty, ScaleBracketsAndPlannerTerms) {
  const fs::path dir =
      fs::temp_directory_path() / ("lumislab_report_u_" + std::to_string(getpid()));
  fs::create_directories(dir / "calib");
  WriteTextAtomically((dir / "calib/scale.json").string(), R"({"schema_version": 1,
    "kind": "scale", "scale": 1, "units": "lux", "report": {
    "bracket_values_p": [{"value": 10}, {"value": 10.2}, {"value": 9.8}],
    "bracket_values_n": [{"value": 2}, {"value": 2}]}})");
  UncertaintyInput in;
  in.info = DefaultSlabInfo(9, 7, 5, 48);
  in.dataset_dir = dir.string();
  in.light_depth_mm = 20;
  in.meter_relative = 0.02;
  const FarFieldUncertainty u = EstimateFarFieldUncertainty(in);
  double scale = -1, sum2 = 0;
  for (const UncertaintyTerm& t : u.terms) {
    if (t.name.find("bracket") != std::string::npos) scale = t.relative;
    if (t.flux) sum2 += t.relative * t.relative;
  }
  EXPECT_NEAR(scale, 0.2 / std::sqrt(3.0) / 8, 1e-9);
  EXPECT_NEAR(u.flux_relative, std::sqrt(sum2), 1e-12);
  EXPECT_NEAR(u.FluxExpanded(), 2 * u.flux_relative, 1e-12);
  EXPECT_GT(u.flux_relative, 0.02);
  // The peak, one direction, takes the parallax bound (2 a sum|c_m| / sqrt 3), not its L2 share.
  EXPECT_GT(u.peak_relative, u.flux_relative);
  const std::string keyword = UncertaintyKeyword(u);
  EXPECT_EQ(keyword.rfind("flux +-", 0), 0u) << keyword;
  EXPECT_NE(keyword.find("(expanded, k=2; terms:"), std::string::npos) << keyword;
  EXPECT_EQ(keyword.back(), ')');
  fs::remove_all(dir);
}

// A lux slab: cd and lm, efficacy from --input-watts, and --per-klm's cd/klm in the diagrams and
// the candela table (cd x 1000 / lm).
TEST(ExportReportLux, PhotometricUnitsEfficacyAndPerKlm) {
  const fs::path dir =
      fs::temp_directory_path() / ("lumislab_report_lux_" + std::to_string(getpid()));
  SlabInfo info = DefaultSlabInfo(5, 5, 5, 24);
  info.units = "lux";
  WriteTruthSlab(DefaultScene().luminaire, info, (dir / "slab").string(), 2);
  ReportOptions o;
  o.slab = (dir / "slab").string();
  o.out = (dir / "r.html").string();
  o.plane_size = 21;
  o.distances_mm = {750};
  o.input_watts = 4;
  o.per_klm = true;
  const ReportData r = MakeReportData(o, 2);
  EXPECT_EQ(r.IntensityUnit(), "cd/klm");
  EXPECT_EQ(r.FluxUnit(), "lm");
  EXPECT_EQ(r.IlluminanceUnit(), "lx");
  EXPECT_NEAR(r.summary.efficacy, r.summary.total_flux / 4, 1e-12);
  const std::string html = ReportHtml(r);
  EXPECT_NE(html.find("lm/W at 4 W"), std::string::npos);
  EXPECT_NE(html.find("Candela table (cd/klm)"), std::string::npos);
  EXPECT_EQ(html.find("not photometric units"), std::string::npos);
  // The candela table's gamma = 0, C = 0 cell: the far field's value per klm.
  const double per_klm = r.summary.PerKlm(r.distribution.At(0, 0));
  EXPECT_NE(html.find("<th>0&deg;</th><td>" + Num(per_klm, 4) + "</td>"), std::string::npos)
      << Num(per_klm, 4);
  // Issue 29 red team: the efficacy of a partial cone is over the seen flux only, a lower bound;
  // an input power above 683 lm/W (K_m) is exit 2 naming --input-watts.
  ASSERT_LT(r.seen_fraction, 1);
  EXPECT_NE(html.find("Luminous efficacy (seen flux)"), std::string::npos);
  EXPECT_NE(html.find("a lower bound"), std::string::npos);
  EXPECT_EQ(html.find("Photometric report"), html.find("<title>") + 7) << "lux: photometric";
  o.input_watts = 1e-300;
  try {
    MakeReportData(o, 2);
    ADD_FAILURE() << "1e-300 W accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_EQ(std::string(e.what()).rfind("--input-watts", 0), 0u) << e.what();
  }
  fs::remove_all(dir);
}

// Colour: a luminaire of blackbody-like emitters (scene field cct_k) whose dataset has a colour
// calibration fitted to the synthetic ColorChecker photo (lumislab-calibrate colour's fit): the
// report's CCT of the total light is the emitters' temperature within 50 K (issue 29), and a
// second, cooler and wider lobe makes the CCT rise away from the axis.
TEST(ExportReportColour, CctOfTheTotalLightAndPerDirection) {
  const fs::path dir =
      fs::temp_directory_path() / ("lumislab_report_colour_" + std::to_string(getpid()));
  fs::create_directories(dir / "ds/calib");
  const std::string chart = (dir / "chart.exr").string();
  WritePhoto(chart, RenderColourChartPhoto({}), PhotoEncoding::kFloatExr);
  const Photo photo = DecodePhoto(chart);
  const ChartPatches patches =
      FindColourChart(photo, ChartReferenceXyz("D65"), ReferenceWhite("D65"));
  nlohmann::json fit_report;
  CheckLog checks("", "test");
  const ColourCalibration calibration =
      CalibrateColour(patches, {}, photo.path, &fit_report, &checks);
  SaveColourCalibration((dir / "ds/calib/colour.json").string(), calibration, fit_report);
  // A dataset folder (the report finds calib/ through dataset.json beside slab/); its content is
  // not read.
  WriteTextAtomically((dir / "ds/dataset.json").string(), "{}");
  const SlabInfo info = DefaultSlabInfo(7, 7, 5, 32);
  for (const bool two_lobes : {false, true}) {
    const std::string file = (dir / "luminaire.json").string();
    WriteTextAtomically(file,
                        std::string(R"({"schema_version": 1, "luminaire": {"emitters": [
        {"position_mm": [0.5, -1, -2], "intensity_w_sr": 1.3, "cct_k": 3000, "lobe_exponent": 8})") +
                            (two_lobes ? R"(, {"position_mm": [-1, 0.5, -1], "intensity_w_sr": 0.8,
                    "cct_k": 6500, "lobe_exponent": 2})"
                                       : "") +
                            "]}}");
    WriteTruthSlab(LoadLuminaire(file), info, (dir / "ds/slab").string(), 2);
    ReportOptions o;
    o.slab = (dir / "ds").string();
    o.out = (dir / "r.html").string();
    o.plane_size = 21;
    o.distances_mm = {750};
    const ReportData r = MakeReportData(o, 2);
    ASSERT_TRUE(r.colour.present);
    std::printf("%s: total light x %.4f y %.4f, CCT %.1f K\n",
                two_lobes ? "3000 K + 6500 K" : "3000 K", r.colour.x, r.colour.y, r.colour.cct_k);
    if (!two_lobes) {
      EXPECT_NEAR(r.colour.cct_k, 3000, 50);
    } else {
      EXPECT_GT(r.colour.cct_k, 3100);  // the cooler lobe's share
      EXPECT_LT(r.colour.cct_k, 6400);
      const std::string html = ReportHtml(r);
      EXPECT_NE(html.find("CCT over "), std::string::npos);
      EXPECT_EQ(html.find("No colour calibration"), std::string::npos);
    }
  }
  // Issue 29 red team: a calibration that puts the light far off the Planckian locus (X, Z swapped
  // gave "CCT 1.684e+04 K" at Duv 0.0965; here X and Z a third of Y's row, a green far above the
  // locus): no CCT, the Duv said.
  ColourCalibration swapped = calibration;
  swapped.rgb_to_xyz << 0.3, 0, 0, 0, 1, 0, 0, 0, 0.3;
  SaveColourCalibration((dir / "ds/calib/colour.json").string(), swapped, fit_report);
  ReportOptions o;
  o.slab = (dir / "ds").string();
  o.out = (dir / "r.html").string();
  o.plane_size = 16;
  o.distances_mm = {750};
  const ReportData r = MakeReportData(o, 2);
  std::printf("off the locus: x %.4f y %.4f, Duv %.4f\n", r.colour.x, r.colour.y, r.colour.duv);
  EXPECT_TRUE(std::isnan(r.colour.cct_k)) << r.colour.cct_k;
  EXPECT_GT(std::abs(r.colour.duv), 0.05);
  EXPECT_NE(ReportHtml(r).find("no CCT (Duv " + Fmt(r.colour.duv, 3)), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lumislab
