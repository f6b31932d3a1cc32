// The built-in scenes (size, closed rooms with inward walls, sane attributes) and scene files
// through Assimp.
#include "lib/lightfield/scenes.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <vector>

#include "core/error.h"
#include "lib/lightfield/scene_setup.h"

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

// The geometric normal of triangle t (the shading normals of curved parts are interpolated).
Eigen::Vector3d FaceNormal(const Mesh& m, size_t t) {
  const Eigen::Vector3d a = m.positions[3 * t].cast<double>();
  return (m.positions[3 * t + 1].cast<double>() - a)
      .cross(m.positions[3 * t + 2].cast<double>() - a)
      .normalized();
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
    backfacing += FaceNormal(m, hit->first).dot(dir) >= 0;
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

void ExpectBounds(const Mesh& m, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  Eigen::Vector3f min = m.positions[0], max = min;
  for (const Eigen::Vector3f& p : m.positions) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  EXPECT_TRUE(min.isApprox(lo)) << min.transpose();
  EXPECT_TRUE(max.isApprox(hi)) << max.transpose();
}

// The ceiling's triangles (facing down, every corner between spring and crown and outside
// `inner` of the axes in x or z) are a surface without holes: each edge is shared by exactly
// two of them unless it lies in one of the walls `walls` (|x| or |z| equal to one of them,
// the other coordinate within it) that the vault rests on.
void ExpectVaultWithoutGaps(const Mesh& m, float spring, float crown, float inner,
                            const std::vector<float>& walls) {
  using Key = std::array<float, 6>;
  std::map<Key, int> edges;
  size_t vault = 0;
  for (size_t t = 0; t < m.triangles(); ++t) {
    const Eigen::Vector3f* p = &m.positions[3 * t];
    bool in = FaceNormal(m, t).y() < -1e-3;
    for (int c = 0; c < 3; ++c) {
      in = in && p[c].y() >= spring && p[c].y() <= crown &&
           std::max(std::abs(p[c].x()), std::abs(p[c].z())) >= inner;
    }
    if (!in) continue;
    ++vault;
    for (int c = 0; c < 3; ++c) {
      Eigen::Vector3f a = p[c], b = p[(c + 1) % 3];
      if (std::lexicographical_compare(b.data(), b.data() + 3, a.data(), a.data() + 3))
        std::swap(a, b);
      ++edges[{a.x(), a.y(), a.z(), b.x(), b.y(), b.z()}];
    }
  }
  EXPECT_GT(vault, 100u);
  auto on_wall = [&](const Key& e) {
    for (const float w : walls) {
      for (int axis : {0, 2}) {
        const int other = 2 - axis;
        if (std::abs(e[axis]) == w && std::abs(e[axis + 3]) == w && e[axis] == e[axis + 3] &&
            std::abs(e[other]) <= w && std::abs(e[other + 3]) <= w)
          return true;
      }
    }
    return false;
  };
  int open = 0, overused = 0;
  for (const auto& [edge, count] : edges) {
    open += count == 1 && !on_wall(edge);
    overused += count > 2;
  }
  EXPECT_EQ(open, 0);
  EXPECT_EQ(overused, 0);
}

TEST(LightFieldScenes, CryptIsAClosedVaultedRoomOfAboutFiveHundredTriangles) {
  const Mesh crypt = MakeCrypt();
  EXPECT_GE(crypt.triangles(), 450u);
  EXPECT_LE(crypt.triangles(), 600u);
  ExpectSaneAttributes(crypt);
  ExpectBounds(crypt, {-3300, 0, -3300}, {3300, 2900, 3300});
  // From the luminaire, the camera, a corner of the room, under the vault's crown, beside a
  // column's abacus, at a wall's springing and above the altar: the room has no hole, and the
  // columns and the altar are solids whose faces all point out (the camera passes cull back
  // faces: an inverted face would vanish).
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(-400, 1500, -700), Eigen::Vector3d(2637, 1619, 2011),
        Eigen::Vector3d(3200, 100, 3200), Eigen::Vector3d(0, 2750, 0),
        Eigen::Vector3d(-1100, 1950, -800), Eigen::Vector3d(-3250, 1950, -1100),
        Eigen::Vector3d(3000, 1100, 0)}) {
    ExpectClosedFromInside(crypt, p, 600);
  }
  // The nine groin vaults meet each other without a gap and end on the walls.
  ExpectVaultWithoutGaps(crypt, 1900, 2800, 0, {3300});
}

TEST(LightFieldScenes, CloisterIsAClosedCourtyardOfAboutEightThousandTriangles) {
  const Mesh cloister = MakeCloister();
  EXPECT_GE(cloister.triangles(), 7000u);
  EXPECT_LE(cloister.triangles(), 9000u);
  ExpectSaneAttributes(cloister);
  ExpectBounds(cloister, {-8400, 0, -8400}, {8400, 7000, 8400});
  // From the luminaire, the camera, the garth under the sky, a gallery's corner bay, under an
  // arch, inside the arcade's opening next to a corner pier and just under the sky.
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(300, 1500, 4200), Eigen::Vector3d(-2520, 1718, 490),
        Eigen::Vector3d(0, 2000, 0), Eigen::Vector3d(7000, 1500, 7000),
        Eigen::Vector3d(5200, 2500, 0), Eigen::Vector3d(5200, 1000, 4900),
        Eigen::Vector3d(0, 6900, 0)}) {
    ExpectClosedFromInside(cloister, p, 300);
  }
  // The 24 gallery vaults (four of them turned copies) meet without a gap and end on the
  // arcade (|x| or |z| = 5400) and on the outer walls (8400).
  ExpectVaultWithoutGaps(cloister, 2200, 3300, 5400, {5400, 8400});
}

