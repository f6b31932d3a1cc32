#include "lib/synthetic/effects.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
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

double NumberOr(const JsonView& spec, const char* key, double lo, double hi, double fallback) {
  return spec.Has(key) ? spec[key].NumberIn(lo, hi) : fallback;
}
unsigned long long SeedOf(const JsonView& spec) {
  return spec.Has("seed") ? (unsigned long long)spec["seed"].IntAtLeast(0) : 0;
}

// splitmix64: a stateless, well-mixed hash, so that a pixel's or a grid position's draw does not
// depend on the order (or the thread) in which photos are made.
unsigned long long Mix(unsigned long long x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}
// Uniform in [0, 1) from a seed and up to three integers.
double Uniform(unsigned long long seed, unsigned long long a, unsigned long long b = 0,
               unsigned long long c = 0) {
  const unsigned long long h = Mix(Mix(Mix(Mix(seed) ^ a) ^ b) ^ c);
  return double(h >> 11) * 0x1.0p-53;
}

// Calls f(pixel, lab_mm) for every pixel of a width x height photo of `setting`'s camera whose
// centre sees the physical screen (as ScreenView does).
template <typename F>
void ForEachScreenPixel(const EffectSetting& setting, int width, int height, F&& f) {
  const PinholeCamera camera(setting.camera);
  const double half_w = 0.5 * setting.screen_w_mm, half_h = 0.5 * setting.screen_h_mm;
  Eigen::Vector2d xy;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      if (camera.PlanePoint(x, y, setting.distance_mm, &xy) && std::abs(xy.x()) <= half_w &&
          std::abs(xy.y()) <= half_h)
        f(size_t(y) * width + x, xy);
}

std::shared_ptr<const Effect> MakeSensorNoise(const JsonView& spec, const EffectSetting&) {
  CheckKeys(spec, {"full_well_e", "read_noise_e", "seed"});
  const double full_well = NumberOr(spec, "full_well_e", 1, 1e9, 20000);
  const double read_noise = NumberOr(spec, "read_noise_e", 0, 1e9, 3.0);
  return std::make_shared<SensorNoiseEffect>(full_well, read_noise, SeedOf(spec));
}

std::shared_ptr<const Effect> MakeQuantization(const JsonView& spec, const EffectSetting&) {
  CheckKeys(spec, {"bit_depth"});
  const int bits = spec.Has("bit_depth") ? spec["bit_depth"].IntIn(8, 16) : 16;
  return std::make_shared<QuantizationEffect>(bits);
}

std::shared_ptr<const Effect> MakeVignetting(const JsonView& spec, const EffectSetting& setting) {
  CheckKeys(spec, {"k1", "k2", "cos4"});
  const double k1 = NumberOr(spec, "k1", -1, 1, 0), k2 = NumberOr(spec, "k2", -1, 1, 0);
  // The polynomial must stay > 0 out to the corners (t = r^2 in [0, 1]): at t = 1 and at its
  // extremum inside (0, 1).
  double lowest = std::min(1.0, 1 + k1 + k2);
  if (k2 != 0 && -k1 / (2 * k2) > 0 && -k1 / (2 * k2) < 1)
    lowest = std::min(lowest, 1 - k1 * k1 / (4 * k2));
  if (!(lowest > 0.01))
    spec[spec.Has("k2") ? "k2" : "k1"].Fail(
        "k1, k2 with 1 + k1 r^2 + k2 r^4 > 0.01 for r in [0, 1]");
  const bool cos4 = spec.Has("cos4") ? spec["cos4"].Bool() : true;
  return std::make_shared<VignettingEffect>(setting.camera, k1, k2, cos4);
}

std::shared_ptr<const Effect> MakeScreenGain(const JsonView& spec, const EffectSetting& setting) {
  CheckKeys(spec, {"amplitude", "blobs", "size_mm", "seed"});
  const double amplitude = NumberOr(spec, "amplitude", 0, 0.15, 0.05);
  const int blobs = spec.Has("blobs") ? spec["blobs"].IntIn(1, 16) : 4;
  const double size_mm = NumberOr(spec, "size_mm", 1, 1e5, 300);
  return std::make_shared<ScreenGainEffect>(setting, amplitude, blobs, size_mm, SeedOf(spec));
}

std::shared_ptr<const Effect> MakeAmbient(const JsonView& spec, const EffectSetting& setting) {
  CheckKeys(spec, {"level"});
  return std::make_shared<AmbientEffect>(setting, NumberOr(spec, "level", 0, 1, 0.02));
}

