// IES LM-63 and EULUMDAT: flux of real manufacturer files against a commercial photometry
// tool, every symmetry, round trips through both writers, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <tuple>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/geometry.h"
#include "lib/photometry/eulumdat.h"
#include "lib/photometry/file_info.h"
#include "lib/photometry/ies.h"
#include "lib/photometry/intensity_distribution.h"

namespace lumislab {
namespace {

std::string DataPath(const std::string& name) {
  return std::string(LUMISLAB_SOURCE_DIR) + "/tests/data/ies/" + name;
}

// The exit code and message of what `f` throws (-1 and "" when it does not throw).
template <typename F>
std::pair<int, std::string> Thrown(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return {e.exit_code(), e.what()};
  }
  return {-1, ""};
}

struct Reference {
  const char* file;
  double flux_lm;  // Photometric Toolbox (tests/data/ies/README.md)
  CSymmetry symmetry;
};
const Reference kReferences[] = {{"1.ies", 9217.18, CSymmetry::kQuadrant},
                                 {"3.ies", 13359.57, CSymmetry::kNone},
                                 {"5.ies", 753.8, CSymmetry::kQuadrant},
                                 {"7.ies", 531.98, CSymmetry::kAxial}};

TEST(Ies, RealFilesFluxAgreesWithACommercialTool) {
  for (const Reference& r : kReferences) {
    const IntensityDistribution d = ReadIes(DataPath(r.file));
    EXPECT_EQ(d.format, "IES LM-63-2002") << r.file;
    EXPECT_EQ(d.Symmetry(), r.symmetry) << r.file;
    EXPECT_TRUE(d.photometric);
    const double flux = d.TotalFlux();
    const double relative = flux / r.flux_lm - 1;
    std::printf("%s: %.2f lm (reference %.2f lm, %+.4f %%)\n", r.file, flux, r.flux_lm,
                100 * relative);
    EXPECT_LT(std::abs(relative), 0.005) << r.file << ": " << flux << " lm";
  }
}

TEST(Ies, ReadsTheHeaderFields) {
  const IntensityDistribution d = ReadIes(DataPath("1.ies"));
  EXPECT_EQ(d.Keyword("MANUFAC"), "RAB LIGHTING INC.");
  EXPECT_NE(d.Keyword("LUMINAIRE").find("\nMETAL HOUSING"), std::string::npos);  // [MORE]
  EXPECT_EQ(d.gamma_deg.size(), 74u);
  EXPECT_EQ(d.c_deg.size(), 12u);
  EXPECT_DOUBLE_EQ(d.input_watts, 69.6);
  EXPECT_NEAR(d.opening.width_mm, 1.47 * 304.8, 1e-9);  // feet
  EXPECT_NEAR(d.opening.height_mm, 0.2375 * 304.8, 1e-9);
}

// An analytic distribution f(C) cos(gamma) on gamma 0-90 with the C dependence `shape`,
// sampled on the planes of `c` and every 2.5 degrees of gamma.
IntensityDistribution Analytic(const std::vector<double>& c, double (*shape)(double)) {
  IntensityDistribution d;
  d.c_deg = c;
  for (int g = 0; g <= 36; ++g) d.gamma_deg.push_back(2.5 * g);
  for (double cc : c)
    for (double g : d.gamma_deg) d.values.push_back(100 * shape(cc) * std::cos(g * kPi / 180));
  d.keywords = {
      {"TEST", "t1"}, {"TESTLAB", "lab"}, {"ISSUEDATE", "2026-12-02"}, {"MANUFAC", "maker"}};
  return d;
}
std::vector<double> Range(double a, double b, double step) {
  std::vector<double> v;
  for (double x = a; x <= b + 1e-9; x += step) v.push_back(x);
  return v;
}
double Rad(double deg) { return deg * kPi / 180; }

struct SymmetryCase {
  const char* name;
  std::vector<double> c;
  double (*shape)(double);
  CSymmetry symmetry;
};
std::vector<SymmetryCase> SymmetryCases() {
  return {
      {"axial", {0}, [](double) { return 1.0; }, CSymmetry::kAxial},
      {"quadrant", Range(0, 90, 15), [](double c) { return 1 + 0.3 * std::cos(2 * Rad(c)); },
       CSymmetry::kQuadrant},
      {"c0-c180", Range(0, 180, 15),
       [](double c) { return 1 + 0.3 * std::cos(Rad(c)) + 0.2 * std::cos(2 * Rad(c)); },
       CSymmetry::kC0C180},
      {"c90-c270", Range(90, 270, 15), [](double c) { return 1 + 0.3 * std::sin(Rad(c)); },
       CSymmetry::kC90C270},
      {"none 0-360", Range(0, 360, 15),
       [](double c) { return 1 + 0.3 * std::cos(Rad(c)) + 0.2 * std::sin(Rad(c)); },
       CSymmetry::kNone},
      {"none 0-345", Range(0, 345, 15),
       [](double c) { return 1 + 0.3 * std::cos(Rad(c)) + 0.2 * std::sin(Rad(c)); },
       CSymmetry::kNone},
  };
}

// Every symmetry: the flux is the analytic 100 pi (the C terms integrate to 0 over the circle,
// cos(gamma) sin(gamma) to 1/2), and Intensity() anywhere on the circle is the function, the
// symmetry mapping C into the stored range.
TEST(IntensityDistribution, EverySymmetryGivesTheAnalyticFluxAndIntensity) {
  for (const SymmetryCase& s : SymmetryCases()) {
    const IntensityDistribution d = Analytic(s.c, s.shape);
    d.Check(s.name);
    EXPECT_EQ(d.Symmetry(), s.symmetry) << s.name;
    EXPECT_NEAR(d.TotalFlux() / (100 * kPi), 1, 3e-4) << s.name;
    for (double c : {0.0, 15.0, 30.0, 105.0, 195.0, 240.0, 300.0, 345.0})
      EXPECT_NEAR(d.Intensity(c, 30), 100 * s.shape(c) * std::cos(Rad(30)), 1e-9)
          << s.name << " C " << c;
    EXPECT_NEAR(d.Intensity(7.5, 1.25), 0.5 * (d.Intensity(0, 1.25) + d.Intensity(15, 1.25)), 1e-9);
    EXPECT_EQ(d.Intensity(0, 120), 0);  // beyond the stored gamma range
  }
}

void ExpectSameDistribution(const IntensityDistribution& a, const IntensityDistribution& b,
                            const std::string& what) {
  ASSERT_EQ(a.c_deg.size(), b.c_deg.size()) << what;
  ASSERT_EQ(a.gamma_deg.size(), b.gamma_deg.size()) << what;
  for (size_t k = 0; k < a.c_deg.size(); ++k) EXPECT_NEAR(a.c_deg[k], b.c_deg[k], 1e-6) << what;
  for (size_t k = 0; k < a.gamma_deg.size(); ++k)
    EXPECT_NEAR(a.gamma_deg[k], b.gamma_deg[k], 1e-6) << what;
  for (size_t k = 0; k < a.values.size(); ++k)
    EXPECT_NEAR(a.values[k], b.values[k], 1e-6 * (1 + std::abs(a.values[k]))) << what << " " << k;
  EXPECT_NEAR(a.TotalFlux(), b.TotalFlux(), 1e-6 * a.TotalFlux()) << what;
  EXPECT_EQ(a.photometric, b.photometric) << what;
}

TEST(Ies, RoundTripsThroughTheLm63_2019Writer) {
  for (const Reference& r : kReferences) {
    IntensityDistribution d = ReadIes(DataPath(r.file));
    if (d.Keyword("TESTLAB").empty()) d.keywords.push_back({"TESTLAB", "lab"});
    if (d.Keyword("ISSUEDATE").empty()) d.keywords.push_back({"ISSUEDATE", "2026-12-02"});
    const std::string text = FormatIes(d, {}, "out.ies");
    EXPECT_EQ(text.rfind("IES:LM-63-2019\r\n[TEST]", 0), 0u);  // CR LF lines, as LM-63 asks
    EXPECT_EQ(text.find("\n"), text.find("\r\n") + 1);
    const IntensityDistribution back = ParseIes(text, "out.ies");
    EXPECT_EQ(back.format, "IES LM-63-2019");
    ExpectSameDistribution(d, back, r.file);
    EXPECT_EQ(back.Keyword("MANUFAC"), d.Keyword("MANUFAC"));
    EXPECT_EQ(back.Keyword("LUMINAIRE"), d.Keyword("LUMINAIRE"));  // [MORE] lines kept
    EXPECT_NEAR(back.opening.width_mm, d.opening.width_mm, 1e-3);
  }
  for (const SymmetryCase& s : SymmetryCases()) {
    IntensityDistribution d = Analytic(s.c, s.shape);
    d.photometric = false;
    const IntensityDistribution back = ParseIes(FormatIes(d, {}, "r.ies"), "r.ies");
    ExpectSameDistribution(d, back, s.name);
  }
}

TEST(Ies, WriterRefusesMissingRequiredKeywords) {
  for (const char* key : kIesRequiredKeywords) {
    IntensityDistribution d = Analytic({0}, [](double) { return 1.0; });
    for (auto& kv : d.keywords)
      if (kv.first == key) kv.second = " ";
    const auto [code, message] = Thrown([&] { FormatIes(d, {}, "out.ies"); });
    EXPECT_EQ(code, 2) << key;
    EXPECT_NE(message.find(std::string("out.ies: [") + key + "]"), std::string::npos) << message;
  }
}

TEST(Eulumdat, RoundTripsEverySymmetryAndTheRealFiles) {
  for (const SymmetryCase& s : SymmetryCases()) {
    const IntensityDistribution d = Analytic(s.c, s.shape);
    const std::string text = FormatEulumdat(d, "x.ldt");
    const IntensityDistribution back = ParseEulumdat(text, "x.ldt");
    EXPECT_EQ(back.format, "EULUMDAT");
    IntensityDistribution expected = d;
    if (s.symmetry == CSymmetry::kNone && s.c.back() == 360) {  // EULUMDAT lists 0-345
      expected.c_deg.pop_back();
      expected.values.resize(expected.values.size() - expected.gamma_deg.size());
    }
    ExpectSameDistribution(expected, back, s.name);
    EXPECT_EQ(back.Keyword("MANUFAC"), "maker");
  }
  for (const Reference& r : kReferences) {
    const IntensityDistribution d = ReadIes(DataPath(r.file));
    const IntensityDistribution back = ParseEulumdat(FormatEulumdat(d, "x.ldt"), "x.ldt");
    EXPECT_EQ(back.Symmetry(), r.symmetry);
    if (r.symmetry != CSymmetry::kNone) ExpectSameDistribution(d, back, r.file);
    EXPECT_NEAR(back.TotalFlux() / r.flux_lm, 1, 0.005) << r.file;
  }
}

TEST(Eulumdat, ReadsTheIsymLayoutsAndDecimalCommas) {
  // Isym 4 (C 0-90 of Mc = 4 planes: 0, 90, 180, 270), two gamma angles, 500 lm of lamps.
  std::ostringstream os;
  os << "Maker\n3\n4\n4\n90\n2\n90\nR1\nName\nNo\nf.ldt\n2026\n100\n50\n10\n80\n40\n5\n5\n5\n5\n"
     << "100\n95,5\n1\n0\n1\n1\nLED\n500\n3000\n80\n12,5\n";
  for (int k = 0; k < 10; ++k) os << "0\n";
  os << "0\n90\n180\n270\n0\n90\n200\n100\n300,5\n0\n";
  const IntensityDistribution d = ParseEulumdat(os.str(), "f.ldt");
  EXPECT_EQ(d.Symmetry(), CSymmetry::kQuadrant);
  ASSERT_EQ(d.c_deg.size(), 2u);
  EXPECT_DOUBLE_EQ(d.At(0, 0), 100);  // 200 cd/klm of 500 lm
  EXPECT_DOUBLE_EQ(d.At(1, 0), 150.25);
  EXPECT_DOUBLE_EQ(d.input_watts, 12.5);
  EXPECT_DOUBLE_EQ(d.opening.length_mm, 80);
  // One value short: truncated, named.
  const std::string cut = os.str().substr(0, os.str().rfind("0\n"));
  const auto [code, message] = Thrown([&] { ParseEulumdat(cut, "f.ldt"); });
  EXPECT_EQ(code, 2);
  EXPECT_NE(message.find("f.ldt: the intensities: 2 planes x 2 angles, the file has 3 values left"),
            std::string::npos)
      << message;
}

// Issue 29 red team: --opening-mm -40,-30,0 gave an ellipse in IES and a 30 mm circle in LDT,
// and mixed signs passed. One check (CheckPortableOpening) keeps the shapes both formats hold;
// the EULUMDAT writer refuses the others instead of turning them into a circle.
TEST(Opening, OnlyShapesIesAndLdtBothHold) {
  for (const LuminousOpening& ok : std::vector<LuminousOpening>{
           {0, 0, 0}, {20, 30, 0}, {20, 30, 5}, {-30, -30, 0}, {-30, -30, 10}})
    EXPECT_NO_THROW(CheckPortableOpening(ok, "--opening-mm", ""))
        << ok.width_mm << "," << ok.length_mm << "," << ok.height_mm;
  for (const LuminousOpening& bad : std::vector<LuminousOpening>{{-40, -30, 0},
                                                                 {-50, 40, 0},
                                                                 {50, -40, 0},
                                                                 {0, 30, 0},
                                                                 {20, 0, 0},
                                                                 {-30, -30, -30},
                                                                 {20, 30, -5},
                                                                 {std::nan(""), 1, 1}}) {
    const auto [code, message] = Thrown([&] { CheckPortableOpening(bad, "--opening-mm", ""); });
    EXPECT_EQ(code, 2);
    EXPECT_EQ(message.rfind("--opening-mm", 0), 0u) << message;
  }
  IntensityDistribution d = Analytic({0}, [](double) { return 1.0; });
  d.opening = {-40, -30, 0};
  const auto [code, message] = Thrown([&] { FormatEulumdat(d, "e.ldt", {}); });
  EXPECT_EQ(code, 2);
  EXPECT_NE(message.find("ellipse"), std::string::npos) << message;
  // A circle: IES's -D,-D and EULUMDAT's diameter D with width 0 read back as the same shape.
  d.opening = {-30, -30, 0};
  const IntensityDistribution back = ParseEulumdat(FormatEulumdat(d, "e.ldt", {}), "e.ldt");
  EXPECT_DOUBLE_EQ(back.opening.width_mm, -30);
  EXPECT_DOUBLE_EQ(back.opening.length_mm, -30);
}

std::string ReadText(const std::string& path) { return ReadTextFile(path); }

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

TEST(Ies, EditionsTiltAndFactors) {
  const std::string seven = ReadText(DataPath("7.ies"));
  const double flux = ParseIes(seven, "7.ies").TotalFlux();
  // 1995: the ballast-lamp photometric factor multiplies; 2002 and later it is not a factor.
  std::string v1995 =
      Replace(Replace(seven, "IESNA:LM-63-2002", "IESNA:LM-63-1995"), "1 1 8.64", "0.5 2 8.64");
  EXPECT_NEAR(ParseIes(v1995, "a.ies").TotalFlux(), flux, 1e-9 * flux);
  std::string v2002 = Replace(seven, "1 1 8.64", "0.5 2 8.64");
  EXPECT_NEAR(ParseIes(v2002, "a.ies").TotalFlux(), 0.5 * flux, 1e-9 * flux);
  // 1986: no edition line.
  const IntensityDistribution old = ParseIes(seven.substr(seven.find('\n') + 1), "a.ies");
  EXPECT_EQ(old.format, "IES LM-63-1986");
  EXPECT_NEAR(old.TotalFlux(), flux, 1e-9 * flux);
  // TILT=INCLUDE: read and recorded.
  const IntensityDistribution tilted =
      ParseIes(Replace(seven, "TILT=NONE", "TILT=INCLUDE\n1\n3\n0 45 90\n1 0.9 0.8"), "a.ies");
  EXPECT_NEAR(tilted.TotalFlux(), flux, 1e-9 * flux);
  EXPECT_NE(tilted.Keyword("TILT").find("3 pairs"), std::string::npos);
}

TEST(Ies, BadInputNamesTheFileAndTheField) {
  const std::string seven = ReadText(DataPath("7.ies"));
  const std::string one = ReadText(DataPath("1.ies"));
  struct Case {
    const char* what;
    std::string text;
    const char* expected;  // in the message
  };
  const Case cases[] = {
      {"truncated", one.substr(0, one.size() / 2),
       "bad.ies: line 27: 74 vertical x 12 horizontal angles need 974 numbers after this line, "
       "the file has 418"},
      {"cut before the data", one.substr(0, one.find("TILT")), "bad.ies: no TILT= line"},
      {"fewer vertical angles than counted", Replace(seven, "24 -1 1 37", "24 -1 1 38"),
       "bad.ies: line 22: 38 vertical x 1 horizontal angles need 77 numbers"},
      {"more values than counted", Replace(seven, "24 -1 1 37", "24 -1 1 36"),
       "bad.ies: line 28: 2 number(s) after the last candela value"},
      {"NaN value", Replace(seven, " 102 90", " nan 90"),
       "bad.ies: line 28: candela value 21 of horizontal angle 1: expected a finite number"},
      {"negative value", Replace(seven, " 102 90", " -102 90"),
       "bad.ies: intensity at C 0, gamma 50"},
      {"text value", Replace(seven, " 102 90", " x 90"), "got \"x\""},
      {"tilt file", Replace(seven, "TILT=NONE", "TILT=lamp.tlt"),
       "bad.ies: line 21: TILT=lamp.tlt: tilt data in another file is not read"},
      {"type B", Replace(seven, "37 1 1 1 -0.45", "37 1 2 1 -0.45"),
       "bad.ies: line 22: photometric type B is not read (type C only)"},
      {"angles out of order", Replace(seven, "0 2.5 5 7.5", "0 5 2.5 7.5"),
       "bad.ies: vertical angle 3: expected more than the one before"},
      {"binary", std::string("IESNA:LM-63-2002\n\0\0\0", 20), "bad.ies: not an IES file"},
  };
  for (const Case& c : cases) {
    const auto [code, message] = Thrown([&] { ParseIes(c.text, "bad.ies"); });
    EXPECT_EQ(code, 2) << c.what;
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.what << ": " << message;
  }
  const auto [code, message] = Thrown([&] { ReadIntensityFile(DataPath("missing.ies")); });
  EXPECT_EQ(code, 2);
  EXPECT_NE(message.find("missing.ies"), std::string::npos);
}

// Hostile input: thousands of truncations and byte changes of the real files either read or are
// refused as bad input (exit 2), never a crash, a hang or an allocation sized by a wild count.
TEST(Ies, MutatedFilesAreReadOrRefused) {
  std::mt19937 rng(11);
  for (const Reference& r : kReferences) {
    const std::string text = ReadText(DataPath(r.file));
    const IntensityDistribution d = ParseIes(text, r.file);
    const std::string ldt = FormatEulumdat(d, "x.ldt");
    for (int k = 0; k < 500; ++k) {
      for (const std::string* original : {&text, &ldt}) {
        std::string bad = *original;
        std::uniform_int_distribution<size_t> at(0, bad.size() - 1);
        if (k % 4 == 0) {
          bad.resize(at(rng));
        } else {
          for (int m = 0; m < 1 + k % 3; ++m)
            bad[at(rng)] = "0123456789 -.,e\n9"[std::uniform_int_distribution<int>(0, 17)(rng)];
        }
        try {
          (original == &text ? ParseIes : ParseEulumdat)(bad, "m");
        } catch (const Error& e) {
          ASSERT_EQ(e.exit_code(), 2) << e.what();
        }
      }
    }
  }
}

// Found by fuzz/fuzz_ies's invariants (the inputs are in fuzz/corpus/fuzz_ies/regression_*):
// values near the largest double, each finite, whose total flux overflows to inf (lumislab-export
// info printed "flux: inf" and a scene emitter's lobe would have been inf / inf), and angles
// closer than the writers printed (8 digits: 179.000002 and 179.000004 both "179"), which
// FormatIes wrote into a file ParseIes refused.
TEST(IntensityDistribution, FuzzFindingsFluxOverflowAndCloseAngles) {
  const std::string head = "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 4 1 1 2 0 0 0\n1 1 0\n";
  auto [code, message] =
      Thrown([&] { ParseIes(head + "0 45 90 180\n0\n1e308 1e308 1e308 0\n", "big.ies"); });
  EXPECT_EQ(code, 2);
  EXPECT_NE(message.find("big.ies: intensity values: expected values whose total flux is a finite"),
            std::string::npos)
      << message;
  // 1e308 feet of luminous width is inf mm, which FormatIes wrote as "inf".
  std::tie(code, message) = Thrown([&] {
    ParseIes("IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 3 1 1 1 1e308 0 0\n1 1 0\n0 45 90\n0\n1 1 1\n",
             "wide.ies");
  });
  EXPECT_EQ(code, 2);
  EXPECT_NE(message.find("wide.ies: luminous width: expected a finite size (mm), got inf"),
            std::string::npos)
      << message;
  std::tie(code, message) =
      Thrown([&] { ParseIes(head + "0 90 90.0000001 180\n0\n1 1 1 1\n", "close.ies"); });
  EXPECT_EQ(code, 2);
  EXPECT_NE(message.find("close.ies: vertical angle 3: expected more than the one before (90 deg "
                         "by over 1e-06 deg), got 90.0000001"),
            std::string::npos)
      << message;
  // 2e-6 degrees apart: read, and written back with the same angles by both writers.
  IntensityDistribution d = ParseIes(head + "0 179.000002 179.000004 180\n0\n4 3 2 1\n", "a.ies");
  for (const char* key : kIesRequiredKeywords) d.keywords.push_back({key, "x"});
  ExpectSameDistribution(d, ParseIes(FormatIes(d, {}, "b.ies"), "b.ies"), "IES");
  ExpectSameDistribution(d, ParseEulumdat(FormatEulumdat(d, "b.ldt"), "b.ldt"), "EULUMDAT");
  EXPECT_NEAR(ParseIes(FormatIes(d, {}, "b.ies"), "b.ies").gamma_deg[2], 179.000004, 1e-12);
}

// Found by fuzz/fuzz_eulumdat's round trip (inputs in fuzz/corpus/fuzz_eulumdat/regression_*): a
// grid whose end plane lies within the 1e-6 degree tolerance of a symmetry plane but not on it
// got its mirror image written as a second plane a hair away (the reader then counted one plane
// too many and refused the file), and a first plane at -5e-7 was written as 359.9999995.
TEST(Eulumdat, FuzzFindingsEndPlanesNearASymmetryPlane) {
  for (const std::vector<double>& c :
       std::vector<std::vector<double>>{{0, 45, 89.9999991},
                                        {-9e-7, 45, 90.0000009},
                                        {90.0000009, 180, 269.9999991},
                                        {0, 90, 179.9999991},
                                        {-5e-7, 90, 180, 270}}) {
    const IntensityDistribution d = Analytic(c, [](double c_deg) { return 1 + c_deg / 360; });
    const IntensityDistribution back = ParseEulumdat(FormatEulumdat(d, "q.ldt"), "q.ldt");
    ExpectSameDistribution(d, back,
                           "C " + std::to_string(c.front()) + " to " + std::to_string(c.back()));
  }
}

// Found by fuzz/fuzz_eulumdat (fuzz/corpus/fuzz_eulumdat/regression_values_near_max_double.ldt):
// intensities near the largest double (a finite total flux) were written as "inf", the downward
// flux fraction as 100 * flux / flux and the intensities as value * 1000 / flux both overflowing;
// the reader then refused what the writer wrote.
TEST(Eulumdat, FuzzFindingValuesNearTheLargestDoubleAreWrittenFinite) {
  IntensityDistribution d = Analytic({0, 90, 180, 270}, [](double) { return 1.0; });
  for (double& v : d.values) v *= 1e304;  // peak 1e306 cd: value * 1000 and 100 * flux overflow
  ASSERT_TRUE(std::isfinite(d.TotalFlux()));
  const std::string text = FormatEulumdat(d, "big.ldt");
  EXPECT_EQ(text.find("inf"), std::string::npos);
  ExpectSameDistribution(d, ParseEulumdat(text, "big.ldt"), "values near the largest double");
}

// lumislab-export info --json on a file whose text is not UTF-8 (an ISO-8859-1 maker's name, as
// European IES files have): nlohmann's dump threw type_error 316, exit 1 ("failure") for a good
// file. The description replaces the bytes (U+FFFD) and keeps the rest (found by reading
// export/formats_cli.cc for fuzz_photometry_info, which checks that the JSON parses back).
TEST(FileInfo, TextThatIsNotUtf8IsReplacedInTheJson) {
  const std::string path = ::testing::TempDir() + "/latin1.ies";
  WriteTextAtomically(path, Replace(ReadText(DataPath("7.ies")), "[MANUFAC]RAB LIGHTING",
                                    "[MANUFAC]Lichttechnik M\xfcller"));
  const nlohmann::json info = PhotometricFileInfo(path);
  const nlohmann::json back = nlohmann::json::parse(FormatPhotometricFileInfo(info, true));
  EXPECT_EQ(back["format"], "IES LM-63-2002");
  EXPECT_EQ(back["keywords"]["MANUFAC"], "Lichttechnik M\xef\xbf\xbdller, INC.");
  EXPECT_NEAR(back["flux"].get<double>(), 531.98, 0.005 * 531.98);
  EXPECT_NE(FormatPhotometricFileInfo(info, false).find("[MANUFAC] Lichttechnik M\xfcller"),
            std::string::npos);
}

}  // namespace
}  // namespace lumislab
