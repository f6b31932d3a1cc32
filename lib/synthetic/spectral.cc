#include "lib/synthetic/spectral.h"

#include <cmath>
#include <random>

#include "core/error.h"
#include "core/geometry.h"

namespace lumislab {
namespace {

double Gauss(double nm, double centre_nm, double sigma_nm) {
  const double t = (nm - centre_nm) / sigma_nm;
  return std::exp(-0.5 * t * t);
}

// The IR-cut filter: transmission falling from 1 at 650 nm to ~0 by 700 nm.
double IrCut(double nm) { return 1.0 / (1.0 + std::exp((nm - 670) / 8)); }

// The mcc classic chart model (cv::mcc, modules/mcc/src/dictionary.hpp): units.
constexpr double kChartW = 16.75, kChartH = 11.25, kPitch = 2.75, kPatch = 2.5, kMargin = 0.25;
constexpr double kFrameReflectance = 0.03, kCardReflectance = 0.18;

}  // namespace

const Eigen::Matrix<double, kSpectralSamples, 3>& SyntheticSensitivities() {
  static const Eigen::Matrix<double, kSpectralSamples, 3> s = [] {
    Eigen::Matrix<double, kSpectralSamples, 3> m;
    for (int k = 0; k < kSpectralSamples; ++k) {
      const double nm = WavelengthNm(k);
      m(k, 0) = (Gauss(nm, 598, 34) + 0.12 * Gauss(nm, 450, 22)) * IrCut(nm);
      m(k, 1) = (Gauss(nm, 545, 40) + 0.05 * Gauss(nm, 620, 30)) * IrCut(nm);
      m(k, 2) = (Gauss(nm, 452, 24) + 0.08 * Gauss(nm, 515, 30)) * IrCut(nm);
    }
    for (int c = 0; c < 3; ++c) m.col(c) /= m.col(c).sum();
    return m;
  }();
  return s;
}

Eigen::Vector3d CameraRgb(const Spectrum& s) { return SyntheticSensitivities().transpose() * s; }

Eigen::Vector3d BlackbodyRgbPerWatt(double kelvin) {
  const Spectrum s = Blackbody(kelvin);
  return CameraRgb(s / s.mean());
}

ImageF RenderColourChartPhoto(const ColourChartPhotoSpec& spec) {
  const std::optional<Spectrum> light = IlluminantByName(spec.illuminant);
  if (!light)
    throw BadInput("colour chart: illuminant: expected D50 or D65, got " + spec.illuminant);
  const Spectrum illuminant = *light / light->mean();
  Eigen::Vector3d patch_rgb[24];
  for (int k = 0; k < 24; ++k)
    patch_rgb[k] = spec.exposure * CameraRgb(ColorCheckerReflectance(k).cwiseProduct(illuminant));
  const Eigen::Vector3d frame = spec.exposure * kFrameReflectance * CameraRgb(illuminant);
  const Eigen::Vector3d card = spec.exposure * kCardReflectance * CameraRgb(illuminant);
  // Chart units -> pixels: scaled, rotated in the image plane and centred; a mild keystone (the
  // chart's top 4 % narrower) stands for a camera not square to it.
  const double scale = spec.chart_fraction * spec.width / kChartW;
  const double a = spec.rotation_deg * kPi / 180;
  const Eigen::Vector2d centre(0.5 * spec.width, 0.5 * spec.height);
  auto chart_of_pixel = [&](double px, double py, Eigen::Vector2d* uv) {
    const Eigen::Vector2d d(px - centre.x(), py - centre.y());
    const Eigen::Vector2d r(std::cos(a) * d.x() + std::sin(a) * d.y(),
                            -std::sin(a) * d.x() + std::cos(a) * d.y());
    const double v = r.y() / scale + 0.5 * kChartH;
    const double keystone = 1 - 0.04 * (1 - v / kChartH);
    *uv = {r.x() / (scale * keystone) + 0.5 * kChartW, v};
  };
  ImageF image(spec.width, spec.height, 3);
  std::mt19937 rng(29);
  std::normal_distribution<double> noise(0, spec.noise);
  constexpr int kSub = 4;  // 4 x 4 samples a pixel: edges anti-aliased like a lens's blur
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int sy = 0; sy < kSub; ++sy)
        for (int sx = 0; sx < kSub; ++sx) {
          Eigen::Vector2d uv;
          chart_of_pixel(x + (sx + 0.5) / kSub - 0.5, y + (sy + 0.5) / kSub - 0.5, &uv);
          if (uv.x() < 0 || uv.y() < 0 || uv.x() > kChartW || uv.y() > kChartH) {
            sum += card;
            continue;
          }
          const int col = int((uv.x() - kMargin) / kPitch), row = int((uv.y() - kMargin) / kPitch);
          const double du = uv.x() - kMargin - col * kPitch, dv = uv.y() - kMargin - row * kPitch;
          const bool in_patch = col >= 0 && col < 6 && row >= 0 && row < 4 && du >= 0 &&
                                du < kPatch && dv >= 0 && dv < kPatch;
          sum += in_patch ? patch_rgb[row * 6 + col] : frame;
        }
      for (int c = 0; c < 3; ++c)
        image.at(x, y, c) = float(sum[c] / (kSub * kSub) * (1 + noise(rng)));
    }
  return image;
}

}  // namespace lumislab
