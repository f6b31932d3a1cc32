// Scenes for the preview: triangle soups with per-vertex normal and Lambertian albedo, in the
// scene (world) frame, mm. Built-in crypt (~500 triangles) and cloister (~8000 triangles): closed
// vaulted rooms with columns and arches that cast shadows, like the paper's test scenes
// (docs/method.md §4.4; built from lib/lightfield/scene_parts.h); files via Assimp.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace lumislab {

struct Mesh {
  std::vector<Eigen::Vector3f> positions;  // 3 per triangle
  std::vector<Eigen::Vector3f> normals;
  std::vector<Eigen::Vector3f> albedo;
  size_t triangles() const { return positions.size() / 3; }
  void AddTriangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                   const Eigen::Vector3f& colour);
  // Quad a-b-c-d (counter-clockwise seen from the side its normal points to).
  void AddQuad(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
               const Eigen::Vector3f& d, const Eigen::Vector3f& colour);
  void Append(const Mesh& other);
};

// Closed rooms, floor y = 0, y up, every surface facing the inside (solids in them facing out).
// The crypt: 6.6 m square, 3 x 3 groin-vaulted bays on four columns (546 triangles).
Mesh MakeCrypt();
// The cloister: a 10 m garth with a well, four arcades, vaulted galleries, roofs, outer walls
// and a dark sky at 7 m; 16.8 m square (7932 triangles).
Mesh MakeCloister();
// The receiver plane z = plane_z of the luminaire frame, square of side extent, normal -z.
Mesh MakeReceiverPlane(double plane_z_mm, double extent_mm);
// OBJ / glTF / PLY / ... through Assimp, in a child process (lib/lightfield/scene_file.cc): the
// flattened triangles, albedo the material's diffuse colour times its diffuse texture at each
// corner (lib/lightfield/scene_texture.h; a missing texture is a warning). BadInput naming the file
// when it is not a regular file, the importer refuses it, crashes on it or runs past `timeout_s`
// (then it is killed), or the scene has no triangles, a non-finite vertex, a face naming a missing
// vertex or more than kMaxSceneTriangles triangles; Failure when StopRequested() ends the wait.
constexpr size_t kMaxSceneTriangles = 10'000'000;
constexpr double kSceneImportTimeoutS = 120;
Mesh LoadSceneFile(const std::string& path, double timeout_s = kSceneImportTimeoutS);

}  // namespace lumislab
