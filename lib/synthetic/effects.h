// Camera effects of the synthetic capture (docs/testing.md §1): each is one small step applied
// to a rendered photo, in the order the scene lists them. Only listed effects are computed.
#pragma once

#include <Eigen/Core>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/json.h"
#include "lib/synthetic/camera.h"

namespace lumislab {

// What a photo's effects know about it beyond its pixels.
struct PhotoContext {
  int photo_index = 0;  // index in dataset.json's photo list (seeds the noise per photo)
  // The photo's relative exposure (camera.exposure x 2^stop of a bracket), taken as its
  // exposure time in s by the dark current.
  double exposure = 1;
};

// The parts of a scene an effect may be built with (the effects come last in a scene file).
struct EffectSetting {
  CameraSpec camera;
  double distance_mm = 0;  // screen plane z = d, lab frame
  double screen_w_mm = 0;  // physical screen, centred on the optical axis
  double screen_h_mm = 0;
};

class Effect {
 public:
  virtual ~Effect() = default;
  virtual std::string Type() const = 0;
  // Changes `rgb` (3 channels, normalised linear values, RGB order) in place.
  virtual void Apply(ImageF& rgb, const PhotoContext& context) const = 0;
  // True when the photo holds code values / 65535 afterwards and is stored as a 16-bit PNG.
  virtual bool Quantizes() const { return false; }
  // Where the stage put the luminaire for grid position (i, j), relative to the nominal centre
  // (mm, lab frame); changes the render, not the photo (stage_error).
  virtual Eigen::Vector2d StageOffsetMm(int /*i*/, int /*j*/) const { return {0, 0}; }
};

// Shot noise (Gaussian with variance = electrons, electrons = v full_well) plus Gaussian read
// noise, in electrons; deterministic for a seed (photo k's mt19937_64 is seeded by a
// std::seed_seq of the seed's two 32-bit halves, k and a constant).
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

// Light fall-off of the lens: cos^4 of the angle off the camera axis (pinhole: tan = distance
// to the principal point / focal length) times 1 + k1 r^2 + k2 r^4, r = distance to the
// principal point / the principal point's distance to pixel (0, 0)'s centre.
class VignettingEffect : public Effect {
 public:
  VignettingEffect(const CameraSpec& camera, double k1, double k2, bool cos4);
  std::string Type() const override { return "vignetting"; }
  void Apply(ImageF& rgb, const PhotoContext& context) const override;
  double Factor(double px, double py) const;  // at pixel (px, py), OpenCV centres

 private:
  CameraSpec camera_;
  double cx_, cy_;  // the principal point, px (the image centre without a lens)
  double k1_, k2_;
  bool cos4_;
};

// A smooth, seeded non-uniformity of the screen's reflectance: 1 + amplitude times a weighted
// mean of `blobs` Gaussians (sigma `size_mm`, centres uniform over the screen, weights uniform in
// [-1, 1], divided by the sum of their magnitudes, so |gain - 1| <= amplitude). Defined in lab mm
// on the screen and applied to the pixels that see the screen.
class ScreenGainEffect : public Effect {
 public:
  ScreenGainEffect(const EffectSetting& setting, double amplitude, int blobs, double size_mm,
                   unsigned long long seed);
  std::string Type() const override { return "screen_gain"; }
  void Apply(ImageF& rgb, const PhotoContext& context) const override;
  double Gain(const Eigen::Vector2d& screen_mm) const;  // lab (x, y) on the screen

 private:
  EffectSetting setting_;
  double amplitude_, size_mm_;
  std::vector<Eigen::Vector2d> centres_mm_;
  std::vector<double> weights_;  // sum of magnitudes 1
};

// Stray light: a constant irradiance `level` (normalised value at exposure 1, i.e. level x the
// radiometric scale in W/m^2) on the screen, the same on both slides, so it cancels in E+ - E-.
class AmbientEffect : public Effect {
 public:
  AmbientEffect(const EffectSetting& setting, double level) : setting_(setting), level_(level) {}
  std::string Type() const override { return "ambient"; }
  void Apply(ImageF& rgb, const PhotoContext& context) const override;
  double level() const { return level_; }

 private:
  EffectSetting setting_;
  double level_;
};

// The sensor's dark signal, in normalised sensor units: a black level (code offset) plus dark
// current x exposure time; a seeded fraction of hot pixels (the same pixels in every photo) has
// `hot_current` instead.
class DarkEffect : public Effect {
 public:
  DarkEffect(double black_level, double dark_current, double hot_fraction, double hot_current,
             unsigned long long seed)
      : black_level_(black_level),
        dark_current_(dark_current),
        hot_fraction_(hot_fraction),
        hot_current_(hot_current),
        seed_(seed) {}
  std::string Type() const override { return "dark"; }
  void Apply(ImageF& rgb, const PhotoContext& context) const override;
  double black_level() const { return black_level_; }
  bool Hot(int pixel) const;  // pixel = y * width + x

