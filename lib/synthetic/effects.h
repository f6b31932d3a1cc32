// Camera effects of the synthetic capture (docs/design.md §8): each is one small step applied to a
// rendered photo, in the order the scene lists them. Only listed effects are computed.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "core/image.h"
#include "core/json.h"

namespace lumislab {

struct PhotoContext {
  int photo_index = 0;  // index in dataset.json's photo list (seeds the noise per photo)
};

class Effect {
 public:
  virtual ~Effect() = default;
  virtual std::string Type() const = 0;
  // Changes `rgb` (3 channels, normalised linear values, RGB order) in place.
  virtual void Apply(ImageF& rgb, const PhotoContext& context) const = 0;
  // True when the photo holds code values / 65535 afterwards and is stored as a 16-bit PNG.
  virtual bool Quantizes() const { return false; }
};

// Shot noise (Gaussian with variance = electrons, electrons = v full_well) plus Gaussian read
// noise, in electrons; deterministic for a seed (the RNG of photo k is seeded from seed + k).
class SensorNoiseEffect : public Effect {
 public:
  SensorNoiseEffect(double full_well_e, double read_noise_e, unsigned long long seed)
      : full_well_e_(full_well_e), read_noise_e_(read_noise_e), seed_(seed) {}
  std::string Type() const override { return "sensor_noise"; }
  void Apply(ImageF& rgb, const PhotoContext& context) const override;

 private:
  double full_well_e_, read_noise_e_;
  unsigned long long seed_;
};

// Clips to [0, 1] (saturation at full scale) and rounds to 2^bit_depth - 1 levels, expressed as
// 16-bit codes / 65535; the photo is then written as a 16-bit linear PNG.
class QuantizationEffect : public Effect {
 public:
  explicit QuantizationEffect(int bit_depth) : bit_depth_(bit_depth) {}
  std::string Type() const override { return "quantization"; }
  bool Quantizes() const override { return true; }
  void Apply(ImageF& rgb, const PhotoContext& context) const override;

 private:
  int bit_depth_;
};

// Builds an effect from its JSON object {"type": ..., params}; `spec` is effects[k] of a scene
// file. Unknown types and bad or unknown parameters throw InputError naming the field.
using EffectFactory = std::shared_ptr<const Effect> (*)(const JsonView& spec);
const std::map<std::string, EffectFactory>& EffectRegistry();
std::shared_ptr<const Effect> MakeEffect(const JsonView& spec);

}  // namespace lumislab
