// EULUMDAT details of issue 29 (item 6): Ityp 1 or 3 (never 0), the lamp sets as the caller
// gives them or as absolute photometry, the direct ratios of line 27 against published files and
// an analytic case, and CR LF line endings (the reader takes LF and CR LF).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/geometry.h"
#include "lib/photometry/eulumdat.h"
#include "lib/photometry/intensity_distribution.h"

namespace lumislab {
namespace {

// The file's lines without their line ending.
std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  return lines;
}

// EULUMDAT line `n` (1-based, lines 1-26 one field each), and the fields after line 26's lamp sets:
// LampField(lines, set, k) is line 26a + k of lamp set `set`, DirectRatio(lines, i) line 27's i-th.
std::string Line(const std::vector<std::string>& lines, int n) { return lines.at(n - 1); }
std::string LampField(const std::vector<std::string>& lines, int set, int k) {
  return lines.at(26 + 6 * set + k);
}
double DirectRatio(const std::vector<std::string>& lines, int i) {
  const int sets = std::stoi(Line(lines, 26));
  std::string v = lines.at(26 + 6 * sets + i);
  for (char& ch : v)
    if (ch == ',') ch = '.';
  return std::stod(v);
}

// A distribution on the given C planes: I(C, gamma) = shape(C, gamma) cd, gamma 0-180 in 5 degrees.
IntensityDistribution Analytic(std::vector<double> c,
                               const std::function<double(double, double)>& shape) {
  IntensityDistribution d;
  d.format = "test";
  d.c_deg = std::move(c);
  for (int g = 0; g <= 180; g += 5) d.gamma_deg.push_back(g);
  for (double cv : d.c_deg)
    for (double g : d.gamma_deg) d.values.push_back(shape(cv, g));
  d.keywords = {{"MANUFAC", "maker"}};
  return d;
}
double Cosine(double, double g) { return g < 90 ? 100 * std::cos(g * kPi / 180) : 0; }

std::string DataPath(const std::string& name) {
  return std::string(LUMISLAB_SOURCE_DIR) + "/tests/data/ldt/" + name;
}

// eulumdat-rs's parser refuses Ityp 0 (it reads 1-3); lumislab wrote 0 for every asymmetric
// distribution.
TEST(LdtDetails, ItypIsOneForAxialAndThreeOtherwise) {
  const std::vector<std::pair<std::vector<double>, int>> cases = {{{0}, 1},
                                                                  {{0, 45, 90}, 3},
                                                                  {{0, 90, 180}, 3},
                                                                  {{90, 180, 270}, 3},
                                                                  {{0, 90, 180, 270, 360}, 3}};
  for (const auto& [c, ityp] : cases) {
    const IntensityDistribution d =
        Analytic(c, [](double cv, double g) { return Cosine(cv, g) * (1 + 0.001 * cv); });
    const std::string text = FormatEulumdat(d, "x.ldt");
    EXPECT_EQ(Line(Lines(text), 2), std::to_string(ityp)) << "C planes " << c.size();
    // Files of other writers with Ityp 0 (as lumislab wrote them) are still read.
    std::string old = text;
    old.replace(old.find("\r\n") + 2, 1, "0");
    EXPECT_EQ(ParseEulumdat(old, "old.ldt").values, ParseEulumdat(text, "x.ldt").values);
  }
}

// Without lamp sets: absolute photometry (number of lamps -1, the luminaire's flux, LORL 100 %),
// the LAMP, COLORTEMP and CRI keywords and the input watts; with sets: as given, the intensities
// per 1000 lm of the first set's flux and LORL the luminaire's share of it. Before, one set of 1
// lamp with "-" for the colour fields was written whatever the caller knew.
TEST(LdtDetails, LampSetsAreTheCallersOrAbsolutePhotometry) {
  IntensityDistribution d = Analytic({0}, Cosine);
  const double flux = d.TotalFlux();
  std::vector<std::string> lines = Lines(FormatEulumdat(d, "x.ldt"));
  EXPECT_EQ(Line(lines, 23), "100");  // LORL, %
  EXPECT_EQ(Line(lines, 26), "1");
  EXPECT_EQ(LampField(lines, 0, 0), "-1");
  EXPECT_EQ(LampField(lines, 0, 1), "luminaire (absolute photometry)");
  EXPECT_NEAR(std::stod(LampField(lines, 0, 2)), flux, 1e-8 * flux);
  EXPECT_EQ(LampField(lines, 0, 3), "-");
  EXPECT_EQ(LampField(lines, 0, 4), "-");
  EXPECT_EQ(LampField(lines, 0, 5), "0");

  d.keywords.push_back({"LAMP", "LED module"});
  d.keywords.push_back({"COLORTEMP", "3000 K"});
  d.keywords.push_back({"CRI", "Ra 90"});
  d.input_watts = 12.5;
  lines = Lines(FormatEulumdat(d, "x.ldt"));
  EXPECT_EQ(LampField(lines, 0, 1), "LED module");
  EXPECT_EQ(LampField(lines, 0, 3), "3000 K");
  EXPECT_EQ(LampField(lines, 0, 4), "Ra 90");
  EXPECT_EQ(LampField(lines, 0, 5), "12.5");
  const IntensityDistribution back = ParseEulumdat(FormatEulumdat(d, "x.ldt"), "x.ldt");
  EXPECT_EQ(back.Keyword("COLORTEMP"), "3000 K");
  EXPECT_EQ(back.Keyword("CRI"), "Ra 90");
  EXPECT_EQ(back.input_watts, 12.5);

  // Relative photometry: two lamps of 2 x flux in all (LORL 50 %), an alternative set after it.
  EulumdatWriteOptions options;
  options.lamp_sets = {{2, "T16 54W", 2 * flux, "4000 K", "1B", 120},
                       {2, "T16 80W", 3 * flux, "", "", 180}};
  const std::string text = FormatEulumdat(d, "x.ldt", options);
  lines = Lines(text);
  EXPECT_EQ(Line(lines, 23), "50");
  EXPECT_EQ(Line(lines, 26), "2");
  EXPECT_EQ(LampField(lines, 0, 0), "2");
  EXPECT_EQ(LampField(lines, 0, 1), "T16 54W");
  EXPECT_EQ(LampField(lines, 0, 3), "4000 K");
  EXPECT_EQ(LampField(lines, 0, 4), "1B");
  EXPECT_EQ(LampField(lines, 0, 5), "120");
  EXPECT_EQ(LampField(lines, 1, 1), "T16 80W");
  EXPECT_EQ(LampField(lines, 1, 3), "-");  // not given
  // The reader scales cd/klm by the first set's flux: the luminaire's candela come back.
  const IntensityDistribution relative = ParseEulumdat(text, "x.ldt");
  for (size_t k = 0; k < d.values.size(); ++k)
    EXPECT_NEAR(relative.values[k], d.values[k], 1e-6 * d.values[0]) << k;
  EXPECT_EQ(relative.input_watts, 120);

  options.lamp_sets = {{0, "x", flux, "", "", 1}};
  try {
    FormatEulumdat(d, "bad.ldt", options);
    ADD_FAILURE() << "0 lamps written";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("bad.ldt: lamp set 1: number of lamps"), std::string::npos)
        << e.what();
  }
  options.lamp_sets = {{1, "x", flux, "", "", 1}, {1, "y", -1, "", "", 1}};
  try {
    FormatEulumdat(d, "bad.ldt", options);
    ADD_FAILURE() << "negative flux written";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.ldt: lamp set 2: flux"), std::string::npos)
        << e.what();
  }
}

