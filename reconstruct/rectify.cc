#include "reconstruct/rectify.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace lumislab {

RectifyMap BuildRectifyMap(const ScreenCalibration& calibration, const SlabLayout& layout,
                           const Eigen::Vector2d& centre_mm, double screen_w_mm, double screen_h_mm,
                           int samples_per_texel) {
  RectifyMap m;
  m.res_x = layout.res_x;
  m.res_y = layout.res_y;
  const int nx = m.res_x + 1, ny = m.res_y + 1;
  const Eigen::Matrix3d image_from_screen = calibration.screen_from_image.inverse();
  const double tw = layout.TexelW(), th = layout.TexelH();
  // Luminaire-frame corner (cx, cy) of the texel grid -> lab point on the screen.
  auto lab_of = [&](double cx, double cy) -> Eigen::Vector2d {
    return Eigen::Vector2d(-0.5 * layout.window_w_mm + cx * tw,
                           0.5 * layout.window_h_mm - cy * th) -
           centre_mm;
  };
  // Exact photo pixel of every texel corner; samples inside a texel interpolate these (the
  // mapping is smooth on the scale of one texel: the error is far below 0.01 px).
  std::vector<Eigen::Vector2f> corner(size_t(nx) * ny);
  cv::parallel_for_(cv::Range(0, ny), [&](const cv::Range& rows) {
    for (int cy = rows.start; cy < rows.end; ++cy)
      for (int cx = 0; cx < nx; ++cx) {
        const Eigen::Vector3d hp = image_from_screen * lab_of(cx, cy).homogeneous();
        Eigen::Vector2d px(NAN, NAN);
        if (hp.z() > 0 || hp.z() < 0) px = calibration.Distort(hp.hnormalized());
        corner[size_t(cy) * nx + cx] = px.cast<float>();
      }
  });
  const float max_x = float(calibration.image_width - 1),
              max_y = float(calibration.image_height - 1);
  auto in_photo = [&](const Eigen::Vector2f& p) {
    return p.x() >= 0 && p.y() >= 0 && p.x() <= max_x && p.y() <= max_y;  // false for NaN
  };
  // Texel extent in pixels, over texels whose corners are in the photo.
  double max_px = 0;
  for (int cy = 0; cy + 1 < ny; ++cy)
    for (int cx = 0; cx + 1 < nx; ++cx) {
      const Eigen::Vector2f& p00 = corner[size_t(cy) * nx + cx];
      const Eigen::Vector2f& p10 = corner[size_t(cy) * nx + cx + 1];
      const Eigen::Vector2f& p01 = corner[size_t(cy + 1) * nx + cx];
      if (!in_photo(p00) || !in_photo(p10) || !in_photo(p01)) continue;
      max_px = std::max({max_px, double((p10 - p00).norm()), double((p01 - p00).norm())});
    }
  m.max_texel_px = max_px;
  const int k = samples_per_texel > 0 ? samples_per_texel
                                      : std::clamp(int(std::ceil(max_px)), 2, kMaxSamplesPerTexel);
  m.samples_per_texel = k;
  m.map_x.create(m.res_y * k, m.res_x * k, CV_32FC1);
  m.map_y.create(m.res_y * k, m.res_x * k, CV_32FC1);
  m.inside.assign(size_t(m.res_x) * m.res_y, 0);
  const double half_w = 0.5 * screen_w_mm, half_h = 0.5 * screen_h_mm;
  cv::parallel_for_(cv::Range(0, m.res_y), [&](const cv::Range& rows) {
    for (int row = rows.start; row < rows.end; ++row)
      for (int col = 0; col < m.res_x; ++col) {
        const Eigen::Vector2f& p00 = corner[size_t(row) * nx + col];
        const Eigen::Vector2f& p10 = corner[size_t(row) * nx + col + 1];
        const Eigen::Vector2f& p01 = corner[size_t(row + 1) * nx + col];
        const Eigen::Vector2f& p11 = corner[size_t(row + 1) * nx + col + 1];
        bool all_inside = true;
        for (int b = 0; b < k; ++b) {
          const float fy = (b + 0.5f) / k;
          float* mx = m.map_x.ptr<float>(row * k + b) + size_t(col) * k;
          float* my = m.map_y.ptr<float>(row * k + b) + size_t(col) * k;
          for (int a = 0; a < k; ++a) {
            const float fx = (a + 0.5f) / k;
            const Eigen::Vector2f p =
                (1 - fy) * ((1 - fx) * p00 + fx * p10) + fy * ((1 - fx) * p01 + fx * p11);
            const Eigen::Vector2d lab = lab_of(col + fx, row + fy);
            const bool ok =
                in_photo(p) && std::abs(lab.x()) <= half_w && std::abs(lab.y()) <= half_h;
            all_inside = all_inside && ok;
            mx[a] = ok ? p.x() : -10.f;  // outside: remap reads the constant border (0)
            my[a] = ok ? p.y() : -10.f;
          }
        }
        m.inside[size_t(row) * m.res_x + col] = all_inside ? 1 : 0;
      }
  });
  return m;
}

cv::Mat Rectify(const cv::Mat& signal, const RectifyMap& map) {
  LUMISLAB_CHECK(signal.type() == CV_32FC4, "Rectify: expects a CV_32FC4 image");
  cv::Mat samples, texels;
  cv::remap(signal, samples, map.map_x, map.map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar::all(0));
  if (map.samples_per_texel == 1) return samples;
  cv::resize(samples, texels, cv::Size(map.res_x, map.res_y), 0, 0, cv::INTER_AREA);
  return texels;
}

}  // namespace lumislab
