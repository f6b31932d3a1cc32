// Diffuse textures of scene files (lib/lightfield/scene_file.cc, in the import's child process):
// the material's first diffuse texture, embedded in the file or beside it, decoded by stb_image
// and linearised through the sRGB curve, then sampled at each triangle corner's texture
// coordinate: the preview's albedo is per vertex (docs/method.md §4.4), so a texture gives the
// mesh its colours at the vertices, not finer detail.
#pragma once

#include <assimp/material.h>
#include <assimp/scene.h>

#include <Eigen/Core>
#include <string>
#include <vector>

namespace lumislab {

struct DiffuseTexture {
  int width = 0, height = 0;
  std::vector<float> rgb;  // linear, row 0 at the top (v = 1)
  bool empty() const { return rgb.empty(); }
  // Bilinear, repeating outside [0, 1) (texture coordinates of tiled materials), v up.
  Eigen::Vector3f Sample(float u, float v) const;
};

// The diffuse texture of `material` (empty when it has none). A texture named but missing or
// unreadable is a warning naming it and the scene file, and the material keeps its colour.
DiffuseTexture LoadDiffuseTexture(const aiScene& scene, const aiMaterial& material,
                                  const std::string& scene_path);

}  // namespace lumislab