// The view factor between two directly opposed parallel squares of side a at distance 1 (Hottel's
// closed form for rectangles, X = Y = a): the direct ratio of a Lambertian luminaire.
double ParallelSquaresViewFactor(double a) {
  const double x = a, s = std::sqrt(1 + x * x);
  return 2 / (kPi * x * x) *
         (0.5 * std::log((1 + x * x) * (1 + x * x) / (1 + 2 * x * x)) +
          2 * x * s * std::atan(x / s) - 2 * x * std::atan(x));
}

// A Lambertian luminaire (I = I0 cos gamma) gives the view factor of the ceiling to the work
// plane at each room index (a = 2k), within 1e-5 (measured 3e-6); a narrow beam puts nearly
// everything on the work plane.
TEST(LdtDetails, DirectRatiosOfAnalyticLuminaires) {
  const std::array<double, 10> lambert = LdtDirectRatios(Analytic({0}, Cosine));
  for (size_t k = 0; k < kLdtRoomIndices.size(); ++k) {
    const double expected = ParallelSquaresViewFactor(2 * kLdtRoomIndices[k]);
    std::printf("k %.2f: Lambertian direct ratio %.6f, view factor %.6f\n", kLdtRoomIndices[k],
                lambert[k], expected);
    EXPECT_NEAR(lambert[k], expected, 1e-5) << kLdtRoomIndices[k];
  }
  const std::array<double, 10> narrow =
      LdtDirectRatios(Analytic({0}, [](double, double g) { return g < 5 ? 1000 - 200 * g : 0; }));
  // (Luminaires near a wall light it a little: 1 - 2 E|x| / a to first order, 0.95 at k = 0.6.)
  EXPECT_GT(narrow[0], 0.95);
  EXPECT_GT(narrow[9], 0.99);
  for (size_t k = 1; k < narrow.size(); ++k) EXPECT_GT(narrow[k], narrow[k - 1]);
  // No downward light: 0, not NaN.
  const std::array<double, 10> up =
      LdtDirectRatios(Analytic({0}, [](double, double g) { return g > 90 ? 1.0 : 0.0; }));
  for (double r : up) EXPECT_EQ(r, 0);
}

