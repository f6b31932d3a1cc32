// Scenes for the preview: triangle soups with per-vertex normal and Lambertian albedo, in the
// scene (world) frame, mm. Built-in crypt (~500 triangles) and cloister (~8000 triangles): rooms
// with pillars and arches that cast shadows, like the paper's test scenes; files via Assimp.
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
  // Axis-aligned box, faces pointing out.
  void AddBox(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, const Eigen::Vector3f& colour);
  void Append(const Mesh& other);
};

// A room (floor y = 0, walls facing in, ceiling), y up. Luminaire hangs near the ceiling.
Mesh MakeCrypt();     // ~500 triangles
Mesh MakeCloister();  // ~8000 triangles
// The receiver plane z = plane_z of the luminaire frame, square of side extent, normal -z.
Mesh MakeReceiverPlane(double plane_z_mm, double extent_mm);
// OBJ / glTF / PLY / ... through Assimp; BadInput when it cannot be read.
Mesh LoadSceneFile(const std::string& path);

}  // namespace lumislab
