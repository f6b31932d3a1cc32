#include "lib/lightfield/scene_texture.h"

#include <stb_image.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/log.h"

namespace lumislab {
namespace {

// The sRGB curve's inverse for an 8-bit code (textures are stored sRGB-encoded).
float LinearFromSrgb(unsigned char code) {
  const double v = code / 255.0;
  return float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

DiffuseTexture FromPixels(const unsigned char* pixels, int width, int height) {
  DiffuseTexture t;
  t.width = width;
  t.height = height;
  t.rgb.resize(size_t(width) * height * 3);
  for (size_t k = 0; k < t.rgb.size(); ++k) t.rgb[k] = LinearFromSrgb(pixels[k]);
  return t;
}

// stb_image, 3 channels; empty when it cannot decode the bytes or the file.
DiffuseTexture Decode(const aiTexture* embedded, const std::string& file) {
  int width = 0, height = 0, channels = 0;
  unsigned char* pixels = nullptr;
  if (embedded != nullptr && embedded->mHeight > 0) {  // raw BGRA texels
    std::vector<unsigned char> rgb;
    for (size_t k = 0; k < size_t(embedded->mWidth) * embedded->mHeight; ++k) {
      const aiTexel& texel = embedded->pcData[k];
      rgb.insert(rgb.end(), {texel.r, texel.g, texel.b});
    }
    return FromPixels(rgb.data(), int(embedded->mWidth), int(embedded->mHeight));
  }
  if (embedded != nullptr) {  // compressed (PNG, JPEG, ...): mWidth bytes
    pixels = stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(embedded->pcData),
                                   int(embedded->mWidth), &width, &height, &channels, 3);
  } else {
    pixels = stbi_load(file.c_str(), &width, &height, &channels, 3);
  }
  if (pixels == nullptr) return {};
  DiffuseTexture t = FromPixels(pixels, width, height);
  stbi_image_free(pixels);
  return t;
}

}  // namespace

Eigen::Vector3f DiffuseTexture::Sample(float u, float v) const {
  if (empty() || !std::isfinite(u) || !std::isfinite(v)) return {1, 1, 1};
  // Texel centres at (i + 0.5) / width; row 0 is v = 1.
  const double x = (u - std::floor(u)) * width - 0.5;
  const double y = (1.0 - (v - std::floor(v))) * height - 0.5;
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  const float fx = float(x - x0), fy = float(y - y0);
  auto texel = [&](int i, int j) {
    i = ((i % width) + width) % width;
    j = ((j % height) + height) % height;
    const float* p = &rgb[(size_t(j) * width + i) * 3];
    return Eigen::Vector3f(p[0], p[1], p[2]);
  };
  return (1 - fy) * ((1 - fx) * texel(x0, y0) + fx * texel(x0 + 1, y0)) +
         fy * ((1 - fx) * texel(x0, y0 + 1) + fx * texel(x0 + 1, y0 + 1));
}

DiffuseTexture LoadDiffuseTexture(const aiScene& scene, const aiMaterial& material,
                                  const std::string& scene_path) {
  aiString name;
  if (material.GetTextureCount(aiTextureType_DIFFUSE) == 0 ||
      material.GetTexture(aiTextureType_DIFFUSE, 0, &name) != AI_SUCCESS || name.length == 0) {
    return {};
  }
  const aiTexture* embedded = scene.GetEmbeddedTexture(name.C_Str());
  const std::string file =
      (std::filesystem::path(scene_path).parent_path() / name.C_Str()).lexically_normal().string();
  DiffuseTexture t = Decode(embedded, file);
  if (t.empty()) {
    LogWarning(scene_path, ": cannot read the diffuse texture ",
               embedded != nullptr ? std::string(name.C_Str()) + " (embedded)" : file,
               "; the material keeps its diffuse colour");
  }
  return t;
}

}  // namespace lumislab
