// The physical orientation of every export (docs/formats.md §17, "Orientation"): a luminaire whose
// one lobe leans towards a known direction of the luminaire frame, (sin 20° cos 60°,
// -sin 20° sin 60°, cos 20°) = +x and -y, i.e. C = 60, gamma = 20 under type C with C = 90
// towards -y. A mirrored convention puts it at C = 300, a C = 0 / C = 90 swap at C = 30: the
// lobe must come out at C = 60 in the IES and EULUMDAT files, as the TM-25 rays' mean direction,
// on the right-hand (C0, C90) side of both polar curves with the C90 side the larger, and in the
// lower right of the plane picture (+x right, +y up).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <regex>
#include <sstream>

#include "../e2e/test_util.h"
#include "core/exr_io.h"
#include "core/geometry.h"
#include "lib/photometry/eulumdat.h"
#include "lib/photometry/ies.h"
#include "lib/photometry/tm25.h"
#include "lib/synthetic/luminaire.h"
#include "lib/synthetic/truth.h"

namespace lumislab {
namespace {

using testing::FreshDir;
using testing::RunTool;
using testing::ShellQuote;

constexpr double kLobeC = 60, kLobeGamma = 20;  // degrees

// An axially symmetric IES file, cos^40 (half maximum at 10.7 degrees): the lobe's shape with no
// C of its own, so that only the emitter's rotation (a physical direction) sets where it points
// and the file reader's C convention plays no part.
void WriteAxialLobe(const std::string& path) {
  std::ofstream out(path);
  out << "IESNA:LM-63-2002\n[TEST] lobe\n[MANUFAC] lumislab test\nTILT=NONE\n"
      << "1 -1 1 37 1 1 2 0 0 0\n1 1 0\n";
  for (int k = 0; k <= 36; ++k) out << k * 2.5 << (k < 36 ? " " : "\n");
  out << "0\n";
  for (int k = 0; k <= 36; ++k)
    out << 1000 * std::pow(std::cos(k * 2.5 * kPi / 180), 40) << (k < 36 ? " " : "\n");
}

// The truth slab (9 x 7 positions, h = 5 mm, 48 texels, d = 750 mm, 1.2 m window) of one emitter
// 1 mm behind S whose lobe axis, the file's gamma = 0, is turned by Rz(-60) Ry(20): first
// towards +x by 20 degrees, then about +z by -60 degrees, to (C, gamma) = (60, 20). In lux, as
// IES and EULUMDAT want.
struct Fixture {
  // ctest runs each test in its own process, in parallel: each its own folder.
  std::string dir = FreshDir(std::string("export_orientation_") +
                             ::testing::UnitTest::GetInstance()->current_test_info()->name());
  Fixture() {
    WriteAxialLobe(dir + "/lobe.ies");
    Emitter e;
    e.position_mm = {0, 0, -1};
    e.intensity_w_sr = {1, 1, 1};
    e.measured = std::make_shared<const MeasuredLobe>(
        MeasuredLobe::Load(dir + "/lobe.ies", {0, kLobeGamma, -kLobeC}));
    Luminaire luminaire;
    luminaire.emitters.push_back(e);
    SlabInfo info = DefaultSlabInfo(9, 7, 5, 48);
    info.units = "lux";
    WriteTruthSlab(luminaire, info, dir + "/ds/slab", 2);
  }
  std::string Slab() const { return ShellQuote(dir + "/ds/slab"); }
};
const Fixture& Data() {
  static const Fixture fixture;
  return fixture;
}

// Every direction the grids below ask for is inside the cone the slab saw (gamma <= 30 of the
// 37 degrees the window sees on its axes), so no file holds an unseen direction.
const char kGrid[] =
    " --c-step 15 --gamma-angles 0,2.5,5,7.5,10,12.5,15,17.5,20,22.5,25,27.5,30 --test T-1"
    " --lab Lab --manufacturer Maker --issue-date 2026-12-05";

// The (C, gamma) of the file's largest intensity.
Eigen::Vector2d PeakDirection(const IntensityDistribution& d) {
  size_t best = 0;
  for (size_t k = 1; k < d.values.size(); ++k)
    if (d.values[k] > d.values[best]) best = k;
  return {d.c_deg[best / d.gamma_deg.size()], d.gamma_deg[best % d.gamma_deg.size()]};
}

void ExpectLobeAtC60(const IntensityDistribution& d) {
  const Eigen::Vector2d peak = PeakDirection(d);
  std::printf("%s: peak at C %.1f, gamma %.1f\n", d.format.c_str(), peak.x(), peak.y());
  EXPECT_EQ(peak.x(), kLobeC);
  EXPECT_NEAR(peak.y(), kLobeGamma, 2.5);
  // Where the lobe's mirror images would be, the file holds what the truth holds there,
  // cos^40 of the angle to the lobe's axis: about the C0-C180 plane (C = 300, 34.5 degrees
  // off the axis: 0.0006), about the C90-C270 plane (C = 120, 19.7 degrees: 0.09) and about the
  // C = 45 diagonal (C = 30, x and y swapped; 10.2 degrees: 0.53).
  const double at = d.Intensity(kLobeC, kLobeGamma);
  const Eigen::Vector3d axis = TypeCDirection(kLobeC, kLobeGamma);
  for (const double mirror : {300.0, 120.0, 30.0}) {
    const double truth = std::pow(axis.dot(TypeCDirection(mirror, kLobeGamma)), 40);
    EXPECT_NEAR(d.Intensity(mirror, kLobeGamma) / at, truth, 0.02) << "C " << mirror;
  }
}

TEST(ExportOrientation, IesAndEulumdatHoldTheLobeAtItsCAngle) {
  const Fixture& f = Data();
  const std::string ies = f.dir + "/out.ies", ldt = f.dir + "/out.ldt";
  auto r =
      RunTool("lumislab-export", "ies --slab " + f.Slab() + " --out " + ShellQuote(ies) + kGrid);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ExpectLobeAtC60(ReadIes(ies));
  r = RunTool("lumislab-export", "ldt --slab " + f.Slab() + " --out " + ShellQuote(ldt) + kGrid);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ExpectLobeAtC60(ReadEulumdat(ldt));
}

TEST(ExportOrientation, Tm25RaysLeanTowardsTheLobe) {
  const Fixture& f = Data();
  const std::string path = f.dir + "/out.ray";
  const auto r =
      RunTool("lumislab-export", "tm25 --slab " + f.Slab() + " --out " + ShellQuote(path) +
                                     " --rays 20000 --seed 5 --allow-partial");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Tm25Ray& ray : ReadTm25(path).rays)
    mean += ray.flux * Eigen::Vector3d(ray.kx, ray.ky, ray.kz);
  // Rays are positions and directions in the luminaire frame (no C convention): the flux-weighted
  // mean direction leans to +x and -y; its C by TypeCAngles is the lobe's.
  const Eigen::Vector2d c_gamma = TypeCAngles(mean);
  std::printf("TM-25 mean direction (%.3f, %.3f, %.3f): C %.1f, gamma %.1f\n", mean.x(), mean.y(),
              mean.z(), c_gamma.x(), c_gamma.y());
  EXPECT_GT(mean.x(), 0);
  EXPECT_LT(mean.y(), 0);
  EXPECT_NEAR(c_gamma.x(), kLobeC, 3);
  EXPECT_NEAR(c_gamma.y(), kLobeGamma, 3);
}

// The polar diagram's two curves (SVG polylines of the planes' colours, the longest of each: the
// legend's sample is two points): how far each reaches right (C0, C90) and left (C180, C270) of
// the centre, in pixels.
struct CurveReach {
  double right = 0, left = 0;
};
CurveReach Reach(const std::string& svg, const std::string& colour, double centre_x) {
  const std::regex line("<polyline[^>]*stroke=\"" + colour + "\"[^>]*points=\"([^\"]*)\"");
  CurveReach best;
  size_t most = 0;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), line); it != std::sregex_iterator();
       ++it) {
    std::istringstream points((*it)[1].str());
    std::string pair;
    CurveReach reach;
    size_t n = 0;
    while (points >> pair) {
      const double x = std::stod(pair.substr(0, pair.find(',')));
      reach.right = std::max(reach.right, x - centre_x);
      reach.left = std::max(reach.left, centre_x - x);
      ++n;
    }
    if (n > most) {
      most = n;
      best = reach;
    }
  }
  return best;
}

