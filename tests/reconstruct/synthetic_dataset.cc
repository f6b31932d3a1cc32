#include "synthetic_dataset.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "core/atomic_file.h"
#include "core/basis.h"
#include "core/exr_io.h"
#include "core/slab.h"
#include "reconstruct/bell_fit.h"

namespace lumislab::testing {

namespace {
constexpr double kChannelGain[3] = {1.0, 0.7, 0.4};
constexpr double kGain = 2.0;                            // radiometric scale, W/m^2 per unit value
constexpr double kSigmaPlus = 14.0, kSigmaMinus = 25.0;  // mm

double Gauss(double dx, double dy, double sigma) {
  return std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma));
}
}  // namespace

std::string FreshTestDir(const std::string& name) {
  const std::string dir =
      (std::filesystem::temp_directory_path() / "lumislab_reconstruct_test" / name).string();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

double SyntheticDataset::Photo(int i, int j, bool positive, int c, double x, double y) const {
  // Luminaire frame point seen at lab (x, y) for this position.
  const Eigen::Vector2d centre = dataset.grid.Centre(i, j);
  const double s = x + centre.x(), t = y + centre.y();
  const double a = options.amplitude * kChannelGain[c];
  if (positive) return 0.02 + a * Gauss(s - (10.0 * i - 5), t - (6.0 * j - 8), kSigmaPlus);
  return 0.02 + 0.3 * a * Gauss(s, t, kSigmaMinus);
}

namespace {
// Mean of exp(-(x - m)^2 / (2 sigma^2)) over [x0, x1].
double GaussMean1D(double x0, double x1, double m, double sigma) {
  const double k = 1.0 / (sigma * std::sqrt(2.0));
  return sigma * std::sqrt(M_PI / 2) * (std::erf((x1 - m) * k) - std::erf((x0 - m) * k)) /
         (x1 - x0);
}
}  // namespace

double SyntheticDataset::TruthBox(int i, int j, int c, double s0, double s1, double t0,
                                  double t1) const {
  const double a = options.amplitude * kChannelGain[c];
  const double plus = a * GaussMean1D(s0, s1, 10.0 * i - 5, kSigmaPlus) *
                      GaussMean1D(t0, t1, 6.0 * j - 8, kSigmaPlus);
  const double minus =
      0.3 * a * GaussMean1D(s0, s1, 0, kSigmaMinus) * GaussMean1D(t0, t1, 0, kSigmaMinus);
  return dataset.filter.peak * kGain * (plus - minus);
}

double SyntheticDataset::Truth(int i, int j, int c, double s, double t) const {
  const Eigen::Vector2d centre = dataset.grid.Centre(i, j);
  const double x = s - centre.x(), y = t - centre.y();
  return dataset.filter.peak * kGain * (Photo(i, j, true, c, x, y) - Photo(i, j, false, c, x, y));
}

void SyntheticDataset::WritePhotos(int i, int j) {
  const int n = options.image_px;
  std::mt19937 rng(options.noise_seed + 7919u * unsigned(dataset.grid.Index(i, j)));
  std::normal_distribution<double> noise(0.0, options.noise_sigma > 0 ? options.noise_sigma : 1.0);
  for (const auto& e : dataset.PhotosOf(i, j)) {
    cv::Mat img(n, n, options.ext == ".png" ? CV_16UC3 : CV_32FC3);
    ImageF exr(n, n, 3);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const Eigen::Vector2d lab = calibration.ScreenFromImage(Eigen::Vector2d(x, y));
        for (int c = 0; c < 3; ++c) {
          double v = e.exposure * Photo(i, j, e.positive, c, lab.x(), lab.y());
          if (options.noise_sigma > 0) v += noise(rng);
          v = std::clamp(v, 0.0, 1.0);
          if (options.ext == ".png")
            img.at<cv::Vec<uint16_t, 3>>(y, x)[2 - c] = uint16_t(std::lround(v * 65535));
          else
            exr.at(x, y, c) = float(v);
        }
      }
    const std::string path = dataset.Path(e.file);
    if (options.ext == ".png")
      WriteAtomically(path, [&](const std::string& tmp) { cv::imwrite(tmp, img); });
    else
      WriteExr(path, exr, {"R", "G", "B"});
  }
}