std::shared_ptr<const Effect> MakeDark(const JsonView& spec, const EffectSetting&) {
  CheckKeys(spec, {"black_level", "dark_current", "hot_fraction", "hot_current", "seed"});
  // black_level within dataset.json's radiometry.black_level range, where it is recorded.
  const double black = NumberOr(spec, "black_level", 0, 0.5, 0.01);
  const double current = NumberOr(spec, "dark_current", 0, 1, 0);
  const double hot_fraction = NumberOr(spec, "hot_fraction", 0, 0.01, 0);
  const double hot_current = NumberOr(spec, "hot_current", 0, 100, 0.5);
  return std::make_shared<DarkEffect>(black, current, hot_fraction, hot_current, SeedOf(spec));
}

std::shared_ptr<const Effect> MakeBrackets(const JsonView& spec, const EffectSetting&) {
  CheckKeys(spec, {"stops"});
  const JsonView list = spec["stops"];
  if (list.Size() < 1 || list.Size() > 9) list.Fail("1 to 9 stops");
  std::vector<double> stops;
  for (size_t k = 0; k < list.Size(); ++k) {
    // +-8 stops keeps camera.exposure x 2^stop inside dataset.json's exposure range.
    const double stop = list[k].NumberIn(-8, 8);
    for (double other : stops)
      if (BracketsEffect::Tag(other) == BracketsEffect::Tag(stop))
        list[k].Fail("a stop not listed before");
    stops.push_back(stop);
  }
  return std::make_shared<BracketsEffect>(stops);
}

std::shared_ptr<const Effect> MakeResponse(const JsonView& spec, const EffectSetting&) {
  CheckKeys(spec, {"curve", "gamma", "shoulder", "quality"});
  const std::string curve = spec.Has("curve") ? spec["curve"].OneOf({"gamma", "srgb"}) : "gamma";
  if (curve == "srgb")
    for (const char* key : {"gamma", "shoulder"})
      if (spec.Has(key)) spec[key].Fail("no parameter of the gamma curve with curve srgb");
  const double gamma = NumberOr(spec, "gamma", 1, 4, 2.2);
  const double shoulder = NumberOr(spec, "shoulder", 0, 10, 0);
  const int quality = spec.Has("quality") ? spec["quality"].IntIn(1, 100) : 95;
  return std::make_shared<ResponseEffect>(curve, gamma, shoulder, quality);
}

std::shared_ptr<const Effect> MakeStageError(const JsonView& spec, const EffectSetting&) {
  CheckKeys(spec, {"max_mm", "seed"});
  return std::make_shared<StageErrorEffect>(NumberOr(spec, "max_mm", 0, 5, 0.3), SeedOf(spec));
}

// The lens must map the photo one to one: the radial map r -> r (1 + k1 r^2 + k2 r^4 + k3 r^6)
// (undistorted -> distorted normalised radius) must keep rising, with slope > 0.2, until it
// reaches the farthest photo corner (a lens folding back inside the photo is no lens).
bool LensMonotonicOverPhoto(const LensSpec& lens, const CameraSpec& camera) {
  const double cx = 0.5 * (camera.width - 1) + lens.principal_offset_px.x();
  const double cy = 0.5 * (camera.height - 1) + lens.principal_offset_px.y();
  const double dx = std::max(cx, camera.width - 1 - cx), dy = std::max(cy, camera.height - 1 - cy);
  const double corner = std::hypot(dx, dy) / camera.focal_px;  // distorted, normalised
  for (double r = 0; r < 10; r += 1e-3) {
    const double r2 = r * r;
    const double slope = 1 + r2 * (3 * lens.k1 + r2 * (5 * lens.k2 + r2 * 7 * lens.k3));
    if (!(slope > 0.2)) return false;
    if (r * (1 + r2 * (lens.k1 + r2 * (lens.k2 + r2 * lens.k3))) > corner) return true;
  }
  return false;
}