TEST(ExportOrientation, PolarPlotDrawsTheLobeOnTheC0AndC90Side) {
  const Fixture& f = Data();
  const std::string svg_path = f.dir + "/polar.svg";
  const auto r = RunTool("lumislab-export", "polar --slab " + f.Slab() + " --out " +
                                                ShellQuote(svg_path) + " --size 600");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(svg_path);
  std::stringstream text;
  text << in.rdbuf();
  const CurveReach c0 = Reach(text.str(), "#c81e1e", 300), c90 = Reach(text.str(), "#1e46c8", 300);
  std::printf("polar: C0-C180 reaches %.0f px right, %.0f left; C90-C270 %.0f right, %.0f left\n",
              c0.right, c0.left, c90.right, c90.left);
  // C = 60 lies 30 degrees from C90 and 60 from C0, and on their sides of the diagram.
  EXPECT_GT(c0.right, 2 * c0.left);
  EXPECT_GT(c90.right, 2 * c90.left);
  EXPECT_GT(c90.right, c0.right);
}

TEST(ExportOrientation, PlanePictureShowsPlusXRightAndPlusYUp) {
  const Fixture& f = Data();
  const std::string exr = f.dir + "/plane.exr";
  const auto r = RunTool("lumislab-export", "irradiance --slab " + f.Slab() + " --out " +
                                                ShellQuote(exr) + " --distance-mm 750 --size 64");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const ImageF image = ReadExr(exr, {"R", "G", "B"});
  // The illuminance's centroid in plane millimetres, taking column c to x = (c + 0.5 - w/2)
  // 1200 / w and row r to y = (h/2 - r - 0.5) 1200 / h (the extent is the window at D = d).
  double sum = 0, x = 0, y = 0;
  for (int row = 0; row < image.height; ++row)
    for (int col = 0; col < image.width; ++col) {
      const double e = std::max(0.0f, image.at(col, row, 1));
      sum += e;
      x += e * (col + 0.5 - image.width / 2.0) * 1200 / image.width;
      y += e * (image.height / 2.0 - row - 0.5) * 1200 / image.height;
    }
  ASSERT_GT(sum, 0);
  x /= sum;
  y /= sum;
  // The lobe's axis meets the plane at 750 tan 20 (cos 60, -sin 60) = (137, -236) mm; the
  // centroid of its light lies further out along the same azimuth.
  const double azimuth = std::atan2(-y, x) * 180 / kPi;
  std::printf("plane: illuminance centroid (%.0f, %.0f) mm, C %.1f\n", x, y, azimuth);
  EXPECT_GT(x, 100);
  EXPECT_LT(y, -150);
  EXPECT_NEAR(azimuth, kLobeC, 5);
}

}  // namespace
}  // namespace lumislab