 private:
  double black_level_, dark_current_, hot_fraction_, hot_current_;
  unsigned long long seed_;
};

// An exposure series per slide: every slide photo is taken once per stop, at camera.exposure x
// 2^stop (the capture scales the render before the effects). Its step clips values >= 1 to 1
// (saturation), wherever it is listed.
class BracketsEffect : public Effect {
 public:
  explicit BracketsEffect(std::vector<double> stops) : stops_(std::move(stops)) {}
  std::string Type() const override { return "brackets"; }
  void Apply(ImageF& rgb, const PhotoContext& context) const override;
  const std::vector<double>& stops() const { return stops_; }
  static std::string Tag(double stop);  // file name tag: "ev-2", "ev+0", "ev+1.5"

 private:
  std::vector<double> stops_;
};

// The camera's non-linear output curve, applied to values clipped to [0, 1] and rounded to 8-bit
// levels (code / 255); the photos are then written as JPEG at `quality`. Curves: "srgb", or
// "gamma": y = (x (1 + s) / (1 + s x))^(1 / gamma) with a highlight shoulder s >= 0 (s = 0: a
// plain power law).
class ResponseEffect : public Effect {
 public:
  ResponseEffect(std::string curve, double gamma, double shoulder, int quality)
      : curve_(std::move(curve)), gamma_(gamma), shoulder_(shoulder), quality_(quality) {}
  std::string Type() const override { return "response"; }
  void Apply(ImageF& rgb, const PhotoContext& context) const override;
  double Curve(double linear) const;  // [0, 1] -> [0, 1], before rounding
  double Inverse(double curve_value) const;
  const std::string& curve() const { return curve_; }
  double gamma() const { return gamma_; }
  double shoulder() const { return shoulder_; }
  int quality() const { return quality_; }

 private:
  std::string curve_;
  double gamma_, shoulder_;
  int quality_;
};

// The luminaire off its nominal grid position: per position a seeded offset uniform in
// [-max_mm, max_mm] on x and y (lab mm). Only the render moves; the truth stays nominal.
class StageErrorEffect : public Effect {
 public:
  StageErrorEffect(double max_mm, unsigned long long seed) : max_mm_(max_mm), seed_(seed) {}
  std::string Type() const override { return "stage_error"; }
  void Apply(ImageF&, const PhotoContext&) const override {}
  Eigen::Vector2d StageOffsetMm(int i, int j) const override;

 private:
  double max_mm_;
  unsigned long long seed_;
};

// The camera's raw sensor output: each value becomes the integer code black + v (white - black)
// of a `bit_depth`-bit sensor, clipped to [0, white] (white: saturation), and is kept as the
// value the decoder gives back, (code - black) / (white - black). The photos are then stored as
// an RGGB Bayer mosaic in a DNG (lib/photo/camera_write.h WriteDng), one channel per pixel.
class RawEffect : public Effect {
 public:
  RawEffect(int bit_depth, int black_level, int white_level)
      : bit_depth_(bit_depth), black_level_(black_level), white_level_(white_level) {}
  std::string Type() const override { return "raw"; }
  void Apply(ImageF& rgb, const PhotoContext& context) const override;
  int Code(float value) const;  // the sensor code of a value
  int bit_depth() const { return bit_depth_; }
  int black_level() const { return black_level_; }
  int white_level() const { return white_level_; }

 private:
  int bit_depth_, black_level_, white_level_;
};

// The camera's lens: OpenCV's Brown-Conrady distortion and a principal point off the image
// centre. It changes where each pixel looks, not a photo's values: the scene hands it to the
// camera (CameraSpec::lens), so it acts on every photo the camera takes (slide photos, the board
// photo, the calibration frames and views) wherever it is listed.
class LensEffect : public Effect {
 public:
  explicit LensEffect(const LensSpec& lens) : lens_(lens) {}
  std::string Type() const override { return "lens"; }
  void Apply(ImageF&, const PhotoContext&) const override {}
  const LensSpec& lens() const { return lens_; }

 private:
  LensSpec lens_;
};

// Builds an effect from its JSON object {"type": ..., params}; `spec` is effects[k] of a scene
// file. Unknown types and bad or unknown parameters throw InputError naming the field.
using EffectFactory = std::shared_ptr<const Effect> (*)(const JsonView& spec,
                                                        const EffectSetting& setting);
const std::map<std::string, EffectFactory>& EffectRegistry();
std::shared_ptr<const Effect> MakeEffect(const JsonView& spec, const EffectSetting& setting);

}  // namespace lumislab
