#include "acquire/render.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>

namespace lumislab {

ScreenView ScreenView::Of(const SynthScene& scene) {
  ScreenView view;
  const PinholeCamera camera(scene.camera);
  view.width = scene.camera.width;
  view.height = scene.camera.height;
  const double half_w = 0.5 * scene.screen_w_mm, half_h = 0.5 * scene.screen_h_mm;
  Eigen::Vector2d xy;
  for (int y = 0; y < view.height; ++y)
    for (int x = 0; x < view.width; ++x)
      if (camera.PlanePoint(x, y, scene.distance_mm, &xy) && std::abs(xy.x()) <= half_w &&
          std::abs(xy.y()) <= half_h) {
        view.pixels.push_back(y * view.width + x);
        view.lab_mm.push_back(xy);
      }
  return view;
}

void RenderPosition(const SynthScene& scene, const ScreenView& view, int i, int j,
                    double radiometric_scale, ImageF* plus, ImageF* minus) {
  *plus = ImageF(view.width, view.height, 3);
  *minus = ImageF(view.width, view.height, 3);
  const DualFilter filter = scene.Filter();
  const double peak = filter.Peak2D();
  const Eigen::Vector2d c = scene.grid.Centre(i, j);
  const double gain = scene.camera.exposure / radiometric_scale;
  Eigen::Vector3d e_plus, e_minus;
  for (size_t k = 0; k < view.pixels.size(); ++k) {
    // The luminaire was moved by -c: lab (x, y) is (x, y) + c in the luminaire frame.
    const Eigen::Vector2d st = view.lab_mm[k] + c;
    scene.luminaire.SlideIrradiance(filter, peak, scene.grid.spacing_mm, c, scene.distance_mm,
                                    st.x(), st.y(), &e_plus, &e_minus);
    float* p = &plus->data[size_t(view.pixels[k]) * 3];
    float* n = &minus->data[size_t(view.pixels[k]) * 3];
    for (int ch = 0; ch < 3; ++ch) {
      p[ch] = float(e_plus[ch] * gain);
      n[ch] = float(e_minus[ch] * gain);
    }
  }
}

double MaxSlideIrradiance(const SynthScene& scene, const ScreenView& view, int stride,
                          int threads) {
  const DualFilter filter = scene.Filter();
  const double peak = filter.Peak2D();
  std::atomic<int> next{0};
  std::vector<double> max_of(std::max(1, threads), 0.0);
  auto work = [&](int t) {
    Eigen::Vector3d e_plus, e_minus;
    for (int q = next++; q < scene.grid.count(); q = next++) {
      const Eigen::Vector2d c = scene.grid.Centre(q % scene.grid.nu, q / scene.grid.nu);
      for (size_t k = 0; k < view.pixels.size(); k += stride) {
        const Eigen::Vector2d st = view.lab_mm[k] + c;
        scene.luminaire.SlideIrradiance(filter, peak, scene.grid.spacing_mm, c, scene.distance_mm,
                                        st.x(), st.y(), &e_plus, &e_minus);
        max_of[t] = std::max({max_of[t], e_plus.maxCoeff(), e_minus.maxCoeff()});
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < int(max_of.size()); ++t) pool.emplace_back(work, t);
  work(0);
  for (auto& th : pool) th.join();
  return *std::max_element(max_of.begin(), max_of.end());
}

namespace {

// Reflectance of the calibration scene at lab (x, y) on the screen plane.
double CheckerValue(const CalibrationTarget& t, double half_w, double half_h, double x, double y) {
  constexpr double kWhite = 0.8, kBlack = 0.05;
  if (std::abs(x) > half_w || std::abs(y) > half_h) return 0;
  const double a = (x - t.origin_mm.x()) / t.square_mm, b = (y - t.origin_mm.y()) / t.square_mm;
  if (a < 0 || b < 0 || a >= t.squares_x || b >= t.squares_y) return kWhite;
  const int ia = int(a), ib = int(b);
  if (ia == 0 && ib == 0) {
    const double da = a - 0.5, db = b - 0.5;
    return da * da + db * db <= 0.2 * 0.2 ? kWhite : kBlack;  // the orientation dot
  }
  return (ia + ib) % 2 == 0 ? kBlack : kWhite;
}

}  // namespace

cv::Mat RenderCalibration(const SynthScene& scene) {
  constexpr int kSub = 4;  // kSub x kSub samples per pixel, at the centres of sub-cells
  const PinholeCamera camera(scene.camera);
  const Eigen::Matrix3d screen_from_image = camera.ScreenFromImage(scene.distance_mm);
  const double half_w = 0.5 * scene.screen_w_mm, half_h = 0.5 * scene.screen_h_mm;
  cv::Mat out(scene.camera.height, scene.camera.width, CV_8UC1);
  Eigen::Vector2d probe;
  for (int y = 0; y < out.rows; ++y) {
    uint8_t* row = out.ptr<uint8_t>(y);
    for (int x = 0; x < out.cols; ++x) {
      double sum = 0;
      for (int sy = 0; sy < kSub; ++sy)
        for (int sx = 0; sx < kSub; ++sx) {
          const double px = x - 0.5 + (sx + 0.5) / kSub, py = y - 0.5 + (sy + 0.5) / kSub;
          if (!camera.PlanePoint(px, py, scene.distance_mm, &probe)) continue;
          const Eigen::Vector3d s = screen_from_image * Eigen::Vector3d(px, py, 1);
          sum += CheckerValue(scene.calibration, half_w, half_h, s.x() / s.z(), s.y() / s.z());
        }
      row[x] = cv::saturate_cast<uint8_t>(std::lround(255.0 * sum / (kSub * kSub)));
    }
  }
  return out;
}

}  // namespace lumislab