// The default views: the camera stands in the room and sees floor, walls and ceiling (vault or
// sky) at once; the luminaire stands in the room with columns inside the window's cone, between
// it and the surfaces most of the cone lands on (soft shadows at first sight).
TEST(LightFieldScenes, DefaultViewsShowFloorWallsCeilingAndColumnsInTheLight) {
  SlabInfo info;
  info.distance_mm = 750;
  info.grid = {9, 7, 5};
  info.layout = {1200, 1200, 300, 300};
  struct Room {
    const char* name;
    float spring, outer;  // columns stand below `spring`, the outer walls at |x| or |z| = outer
  };
  for (const Room& room : {Room{"crypt", 1900, 3300}, Room{"cloister", 2200, 8400}}) {
    const char* name = room.name;
    const SceneSetup s = MakeSceneSetup(name, info);
    const Eigen::Matrix4d scene_from_clip = OrbitCamera(s, 4.0 / 3).cast<double>().inverse();
    auto unproject = [&](double x, double y, double z) {
      const Eigen::Vector4d p = scene_from_clip * Eigen::Vector4d(x, y, z, 1);
      return Eigen::Vector3d(p.head<3>() / p.w());
    };
    int floor = 0, wall = 0, ceiling = 0, misses = 0, rays = 0;
    for (int row = 0; row < 12; ++row) {
      for (int col = 0; col < 16; ++col, ++rays) {
        const double x = (col + 0.5) / 8 - 1, y = 1 - (row + 0.5) / 6;
        const Eigen::Vector3d eye = unproject(x, y, -1);
        const auto hit = Cast(s.mesh, eye, unproject(x, y, 1) - eye);
        if (!hit) {
          ++misses;
          continue;
        }
        const double ny = FaceNormal(s.mesh, hit->first).y();
        floor += ny > 0.9;
        ceiling += ny < -0.3;
        wall += std::abs(ny) < 0.3;
      }
    }
    EXPECT_EQ(misses, 0) << name;
    EXPECT_GE(floor, rays / 10) << name;
    EXPECT_GE(wall, rays / 10) << name;
    EXPECT_GE(ceiling, rays / 20) << name;
    int occluded = 0, far = 0, cone = 0;
    for (int j = 0; j < 9; ++j) {
      for (int i = 0; i < 9; ++i, ++cone) {
        const Eigen::Vector3d through(-600 + 150 * i, -600 + 150 * j, 750);  // the window at d
        const auto hit = Cast(s.mesh, s.pose.translation(), s.pose.linear() * through.normalized());
        ASSERT_TRUE(hit) << name;
        // A column (or a pier, the altar, the well): above the floor, below the vaults, inside
        // the outer walls.
        const Eigen::Vector3d at =
            s.pose.translation() + hit->second * (s.pose.linear() * through.normalized());
        occluded += at.y() > 1 && at.y() < room.spring &&
                    std::max(std::abs(at.x()), std::abs(at.z())) < room.outer - 1;
        far += hit->second > 3000;
      }
    }
    EXPECT_GE(occluded, cone / 20) << name;
    EXPECT_GE(far, cone / 3) << name;
    std::printf(
        "%s: view floor %d wall %d ceiling %d of %d; cone on columns %d, beyond 3 m %d of %d\n",
        name, floor, wall, ceiling, rays, occluded, far, cone);
  }
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

// A material's diffuse texture (OBJ map_Kd, here a 2 x 1 PPM) multiplies its colour Kd at each
// corner's texture coordinate, linearised through the sRGB curve; a texture that is not there
// leaves the colour alone.
TEST_F(LightFieldSceneFiles, DiffuseTexturesColourTheVertices) {
  Write("tex.ppm", std::string("P6\n2 1\n255\n") + std::string("\xff\x00\x80\x00\xff\x40", 6));
  Write("quad.mtl",
        "newmtl textured\nKd 1 0.5 1\nmap_Kd tex.ppm\n"
        "newmtl missing\nKd 0.2 0.3 0.4\nmap_Kd nowhere.ppm\n");
  const std::string quad =
      "v 0 0 0\nv 1000 0 0\nv 1000 0 1000\nv 0 0 1000\n"
      "vt 0.25 0.5\nvt 0.75 0.5\nvt 0.75 0.5\nvt 0.25 0.5\n";
  const Mesh textured = LoadSceneFile(
      Write("textured.obj", "mtllib quad.mtl\n" + quad + "usemtl textured\nf 1/1 4/4 3/3 2/2\n"));
  ASSERT_EQ(textured.triangles(), 2u);
  auto linear = [](double code) {  // the sRGB curve's inverse
    const double v = code / 255;
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
  };
  for (size_t k = 0; k < textured.positions.size(); ++k) {
    // u = 0.25 is the left texel's centre (x = 0 here), u = 0.75 the right one's.
    const Eigen::Vector3d expected = textured.positions[k].x() == 0
                                         ? Eigen::Vector3d(1, 0, linear(128))
                                         : Eigen::Vector3d(0, 0.5, linear(64));
    EXPECT_TRUE(textured.albedo[k].cast<double>().isApprox(expected, 1e-5))
        << textured.albedo[k].transpose() << " at " << textured.positions[k].transpose();
  }
  testing::internal::CaptureStderr();
  const Mesh missing = LoadSceneFile(
      Write("missing.obj", "mtllib quad.mtl\n" + quad + "usemtl missing\nf 1/1 4/4 3/3 2/2\n"));
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("nowhere.ppm"), std::string::npos) << err;
  for (const Eigen::Vector3f& a : missing.albedo)
    EXPECT_TRUE(a.isApprox(Eigen::Vector3f(0.2f, 0.3f, 0.4f)));
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
