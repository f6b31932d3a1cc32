#include "lib/synthetic/effects.h"

#include <cmath>
#include <random>
#include <vector>

#include "core/error.h"

namespace lumislab {
namespace {

// Rejects parameters the effect does not know (a typo must not silently fall back to a default).
void CheckKeys(const JsonView& spec, const std::vector<std::string>& allowed) {
  for (const std::string& key : spec.Keys()) {
    bool ok = key == "type";
    for (const auto& a : allowed) ok = ok || key == a;
    if (!ok) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw InputError(spec.file(), spec.path() + "." + key,
                       "a parameter of " + spec["type"].String() + " (" + list + ")",
                       "unknown parameter");
    }
  }
}

std::shared_ptr<const Effect> MakeSensorNoise(const JsonView& spec) {
  CheckKeys(spec, {"full_well_e", "read_noise_e", "seed"});
  const double full_well = spec.Has("full_well_e") ? spec["full_well_e"].NumberIn(1, 1e9) : 20000;
  const double read_noise = spec.Has("read_noise_e") ? spec["read_noise_e"].NumberIn(0, 1e9) : 3.0;
  const int seed = spec.Has("seed") ? spec["seed"].IntAtLeast(0) : 0;
  return std::make_shared<SensorNoiseEffect>(full_well, read_noise, seed);
}

std::shared_ptr<const Effect> MakeQuantization(const JsonView& spec) {
  CheckKeys(spec, {"bit_depth"});
  const int bits = spec.Has("bit_depth") ? spec["bit_depth"].IntIn(8, 16) : 16;
  return std::make_shared<QuantizationEffect>(bits);
}

}  // namespace

void SensorNoiseEffect::Apply(ImageF& rgb, const PhotoContext& context) const {
  // splitmix-style mixing so that neighbouring photo indices get unrelated streams.
  std::seed_seq seq{static_cast<unsigned>(seed_), static_cast<unsigned>(seed_ >> 32),
                    static_cast<unsigned>(context.photo_index), 0x6c756d69u};
  std::mt19937_64 rng(seq);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double read_var = read_noise_e_ * read_noise_e_;
  for (float& v : rgb.data) {
    const double electrons = std::max(0.0, double(v) * full_well_e_);
    const double sigma = std::sqrt(electrons + read_var);
    v = float(v + sigma * normal(rng) / full_well_e_);
  }
}

void QuantizationEffect::Apply(ImageF& rgb, const PhotoContext&) const {
  const double levels = double((1 << bit_depth_) - 1);
  for (float& value : rgb.data) {
    const double v = std::min(1.0, std::max(0.0, double(value)));
    // Level k of the bit depth, stored as the 16-bit code of the PNG (k * 65535 / levels,
    // rounded) so that writing round(v * 65535) gives exactly that code.
    value = float(std::round(std::round(v * levels) * 65535 / levels) / 65535);
  }
}

const std::map<std::string, EffectFactory>& EffectRegistry() {
  static const std::map<std::string, EffectFactory> registry = {
      {"sensor_noise", &MakeSensorNoise},
      {"quantization", &MakeQuantization},
  };
  return registry;
}

std::shared_ptr<const Effect> MakeEffect(const JsonView& spec) {
  std::vector<std::string> types;
  for (const auto& entry : EffectRegistry()) types.push_back(entry.first);
  const std::string type = spec["type"].OneOf(types);
  return EffectRegistry().at(type)(spec);
}

}  // namespace lumislab
