// The built-in scenes (size, closed rooms with inward walls, sane attributes) and scene files
// through Assimp.
#include "lib/lightfield/scenes.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

#include "core/error.h"

namespace lumislab {
namespace {

// Nearest hit of the ray o + t dir (t > 0) with the mesh: triangle index and distance.
std::optional<std::pair<size_t, double>> Cast(const Mesh& m, const Eigen::Vector3d& o,
                                              const Eigen::Vector3d& dir) {
  std::optional<std::pair<size_t, double>> best;
  for (size_t k = 0; k < m.triangles(); ++k) {  // Moller-Trumbore
    const Eigen::Vector3d a = m.positions[3 * k].cast<double>();
    const Eigen::Vector3d e1 = m.positions[3 * k + 1].cast<double>() - a;
    const Eigen::Vector3d e2 = m.positions[3 * k + 2].cast<double>() - a;
    const Eigen::Vector3d p = dir.cross(e2);
    const double det = e1.dot(p);
    if (std::abs(det) < 1e-12) continue;
    const Eigen::Vector3d s = o - a;
    const double u = s.dot(p) / det;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = dir.dot(q) / det;
    const double t = e2.dot(q) / det;
    if (u < 0 || v < 0 || u + v > 1 || t <= 1e-6) continue;
    if (!best || t < best->second) best = {{k, t}};
  }
  return best;
}

// Rays from `inside` in a spread of directions: every one hits a surface, and the first surface
// hit faces the origin (a closed room, walls facing in, no hole; solids in it facing out).
void ExpectClosedFromInside(const Mesh& m, const Eigen::Vector3d& inside, int rays) {
  int misses = 0, backfacing = 0;
  for (int k = 0; k < rays; ++k) {  // Fibonacci sphere
    const double z = 1 - 2 * (k + 0.5) / rays, r = std::sqrt(1 - z * z);
    const double phi = k * M_PI * (3 - std::sqrt(5.0));
    const Eigen::Vector3d dir(r * std::cos(phi), z, r * std::sin(phi));
    const auto hit = Cast(m, inside, dir);
    if (!hit) {
      ++misses;
      continue;
    }
    backfacing += m.normals[3 * hit->first].cast<double>().dot(dir) >= 0;
  }
  EXPECT_EQ(misses, 0);
  EXPECT_EQ(backfacing, 0);
}

void ExpectSaneAttributes(const Mesh& m) {
  ASSERT_EQ(m.positions.size() % 3, 0u);
  ASSERT_EQ(m.normals.size(), m.positions.size());
  ASSERT_EQ(m.albedo.size(), m.positions.size());
  for (size_t k = 0; k < m.positions.size(); ++k) {
    EXPECT_NEAR(m.normals[k].norm(), 1, 1e-5);
    EXPECT_GE(m.albedo[k].minCoeff(), 0);
    EXPECT_LE(m.albedo[k].maxCoeff(), 1);
  }
}

TEST(LightFieldScenes, CryptIsAClosedRoomOfAboutFiveHundredTriangles) {
  const Mesh crypt = MakeCrypt();
  EXPECT_GE(crypt.triangles(), 400u);
  EXPECT_LE(crypt.triangles(), 600u);
  ExpectSaneAttributes(crypt);
  // From the luminaire, the preview's camera, a corner of the room, between pillar and wall,
  // under an arch and above one: the room has no hole, and pillars and arches are solids whose
  // faces all point out (the camera passes cull back faces: an inverted face would vanish).
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(250, 2300, -150), Eigen::Vector3d(1763, 2901, 2517),
        Eigen::Vector3d(2700, 300, 2700), Eigen::Vector3d(-2000, 1000, 0),
        Eigen::Vector3d(0, 1000, -1200), Eigen::Vector3d(0, 2800, -1200)}) {
    ExpectClosedFromInside(crypt, p, 400);
  }
}

TEST(LightFieldScenes, CloisterIsAClosedRoomOfAboutEightThousandTriangles) {
  const Mesh cloister = MakeCloister();
  EXPECT_GE(cloister.triangles(), 7000u);
  EXPECT_LE(cloister.triangles(), 9000u);
  ExpectSaneAttributes(cloister);
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(900, 3700, 900), Eigen::Vector3d(7500, 500, -7500)}) {
    ExpectClosedFromInside(cloister, p, 200);
  }
}

