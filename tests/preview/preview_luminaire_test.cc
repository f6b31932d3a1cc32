// lumislab-preview on a luminaire folder (docs/method.md §4.12, "The preview of a luminaire
// folder"): the full-sphere synthetic luminaire turned into cube-face orientations, each a truth
// slab (2000 mm screen at d = 750 mm), lights receiver planes in front of, behind and beside it
// as the analytic luminaire does (--analytic over the whole luminaire frame), where one slab
// cannot; a receiver that only the overlap of two orientations lights is not lit twice; the
// shader's blend taper is core's ConeTaper; --watch adds an orientation whose slab appears.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "../e2e/test_util.h"
#include "core/exr_io.h"
#include "core/geometry.h"
#include "core/luminaire_set.h"
#include "lib/synthetic/scene.h"
#include "lib/synthetic/truth.h"
#include "preview/renderer.h"
#include "preview_slab_files.h"
#include "preview_test_util.h"

namespace lumislab {
namespace {

namespace fs = std::filesystem;

std::string Scratch(const std::string& name) {
  return ::testing::TempDir() + "/preview_luminaire_" + std::to_string(getpid()) + "_" + name;
}

// The cube's faces: rotation_deg [rx, ry, rz] of the orientation that turns the face's normal
// (luminaire frame) to +z of the capture frame.
struct Face {
  const char* name;
  Eigen::Vector3d rotation_deg;
};
const Face kFaces[6] = {{"o00", {0, 0, 0}},  {"o01", {0, -90, 0}}, {"o02", {180, 0, 0}},
                        {"o03", {0, 90, 0}}, {"o04", {90, 0, 0}},  {"o05", {-90, 0, 0}}};

// The slab layout of every orientation: a 2000 mm screen at d = 750 mm (the full-sphere scene's),
// few texels and positions (quick to write and render), the grid wide enough that every ray of
// the cone (51.8 degrees: ConeOfDataset takes the positions' support off the screen) crosses S
// where the grid's duals sum to 1, |u| <= ((7 - 1)/2 - 1) 12 = 24 mm, from an emitter within
// 4 mm of the luminaire's centre, CentreDepth behind S.
SlabInfo OrientationSlabInfo() {
  SlabInfo info = DefaultSlabInfo(7, 7, 12, 48);
  info.layout.window_w_mm = info.layout.window_h_mm = 2000;
  return info;
}

Luminaire FullSphere() { return LoadScene("full-sphere").luminaire; }

// The luminaire's centre behind S in every orientation (mm): its emitters' reach about the
// centre and a margin.
double CentreDepth(const Luminaire& luminaire) {
  double reach = 0;
  for (const Emitter& e : luminaire.emitters)
    reach = std::max(reach, (e.position_mm - luminaire.centre_mm).norm());
  return reach + 6;
}

// The truth slab of face `face` in <lum>/<name>/slab (written once per process and copied).
std::string FaceSlab(int face) {
  static std::vector<std::string> slabs(6);
  std::string& dir = slabs[face];
  if (dir.empty()) {
    dir = Scratch(std::string("slab_") + kFaces[face].name);
    fs::remove_all(dir);
    const Luminaire luminaire = FullSphere();
    const Eigen::Vector3d centre(0, 0, -CentreDepth(luminaire));
    WriteTruthSlab(luminaire.Turned(RotationZyxDegrees(kFaces[face].rotation_deg), centre),
                   OrientationSlabInfo(), dir, 2);
  }
  return dir;
}

// A luminaire folder of the faces `faces` (truth/luminaire.json beside them for --analytic);
// `with_slab`: which of them have their slab now (the others' come later, --watch).
std::string LuminaireFolder(const std::string& name, const std::vector<int>& faces,
                            std::vector<bool> with_slab = {}) {
  const std::string lum = Scratch(name);
  fs::remove_all(lum);
  fs::create_directories(lum + "/truth");
  const Luminaire luminaire = FullSphere();
  WriteTruthLuminaire(luminaire, lum + "/truth/luminaire.json");
  LuminaireSet set;
  set.folder = lum;
  set.coverage = "sphere";
  for (size_t k = 0; k < faces.size(); ++k) {
    Orientation o;
    o.name = kFaces[faces[k]].name;
    o.dataset = o.name;
    o.rotation_deg = kFaces[faces[k]].rotation_deg;
    o.centre_mm = Eigen::Vector3d(0, 0, -CentreDepth(luminaire));
    set.orientations.push_back(o);
    fs::create_directories(lum + "/" + o.dataset);
    if (with_slab.empty() || with_slab[k])
      fs::copy(FaceSlab(faces[k]), lum + "/" + o.dataset + "/slab", fs::copy_options::recursive);
  }
  WriteLuminaireSet(set);
  return lum;
}

// A receiver plane D mm from the luminaire's origin, the luminaire turned in the scene by
// (rx, ry) degrees (so the plane sees its directions about R^T z), `extent` mm wide, 32 x 32
// pixels, irradiance (W/m^2): the preview of `lum`, or the analytic image of its truth.
ImageF Plane(const std::string& lum, double rx, double ry, double extent, bool analytic,
             const std::string& out_name) {
  const std::string out = Scratch(out_name + ".exr");
  const std::string pose = "0,0,0," + std::to_string(rx) + "," + std::to_string(ry) + ",0";
  std::vector<std::string> args = {"--slab", lum, "--scene", "plane", "--receiver-plane", "1500"};
  args.insert(args.end(), {"--extent", std::to_string(extent), "--luminaire-pose", pose});
  args.insert(args.end(), {"--size", "32x32", "--no-shadows", "--threads", "2", "--out", out});
  if (analytic) args.insert(args.end(), {"--analytic", lum});
  EXPECT_EQ(RunPreviewWith(args), 0) << out_name;
  return ReadExr(out, {"R", "G", "B"});
}

double RelativeL2(const ImageF& a, const ImageF& b) {
  double num = 0, den = 0;
  for (size_t k = 0; k < b.data.size(); ++k) {
    num += std::pow(double(a.data[k]) - b.data[k], 2);
    den += std::pow(double(b.data[k]), 2);
  }
  return std::sqrt(num / den);
}

double Sum(const ImageF& image) {
  double sum = 0;
  for (float v : image.data) sum += v;
  return sum;
}

double Peak(const ImageF& image) {
  double peak = 0;
  for (float v : image.data) peak = std::max(peak, double(v));
  return peak;
}

TEST(PreviewLuminaire, ShaderTaperEqualsConeTaper) {
  Context();
  Dataset dataset;
  const SlabInfo info = OrientationSlabInfo();
  dataset.distance_mm = info.distance_mm;
  dataset.grid = info.grid;
  dataset.screen_w_mm = 2000;
  dataset.screen_h_mm = 1400;  // unequal sides: each axis its own limit
  dataset.filter = info.filter;
  const OrientationCone cone = ConeOfDataset(dataset);
  // Directions over the sphere (a Fibonacci spiral), denser near the cone's edges.
  std::vector<Eigen::Vector3d> directions;
  const int n = 4000;
  for (int k = 0; k < n; ++k) {
    const double z = 1 - (k + 0.5) * 2.0 / n, r = std::sqrt(1 - z * z);
    const double phi = k * M_PI * (3 - std::sqrt(5.0));
    directions.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
  }
  const double limit_x = std::atan2(cone.half_w_mm, cone.distance_mm);
  const double limit_y = std::atan2(cone.half_h_mm, cone.distance_mm);
  for (int k = 0; k < 400; ++k) {  // inside the taper band of each axis
    const double margin = (k % 100) * 5.0 / 100 * M_PI / 180, along = (k / 100 - 1.5) * 0.3;
    const double ax = (k < 200 ? limit_x - margin : along),
                 ay = (k < 200 ? along : limit_y - margin);
    directions.push_back(Eigen::Vector3d(std::tan(ax), std::tan(ay), 1).normalized());
  }
  const std::vector<double> gl = ShaderConeTaper(cone, directions);
  ASSERT_EQ(gl.size(), directions.size());
  double worst = 0;
  int tapering = 0;
  for (size_t k = 0; k < directions.size(); ++k) {
    const double cpu = ConeTaper(cone, directions[k]);
    worst = std::max(worst, std::abs(gl[k] - cpu));
    tapering += cpu > 0 && cpu < 1;
  }
  std::printf("shader taper vs ConeTaper: %zu directions (%d in the taper), max |diff| %.3g\n",
              directions.size(), tapering, worst);
  EXPECT_GT(tapering, 300);
  EXPECT_LT(worst, 1e-4);
}

// Six cube-face orientations light planes in front of (+z), behind (-z), beside (+x, +y) and
// oblique to the luminaire (three faces' cones meet there) as the analytic luminaire does; the
// first face alone lights only the front.
TEST(PreviewLuminaire, AllOrientationsLightTheWholeSphere) {
  if (testing::kSanitized) GTEST_SKIP() << "six truth slabs: too slow under sanitizers";
  const std::string six = LuminaireFolder("six", {0, 1, 2, 3, 4, 5});
  const std::string one = LuminaireFolder("one", {0});
  struct View {
    const char* name;
    double rx, ry;
  };
  // The luminaire turned in the scene so that the plane (scene +z) faces its direction R^T z.
  for (const View& v : {View{"front", 0, 0}, View{"behind", 180, 0}, View{"beside_x", 0, -90},
                        View{"beside_y", 90, 0}, View{"oblique", -35.26, -45}}) {
    const ImageF analytic = Plane(six, v.rx, v.ry, 2400, true, std::string("an_") + v.name);
    const ImageF gl = Plane(six, v.rx, v.ry, 2400, false, std::string("six_") + v.name);
    const ImageF single = Plane(one, v.rx, v.ry, 2400, false, std::string("one_") + v.name);
    const double e = RelativeL2(gl, analytic);
    std::printf("%-8s six orientations vs analytic %.4f; one orientation: peak %.3g of %.3g\n",
                v.name, e, Peak(single), Peak(analytic));
    EXPECT_GT(Peak(analytic), 0) << v.name;
    EXPECT_LT(e, 0.01) << v.name;
    if (std::string(v.name) == "behind") {
      EXPECT_EQ(Peak(single), 0) << "one slab lights behind S";
    }
  }
  // The false-colour view of the whole luminaire in a room (shadows: every position's map).
  const std::string png = Scratch("crypt_false_colour.png");
  EXPECT_EQ(RunPreviewWith({"--slab", six, "--scene", "crypt", "--size", "48x32", "--view",
                            "false-colour", "--out", png}),
            0);
  EXPECT_TRUE(fs::exists(png));
}

// A receiver that only the overlap of the +z and +x faces sees (directions 45 +- 5 degrees
// between them): each face alone lights it fully, both together light it once, not twice.
TEST(PreviewLuminaire, OverlapIsNotCountedTwice) {
  const std::string both = LuminaireFolder("both", {0, 1});
  const std::string z_only = LuminaireFolder("z_only", {0}),
                    x_only = LuminaireFolder("x_only", {1});
  const double extent = 2 * 1500 * std::tan(5 * M_PI / 180);
  const ImageF analytic = Plane(both, 0, -45, extent, true, "overlap_analytic");
  const double e_both = RelativeL2(Plane(both, 0, -45, extent, false, "overlap_both"), analytic);
  const double e_z = RelativeL2(Plane(z_only, 0, -45, extent, false, "overlap_z"), analytic);
  const double e_x = RelativeL2(Plane(x_only, 0, -45, extent, false, "overlap_x"), analytic);
  std::printf("overlap: both vs analytic %.4f, +z alone %.4f, +x alone %.4f\n", e_both, e_z, e_x);
  EXPECT_LT(e_both, 0.01);
  EXPECT_LT(e_z, 0.01);  // each sees it all: a plain sum would be twice the light
  EXPECT_LT(e_x, 0.01);
}

// --watch on a luminaire folder whose second orientation has no slab yet: it is added when its
// slab appears, and the last image is the finished folder's.
TEST(PreviewLuminaire, WatchAddsAnOrientationThatAppears) {
  const std::string lum = LuminaireFolder("watch", {0, 1}, {true, false});
  const std::string finished = LuminaireFolder("watch_finished", {0, 1});
  const std::string out = Scratch("watch.exr"), expected = Scratch("watch_expected.exr");
  const std::vector<std::string> common = {
      "--scene",  "plane", "--receiver-plane", "1500",  "--luminaire-pose", "0,0,0,0,-45,0",
      "--extent", "2400",  "--size",           "32x32", "--no-shadows"};
  int code = -1;
  std::thread watcher([&] {
    std::vector<std::string> args = {"--slab", lum, "--watch", "--poll", "0.05", "--out", out};
    args.insert(args.end(), common.begin(), common.end());
    code = RunPreviewWith(args);
  });
  // The first image (one orientation), then the second orientation's slab arrives whole.
  const auto start = std::chrono::steady_clock::now();
  while (!fs::exists(out) && std::chrono::steady_clock::now() - start < std::chrono::seconds(30))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(fs::exists(out));
  const ImageF first = ReadExr(out, {"R", "G", "B"});
  fs::copy(FaceSlab(1), lum + "/o01/slab_incoming", fs::copy_options::recursive);
  fs::rename(lum + "/o01/slab_incoming", lum + "/o01/slab");
  watcher.join();
  EXPECT_EQ(code, 0);
  std::vector<std::string> args = {"--slab", finished, "--out", expected};
  args.insert(args.end(), common.begin(), common.end());
  ASSERT_EQ(RunPreviewWith(args), 0);
  const ImageF last = ReadExr(out, {"R", "G", "B"});
  EXPECT_EQ(last.data, ReadExr(expected, {"R", "G", "B"}).data);
  EXPECT_GT(Sum(last), 1.2 * Sum(first)) << "the +x face adds the light beyond the +z cone";
}

TEST(PreviewLuminaire, RefusalsNameTheirCause) {
  const std::string lum = LuminaireFolder("refusals", {0, 1});
  const std::string out = Scratch("refused.exr");
  for (const std::vector<std::string>& extra : {std::vector<std::string>{"--merge-group", "2"},
                                                {"--shadow-share", "1"},
                                                {"--reference"},
                                                {"--write-test-slab"}}) {
    std::vector<std::string> args = {"--slab", lum, "--scene", "plane", "--out", out};
    args.insert(args.end(), extra.begin(), extra.end());
    EXPECT_EQ(RunPreviewWith(args), 2) << extra[0];
  }
  // An orientation without its slab, without --watch.
  fs::remove_all(lum + "/o01/slab");
  EXPECT_EQ(RunPreviewWith({"--slab", lum, "--scene", "plane", "--out", out}), 2);
  // An orientation's slab of another layout.
  const std::string other = Scratch("other_layout");
  fs::remove_all(other);
  WriteTruthSlab(
      FullSphere().Turned(Eigen::Matrix3d::Identity(), {0, 0, -CentreDepth(FullSphere())}),
      DefaultSlabInfo(5, 5, 12, 48), other, 2);
  fs::copy(other, lum + "/o01/slab", fs::copy_options::recursive);
  EXPECT_EQ(RunPreviewWith({"--slab", lum, "--scene", "plane", "--out", out}), 2);
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace lumislab