std::shared_ptr<const Effect> MakeLens(const JsonView& spec, const EffectSetting& setting) {
  CheckKeys(spec, {"k1", "k2", "k3", "p1", "p2", "principal_offset_px"});
  LensSpec lens;
  lens.k1 = NumberOr(spec, "k1", -1, 1, 0);
  lens.k2 = NumberOr(spec, "k2", -1, 1, 0);
  lens.k3 = NumberOr(spec, "k3", -1, 1, 0);
  lens.p1 = NumberOr(spec, "p1", -0.05, 0.05, 0);
  lens.p2 = NumberOr(spec, "p2", -0.05, 0.05, 0);
  if (spec.Has("principal_offset_px")) {
    const JsonView offset = spec["principal_offset_px"];
    if (offset.Size() != 2) offset.Fail("[dx, dy] in pixels");
    // Within a quarter of the photo of its centre, as a real lens's principal point is.
    lens.principal_offset_px = {
        offset[0].NumberIn(-0.25 * setting.camera.width, 0.25 * setting.camera.width),
        offset[1].NumberIn(-0.25 * setting.camera.height, 0.25 * setting.camera.height)};
  }
  if (!LensMonotonicOverPhoto(lens, setting.camera))
    spec[spec.Has("k1")   ? "k1"
         : spec.Has("k2") ? "k2"
                          : "k3"]
        .Fail(
            "k1, k2, k3 whose radial distortion keeps rising (slope > 0.2) out to the photo's "
            "corners");
  return std::make_shared<LensEffect>(lens);
}

}  // namespace

void SensorNoiseEffect::Apply(ImageF& rgb, const PhotoContext& context) const {
  // std::seed_seq mixes seed and photo index so that neighbouring indices get unrelated streams.
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

VignettingEffect::VignettingEffect(const CameraSpec& camera, double k1, double k2, bool cos4)
    : camera_(camera), k1_(k1), k2_(k2), cos4_(cos4) {
  const PinholeCamera pinhole(camera);
  cx_ = pinhole.model().cx;
  cy_ = pinhole.model().cy;
}

double VignettingEffect::Factor(double px, double py) const {
  const double cx = cx_, cy = cy_;
  const double d2 = (px - cx) * (px - cx) + (py - cy) * (py - cy);
  const double f2 = camera_.focal_px * camera_.focal_px;
  const double cos2 = f2 / (f2 + d2);                        // cos^2 of the angle off the axis
  const double t = d2 / std::max(cx * cx + cy * cy, 1e-12);  // r^2
  return (cos4_ ? cos2 * cos2 : 1.0) * (1 + k1_ * t + k2_ * t * t);
}

void VignettingEffect::Apply(ImageF& rgb, const PhotoContext&) const {
  for (int y = 0; y < rgb.height; ++y)
    for (int x = 0; x < rgb.width; ++x) {
      const double f = Factor(x, y);
      for (int c = 0; c < rgb.channels; ++c) rgb.at(x, y, c) = float(rgb.at(x, y, c) * f);
    }
}

ScreenGainEffect::ScreenGainEffect(const EffectSetting& setting, double amplitude, int blobs,
                                   double size_mm, unsigned long long seed)
    : setting_(setting), amplitude_(amplitude), size_mm_(size_mm) {
  double sum = 0;
  for (int k = 0; k < blobs; ++k) {
    centres_mm_.emplace_back((Uniform(seed, k, 0) - 0.5) * setting.screen_w_mm,
                             (Uniform(seed, k, 1) - 0.5) * setting.screen_h_mm);
    weights_.push_back(2 * Uniform(seed, k, 2) - 1);
    sum += std::abs(weights_.back());
  }
  for (double& w : weights_) w = sum > 0 ? w / sum : 0;
}

double ScreenGainEffect::Gain(const Eigen::Vector2d& screen_mm) const {
  double s = 0;
  for (size_t k = 0; k < weights_.size(); ++k)
    s += weights_[k] *
         std::exp(-(screen_mm - centres_mm_[k]).squaredNorm() / (2 * size_mm_ * size_mm_));
  return 1 + amplitude_ * s;
}

void ScreenGainEffect::Apply(ImageF& rgb, const PhotoContext&) const {
  ForEachScreenPixel(setting_, rgb.width, rgb.height, [&](size_t pixel, const Eigen::Vector2d& xy) {
    const double g = Gain(xy);
    for (int c = 0; c < rgb.channels; ++c) {
      float& v = rgb.data[pixel * rgb.channels + c];
      v = float(v * g);
    }
  });
}

void AmbientEffect::Apply(ImageF& rgb, const PhotoContext& context) const {
  const float add = float(level_ * context.exposure);
  ForEachScreenPixel(setting_, rgb.width, rgb.height, [&](size_t pixel, const Eigen::Vector2d&) {
    for (int c = 0; c < rgb.channels; ++c) rgb.data[pixel * rgb.channels + c] += add;
  });
}

bool DarkEffect::Hot(int pixel) const {
  return hot_fraction_ > 0 && Uniform(seed_, (unsigned long long)pixel) < hot_fraction_;
}

void DarkEffect::Apply(ImageF& rgb, const PhotoContext& context) const {
  const double normal = black_level_ + dark_current_ * context.exposure;
  const double hot = black_level_ + hot_current_ * context.exposure;
  for (int p = 0; p < rgb.width * rgb.height; ++p) {
    const float add = float(Hot(p) ? hot : normal);
    for (int c = 0; c < rgb.channels; ++c) rgb.data[size_t(p) * rgb.channels + c] += add;
  }
}

std::string BracketsEffect::Tag(double stop) {
  std::ostringstream s;
  s << "ev" << (stop >= 0 ? "+" : "") << (stop == 0 ? 0.0 : stop);
  return s.str();
}

void BracketsEffect::Apply(ImageF& rgb, const PhotoContext&) const {
  for (float& v : rgb.data) v = std::min(v, 1.f);
}

double ResponseEffect::Curve(double x) const {
  x = std::clamp(x, 0.0, 1.0);
  if (curve_ == "srgb") return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1 / 2.4) - 0.055;
  return std::pow(x * (1 + shoulder_) / (1 + shoulder_ * x), 1 / gamma_);
}