TEST(LightFieldScenes, PillarsCastShadowsOnTheCryptFloor) {
  // Straight down from the luminaire's height onto a pillar's top: blocked above the floor.
  const Mesh crypt = MakeCrypt();
  const auto onto_pillar = Cast(crypt, {1200, 2300, 1200}, {0, -1, 0});
  ASSERT_TRUE(onto_pillar);
  EXPECT_GT(2300 - onto_pillar->second, 1000);  // hits something at pillar height, not the floor
  const auto onto_floor = Cast(crypt, {2500, 2300, 0}, {0, -1, 0});
  ASSERT_TRUE(onto_floor);
  EXPECT_NEAR(onto_floor->second, 2300, 1e-3);  // open floor there
}

TEST(LightFieldScenes, ReceiverPlaneFacesTheLuminaire) {
  const Mesh plane = MakeReceiverPlane(1500, 3000);
  ASSERT_EQ(plane.triangles(), 2u);
  ExpectSaneAttributes(plane);
  for (size_t k = 0; k < 6; ++k) {
    EXPECT_EQ(plane.positions[k].z(), 1500);
    EXPECT_EQ(plane.positions[k].cwiseAbs().head<2>().maxCoeff(), 1500);
    EXPECT_NEAR(plane.normals[k].z(), -1, 1e-6);
  }
}

class LightFieldSceneFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("lumislab_lightfield_scenes_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  // BadInput whose message names `path`.
  static void ExpectBadInputNaming(const std::string& path) {
    try {
      LoadSceneFile(path);
      ADD_FAILURE() << path << " loaded";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::kBadInput) << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
  std::filesystem::path dir_;
};

TEST_F(LightFieldSceneFiles, LoadsAnObjFile) {
  const Mesh m = LoadSceneFile(Write("quad.obj",
                                     "v 0 0 0\nv 1000 0 0\nv 1000 0 1000\nv 0 0 1000\n"
                                     "f 1 4 3 2\n"));
  ASSERT_EQ(m.triangles(), 2u);  // the quad, triangulated
  ExpectSaneAttributes(m);
  for (const Eigen::Vector3f& n : m.normals) EXPECT_NEAR(n.y(), 1, 1e-5);  // 1-4-3-2 faces +y
}

TEST_F(LightFieldSceneFiles, RefusesMissingAndNonMeshFilesNamingThem) {
  ExpectBadInputNaming((dir_ / "missing.obj").string());
  ExpectBadInputNaming(Write("notes.txt", "this is not a scene\n"));
  ExpectBadInputNaming(Write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"));  // no faces
}

// A face naming a vertex the file does not have once corrupted memory in the renderer.
TEST_F(LightFieldSceneFiles, RefusesAFaceIndexOutOfRange) {
  ExpectBadInputNaming(Write("bad_index.ply",
                             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                             "property float y\nproperty float z\nelement face 1\n"
                             "property list uchar int vertex_indices\nend_header\n"
                             "0 0 0\n1 0 0\n0 1 0\n3 0 1 99999\n"));
  ExpectBadInputNaming(Write("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n"));
}

// Assimp 5.2 loops forever on a PLY cut short: the pre-check refuses it at once, naming the part.
TEST_F(LightFieldSceneFiles, RefusesAPlyCutShortAtOnce) {
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const std::string cases[][2] = {
      {"no_end.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"},
      {"short_body.ply", header + std::string(20, '\0')},  // 3 * 12 + 1 bytes needed
      {"ascii_short.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n0 0 0\n1 0 0\n"},
      {"bad_type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty vec3 p\nend_header\n"},
      {"no_vertex.ply", "ply\nformat ascii 1.0\nelement face 0\nend_header\n"}};
  for (const auto& [name, text] : cases) {
    const auto start = std::chrono::steady_clock::now();
    ExpectBadInputNaming(Write(name, text));
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10)
        << name << " was not refused before the import";
  }
}

// The import runs in a child with a time limit: past it the child is killed and the error names
// the file (a limit of 0 s is always past). A FIFO is refused before anything opens it.
TEST_F(LightFieldSceneFiles, TimeLimitAndFifo) {
  const std::string quad = Write("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 4 3 2\n");
  try {
    LoadSceneFile(quad, 0.0);
    ADD_FAILURE() << "loaded within 0 s";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kBadInput);
    EXPECT_NE(std::string(e.what()).find(quad + ": reading the scene took longer than"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(LoadSceneFile(quad).triangles(), 2u);  // and within the default limit it loads
  const std::string fifo = (dir_ / "scene.obj").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  ExpectBadInputNaming(fifo);
}

}  // namespace
}  // namespace lumislab