SyntheticDataset MakeSyntheticDataset(const std::string& dir, const SyntheticOptions& options,
                                      bool write_photos) {
  SyntheticDataset s;
  s.options = options;
  s.dir = dir;
  Dataset& d = s.dataset;
  d.dir = dir;
  d.distance_mm = 50;
  d.grid = {options.nu, options.nv, options.spacing_mm};
  d.screen_w_mm = d.screen_h_mm = options.screen_mm;
  const DualFilter filter = DualFilter::Truncated(1);
  d.filter.spacing_mm = options.spacing_mm;
  d.filter.dual_coefficients = filter.coefficients();
  d.filter.peak = filter.Peak2D();
  d.radiometric_scale = kGain;
  d.saturation_level = 1.0;
  d.synthetic = true;
  d.calibration = {"photos/calib_0.png", 8, 7, 10.0, {-40, -35}};  // not square: checked on load
  for (int j = 0; j < d.grid.nv; ++j)
    for (int i = 0; i < d.grid.nu; ++i)
      for (bool positive : {true, false})
        for (size_t k = 0; k < options.exposures.size(); ++k) {
          const std::string tag = options.exposures.size() > 1 ? "e" + std::to_string(k) : "";
          d.photos.push_back({i, j, positive,
                              "photos/" + PhotoFileName(i, j, positive, options.ext.substr(1), tag),
                              options.exposures[k]});
        }
  // image_from_screen: u = (a x + c0) / w, v = (-a y + c0) / w, w = 1 + p x.
  const double a = options.px_per_mm, c0 = 0.5 * (options.image_px - 1);
  Eigen::Matrix3d image_from_screen;
  image_from_screen << a, 0, c0, 0, -a, c0, options.perspective, 0, 1;
  ScreenCalibration& cal = s.calibration;
  cal.image_width = cal.image_height = options.image_px;
  cal.screen_from_image = image_from_screen.inverse();
  cal.k1 = options.k1;
  cal.centre_px = {c0, c0};
  cal.scale_px = 0.5 * options.image_px;
  cal.photo = d.calibration.photo;
  MakeDirectories(dir + "/photos");
  MakeDirectories(dir + "/calib");
  d.Save(dir);
  if (options.write_calibration) cal.Save(dir + "/calib/screen.json");
  if (write_photos)
    for (int j = 0; j < d.grid.nv; ++j)
      for (int i = 0; i < d.grid.nu; ++i) s.WritePhotos(i, j);
  // Pixels clipped in every exposure of a slide (T+ only can exceed 1 here).
  double min_exposure = 1e300;
  for (double e : options.exposures) min_exposure = std::min(min_exposure, e);
  for (int j = 0; j < d.grid.nv; ++j)
    for (int i = 0; i < d.grid.nu; ++i)
      for (int y = 0; y < options.image_px; ++y)
        for (int x = 0; x < options.image_px; ++x) {
          const Eigen::Vector2d lab = cal.ScreenFromImage(Eigen::Vector2d(x, y));
          bool clipped = false;
          for (int c = 0; c < 3; ++c)
            clipped = clipped || min_exposure * s.Photo(i, j, true, c, lab.x(), lab.y()) >= 1.0;
          s.saturated_pixels_total += clipped ? 1 : 0;
        }
  return s;
}

ImageF PointTruth(const SyntheticDataset& ds, int i, int j, const SlabLayout& layout) {
  ImageF out(layout.res_x, layout.res_y, 3);
  for (int row = 0; row < layout.res_y; ++row)
    for (int col = 0; col < layout.res_x; ++col) {
      const Eigen::Vector2d st = layout.TexelCentre(col, row);
      for (int c = 0; c < 3; ++c) out.at(col, row, c) = float(ds.Truth(i, j, c, st.x(), st.y()));
    }
  return out;
}

ImageF ExpectedFit(const SyntheticDataset& ds, int i, int j, const SlabLayout& layout,
                   const SlabPosition& p) {
  const size_t n = size_t(layout.res_x) * layout.res_y;
  std::vector<double> b(n * 3, 0.0);
  std::vector<unsigned char> seen(n);
  for (int row = 0; row < layout.res_y; ++row)
    for (int col = 0; col < layout.res_x; ++col) {
      const size_t k = size_t(row) * layout.res_x + col;
      seen[k] = p.mask.data[k] > 0.5f;
      const Eigen::Vector2d st = layout.TexelCentre(col, row);
      const double hw = 0.5 * layout.TexelW(), hh = 0.5 * layout.TexelH();
      for (int c = 0; c < 3; ++c)
        b[k * 3 + c] = ds.TruthBox(i, j, c, st.x() - hw, st.x() + hw, st.y() - hh, st.y() + hh);
    }
  BellFitOptions o;
  o.tolerance = 1e-12;
  const std::vector<double> c = FitBell(b, seen, layout.res_x, layout.res_y, 3, o);
  ImageF out(layout.res_x, layout.res_y, 3);
  for (size_t k = 0; k < c.size(); ++k) out.data[k] = float(c[k]);
  return out;
}

double RelativeL2(const SlabPosition& p, const ImageF& reference) {
  float max_ref = 0;
  for (float v : reference.data) max_ref = std::max(max_ref, std::abs(v));
  double err2 = 0, ref2 = 0;
  for (size_t k = 0; k < p.mask.data.size(); ++k) {
    if (p.mask.data[k] < 0.5f) continue;
    float mag = 0;
    for (int c = 0; c < 3; ++c) mag = std::max(mag, std::abs(reference.data[k * 3 + c]));
    if (mag < 0.01f * max_ref) continue;
    for (int c = 0; c < 3; ++c) {
      const double e = double(p.irradiance.data[k * 3 + c]) - reference.data[k * 3 + c];
      err2 += e * e;
      ref2 += double(reference.data[k * 3 + c]) * reference.data[k * 3 + c];
    }
  }
  return ref2 > 0 ? std::sqrt(err2 / ref2) : 0.0;
}

}  // namespace lumislab::testing