double ResponseEffect::Inverse(double y) const {
  y = std::clamp(y, 0.0, 1.0);
  if (curve_ == "srgb") return y <= 0.04045 ? y / 12.92 : std::pow((y + 0.055) / 1.055, 2.4);
  const double z = std::pow(y, gamma_);
  return z / (1 + shoulder_ - shoulder_ * z);
}

void ResponseEffect::Apply(ImageF& rgb, const PhotoContext&) const {
  for (float& v : rgb.data) v = float(std::round(Curve(v) * 255) / 255);
}

Eigen::Vector2d StageErrorEffect::StageOffsetMm(int i, int j) const {
  return {(2 * Uniform(seed_, i, j, 0) - 1) * max_mm_, (2 * Uniform(seed_, i, j, 1) - 1) * max_mm_};
}

std::shared_ptr<const Effect> MakeRaw(const JsonView& spec, const EffectSetting&) {
  CheckKeys(spec, {"bit_depth", "black_level", "white_level"});
  const int bits = spec.Has("bit_depth") ? spec["bit_depth"].IntIn(12, 16) : 14;
  const int max_code = (1 << bits) - 1;
  const int black = spec.Has("black_level") ? spec["black_level"].IntIn(0, (1 << bits) / 4) : 512;
  // At least 1024 levels between black and white (black <= 2^bits / 4 leaves them by default).
  const int white =
      spec.Has("white_level") ? spec["white_level"].IntIn(black + 1024, max_code) : max_code;
  return std::make_shared<RawEffect>(bits, black, white);
}

int RawEffect::Code(float value) const {
  const double code = std::round(black_level_ + double(value) * (white_level_ - black_level_));
  return int(std::clamp(code, 0.0, double(white_level_)));
}

void RawEffect::Apply(ImageF& rgb, const PhotoContext&) const {
  const double range = white_level_ - black_level_;
  for (float& v : rgb.data) v = float((Code(v) - black_level_) / range);
}

const std::map<std::string, EffectFactory>& EffectRegistry() {
  static const std::map<std::string, EffectFactory> registry = {
      {"sensor_noise", &MakeSensorNoise},
      {"quantization", &MakeQuantization},
      {"vignetting", &MakeVignetting},
      {"screen_gain", &MakeScreenGain},
      {"ambient", &MakeAmbient},
      {"dark", &MakeDark},
      {"brackets", &MakeBrackets},
      {"response", &MakeResponse},
      {"stage_error", &MakeStageError},
      {"raw", &MakeRaw},
      {"lens", &MakeLens},
  };
  return registry;
}

std::shared_ptr<const Effect> MakeEffect(const JsonView& spec, const EffectSetting& setting) {
  std::vector<std::string> types;
  for (const auto& entry : EffectRegistry()) types.push_back(entry.first);
  const std::string type = spec["type"].OneOf(types);
  return EffectRegistry().at(type)(spec, setting);
}

}  // namespace lumislab