// Three files whose line 27 another tool computed (tests/data/ldt/README.md): the direct ratios
// computed from their intensities agree within 0.015 (absolute) at every room index, and a file
// lumislab writes carries the computed ones. Before, line 27 was ten zeros.
TEST(LdtDetails, DirectRatiosAgreeWithPublishedFiles) {
  for (const char* file : {"road_luminaire.ldt", "fluorescent_luminaire.ldt", "projector.ldt"}) {
    const std::string text = ReadTextFile(DataPath(file));
    const std::vector<std::string> published = Lines(text);
    const IntensityDistribution d = ParseEulumdat(text, file);
    const std::array<double, 10> ratios = LdtDirectRatios(d);
    double worst = 0;
    for (size_t k = 0; k < ratios.size(); ++k) {
      const double reference = DirectRatio(published, int(k));
      worst = std::max(worst, std::abs(ratios[k] - reference));
      EXPECT_NEAR(ratios[k], reference, 0.015) << file << " k " << kLdtRoomIndices[k];
    }
    std::printf("%s (Isym %s): direct ratios within %.4f of the published ones\n", file,
                Line(published, 3).c_str(), worst);
    const std::vector<std::string> written = Lines(FormatEulumdat(d, "x.ldt"));
    for (size_t k = 0; k < ratios.size(); ++k)
      EXPECT_NEAR(DirectRatio(written, int(k)), ratios[k], 5e-5) << file;
  }
}

// Every line ends in CR LF; the reader reads the file with CR LF and with LF alike.
TEST(LdtDetails, LinesEndInCrLfAndTheReaderTakesBoth) {
  const IntensityDistribution d =
      Analytic({0, 30, 60, 90}, [](double c, double g) { return Cosine(c, g) * (1 + c / 90); });
  const std::string text = FormatEulumdat(d, "x.ldt");
  size_t lf = 0;
  for (size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n') {
      ++lf;
      ASSERT_TRUE(i > 0 && text[i - 1] == '\r') << "line " << lf << " ends in a bare LF";
    } else if (text[i] == '\r') {
      ASSERT_TRUE(i + 1 < text.size() && text[i + 1] == '\n') << "a CR without LF";
    }
  EXPECT_GT(lf, 40u);
  EXPECT_EQ(text.substr(text.size() - 2), "\r\n");
  std::string unix_text;
  for (char ch : text)
    if (ch != '\r') unix_text += ch;
  const IntensityDistribution crlf = ParseEulumdat(text, "x.ldt");
  const IntensityDistribution plain = ParseEulumdat(unix_text, "x.ldt");
  EXPECT_EQ(crlf.values, plain.values);
  EXPECT_EQ(crlf.c_deg, plain.c_deg);
  EXPECT_EQ(crlf.keywords, plain.keywords);
  for (size_t k = 0; k < d.values.size(); ++k)
    EXPECT_NEAR(crlf.values[k], d.values[k], 1e-6 * 200) << k;
}

}  // namespace
}  // namespace lumislab
