#include "reconstruct/rectify.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "lib/photo/photo_allocator.h"

namespace lumislab {

namespace {

// The texel grid's (res_x + 1) x (res_y + 1) corners: lab point on the screen, and its exact
// photo pixel (NaN where the camera does not see it). Samples inside a texel interpolate these
// (the mapping is smooth on the scale of one texel: the error is far below 0.01 px).
struct TexelCorners {
  int nx = 0, ny = 0;
  std::function<Eigen::Vector2d(double, double)> lab_of;  // corner (cx, cy) -> lab mm
  std::vector<Eigen::Vector2f> pixel;                     // row-major, ny x nx
  const Eigen::Vector2f& at(int cx, int cy) const { return pixel[size_t(cy) * nx + cx]; }
};

TexelCorners CornerPixels(const ScreenCalibration& calibration, const SlabLayout& layout,
                          const Eigen::Vector2d& centre_mm) {
  TexelCorners c;
  c.nx = layout.res_x + 1;
  c.ny = layout.res_y + 1;
  const double tw = layout.TexelW(), th = layout.TexelH();
  // Luminaire-frame corner (cx, cy) of the texel grid -> lab point on the screen.
  c.lab_of = [=](double cx, double cy) -> Eigen::Vector2d {
    return Eigen::Vector2d(-0.5 * layout.window_w_mm + cx * tw,
                           0.5 * layout.window_h_mm - cy * th) -
           centre_mm;
  };
  const Eigen::Matrix3d image_from_screen = calibration.screen_from_image.inverse();
  // A screen point behind the camera maps through the homography to a mirrored pixel, which can
  // lie inside the photo: its texel would read the light of another point (a camera near a
  // large screen at a grazing angle, tests/e2e/hard_cases_test.cc). Points in front share the
  // sign of the homogeneous coordinate with the photo's centre, which the camera sees; the
  // homography's overall sign is arbitrary, so it is taken from there.
  const Eigen::Vector2d centre_px(0.5 * (calibration.image_width - 1),
                                  0.5 * (calibration.image_height - 1));
  const double in_front =
      (calibration.screen_from_image * calibration.Undistort(centre_px).homogeneous()).z();
  c.pixel.resize(size_t(c.nx) * c.ny);
  cv::parallel_for_(cv::Range(0, c.ny), [&](const cv::Range& rows) {
    for (int cy = rows.start; cy < rows.end; ++cy)
      for (int cx = 0; cx < c.nx; ++cx) {
        const Eigen::Vector3d hp = image_from_screen * c.lab_of(cx, cy).homogeneous();
        Eigen::Vector2d px(NAN, NAN);
        if (hp.z() * in_front > 0) px = calibration.Distort(hp.hnormalized());
        c.pixel[size_t(cy) * c.nx + cx] = px.cast<float>();
      }
  });
  return c;
}

// Inside the photo [0, max_x] x [0, max_y]; false for NaN.
struct PhotoBounds {
  float max_x, max_y;
  bool Contains(const Eigen::Vector2f& p) const {
    return p.x() >= 0 && p.y() >= 0 && p.x() <= max_x && p.y() <= max_y;
  }
};

// Texel edge lengths in pixels over the texels in the photo: fills max/min_texel_px, returns
// the median (1 when no texel is in the photo).
double MeasureTexels(const TexelCorners& c, const PhotoBounds& photo, RectifyMap* m) {
  std::vector<float> extents;
  for (int cy = 0; cy + 1 < c.ny; ++cy)
    for (int cx = 0; cx + 1 < c.nx; ++cx) {
      const Eigen::Vector2f &p00 = c.at(cx, cy), &p10 = c.at(cx + 1, cy), &p01 = c.at(cx, cy + 1);
      if (!photo.Contains(p00) || !photo.Contains(p10) || !photo.Contains(p01)) continue;
      extents.push_back((p10 - p00).norm());
      extents.push_back((p01 - p00).norm());
    }
  if (extents.empty()) return 1;
  m->max_texel_px = *std::max_element(extents.begin(), extents.end());
  m->min_texel_px = *std::min_element(extents.begin(), extents.end());
  std::nth_element(extents.begin(), extents.begin() + extents.size() / 2, extents.end());
  return extents[extents.size() / 2];
}

// Seen geometrically: all four corners inside the photo (the samples interpolate them, so they
// are inside too) and the texel's lab rectangle on the physical screen. Near the screen's edge a
// sample also reads photo pixels beyond the texel: bilinear reads of the F x F-averaged image
// reach photo pixels up to 2F - 1 away, which there show the frame around the screen, not the
// light (the edge texels came out 4 % dark with light running off the screen,
// tests/e2e/hard_cases_test.cc). Such a sample gets weight 0 (`sample_weight`), and the texel
// is the mean of its other samples: the light over the part of the texel that reads only the
// screen. A texel with less than kMinCleanSamples of its samples left is unseen. Texels far from
// the edge have no such sample, and when no texel has one `sample_weight` stays empty. `f` is
// the pre-average, `k` the samples per texel; the corners are in the averaged image's pixels.
constexpr double kMinCleanSamples = 0.25;

void MarkInside(const TexelCorners& c, const PhotoBounds& photo, const ScreenCalibration& calib,
                int f, int k, double screen_w_mm, double screen_h_mm, RectifyMap* m) {
  m->inside.assign(size_t(m->res_x) * m->res_y, 0);
  const double half_w = 0.5 * screen_w_mm + 1e-9, half_h = 0.5 * screen_h_mm + 1e-9;
  auto on_screen = [&](const Eigen::Vector2d& lab) {
    return std::abs(lab.x()) <= half_w && std::abs(lab.y()) <= half_h;
  };
  // The photo pixels the averaged image covers (its top-left multiple of F; beyond, remap
  // reads 0).
  const double photo_x1 = f * (calib.image_width / f) - 0.5;
  const double photo_y1 = f * (calib.image_height / f) - 0.5;
  // Whether the sample at averaged pixel p reads only the screen: the averaged pixels bilinear
  // reads touch (floor(p) and the next), the photo pixels those average, half a pixel more for
  // the pixels' own area; their box's corners on the screen (the box spans a few pixels, where
  // the lens's distortion bends no edge measurably; the screen is convex).
  auto clean = [&](const Eigen::Vector2f& p) {
    const double x0 = f * std::floor(p.x()) - 0.5, y0 = f * std::floor(p.y()) - 0.5;
    const double x1 = f * (std::floor(p.x()) + 2) - 0.5, y1 = f * (std::floor(p.y()) + 2) - 0.5;
    if (x0 < -0.5 || y0 < -0.5 || x1 > photo_x1 || y1 > photo_y1) return false;
    for (const double y : {y0, y1})
      for (const double x : {x0, x1})
        if (!on_screen(calib.ScreenFromImage({x, y}))) return false;
    return true;
  };
  std::vector<float> fr(k);
  for (int a = 0; a < k; ++a) fr[a] = (a + 0.5f) / k;
  cv::Mat weight(m->res_y * k, m->res_x * k, CV_32FC1, cv::Scalar(1));
  std::atomic<bool> partial{false};
  cv::parallel_for_(cv::Range(0, m->res_y), [&](const cv::Range& rows) {
    for (int row = rows.start; row < rows.end; ++row)
      for (int col = 0; col < m->res_x; ++col) {
        const Eigen::Vector2d lo = c.lab_of(col, row + 1), hi = c.lab_of(col + 1, row);
        const Eigen::Vector2f &p00 = c.at(col, row), &p10 = c.at(col + 1, row);
        const Eigen::Vector2f &p01 = c.at(col, row + 1), &p11 = c.at(col + 1, row + 1);
        const bool in = photo.Contains(p00) && photo.Contains(p10) && photo.Contains(p01) &&
                        photo.Contains(p11);
        if (!in ||
            !(lo.x() >= -half_w && hi.x() <= half_w && lo.y() >= -half_h && hi.y() <= half_h))
          continue;
        // Far from the screen's edge every sample reads the screen: the reads reach at most
        // 2F photo pixels (two averaged pixels) beyond the texel, times the texel's mm per
        // pixel, doubled (√2 for a rotated view, and the perspective's change over a few
        // texels), is a safe margin. Only near the edge are the samples mapped to the screen.
        const double side_px = f * std::min((p10 - p00).norm(), (p01 - p00).norm());
        const double margin = 2 * std::sqrt(2.0) * 2 * f *
                              std::max(hi.x() - lo.x(), hi.y() - lo.y()) / std::max(side_px, 1e-9);
        const bool far_from_edge = lo.x() - margin >= -half_w && hi.x() + margin <= half_w &&
                                   lo.y() - margin >= -half_h && hi.y() + margin <= half_h;
        int kept = k * k;
        if (!far_from_edge) {
          kept = 0;
          for (int b = 0; b < k; ++b) {
            const Eigen::Vector2f left = p00 + fr[b] * (p01 - p00);
            const Eigen::Vector2f right = p10 + fr[b] * (p11 - p10);
            float* w = weight.ptr<float>(row * k + b) + col * k;
            for (int a = 0; a < k; ++a) {
              const bool ok = clean(left + fr[a] * (right - left));
              w[a] = ok ? 1.f : 0.f;
              kept += ok;
            }
          }
          if (kept < k * k) partial = true;
        }
        m->inside[size_t(row) * m->res_x + col] = kept >= kMinCleanSamples * k * k ? 1 : 0;
      }
  });
  if (partial) m->sample_weight = weight;
}

// Sample (a, b) of texel (col, row) interpolates the texel's corners bilinearly at
// ((a + 0.5) / K, (b + 0.5) / K). Written directly in OpenCV's fixed-point remap format
// (integer pixel + 1/32 fraction, what remap converts float maps to anyway).
void WriteRemapTables(const TexelCorners& c, RectifyMap* m) {
  constexpr int kBits = cv::INTER_BITS, kTab = cv::INTER_TAB_SIZE;
  const int k = m->samples_per_texel;
  m->map_xy.create(m->res_y * k, m->res_x * k, CV_16SC2);
  m->map_frac.create(m->res_y * k, m->res_x * k, CV_16UC1);
  std::vector<float> fr(k);
  for (int a = 0; a < k; ++a) fr[a] = (a + 0.5f) / k;
  cv::parallel_for_(cv::Range(0, m->res_y), [&](const cv::Range& rows) {
    for (int row = rows.start; row < rows.end; ++row)
      for (int b = 0; b < k; ++b) {
        const float fy = fr[b];
        int16_t* xy = m->map_xy.ptr<int16_t>(row * k + b);
        uint16_t* frac = m->map_frac.ptr<uint16_t>(row * k + b);
        for (int col = 0; col < m->res_x; ++col) {
          const Eigen::Vector2f &p00 = c.at(col, row), &p10 = c.at(col + 1, row);
          const Eigen::Vector2f &p01 = c.at(col, row + 1), &p11 = c.at(col + 1, row + 1);
          const Eigen::Vector2f left = p00 + fy * (p01 - p00), right = p10 + fy * (p11 - p10);
          const bool ok = m->inside[size_t(row) * m->res_x + col] != 0;
          for (int a = 0; a < k; ++a, xy += 2, ++frac) {
            const Eigen::Vector2f p = left + fr[a] * (right - left);
            // Unseen texels read the constant border; their values are never used.
            const int ix = ok ? cvRound(p.x() * kTab) : -10 * kTab;
            const int iy = ok ? cvRound(p.y() * kTab) : -10 * kTab;
            xy[0] = int16_t(ix >> kBits);
            xy[1] = int16_t(iy >> kBits);
            frac[0] = uint16_t((iy & (kTab - 1)) * kTab + (ix & (kTab - 1)));
          }
        }
      }
  });
}

// The bounding box of the pixels the seen texels' samples read (unseen texels' samples read the
// border at -10 and are left out), clipped to the w x h averaged image.
cv::Rect ReadRegion(const RectifyMap& m, int w, int h) {
  int x0 = w, y0 = h, x1 = -1, y1 = -1;
  for (int r = 0; r < m.map_xy.rows; ++r) {
    const int16_t* xy = m.map_xy.ptr<int16_t>(r);
    for (int c = 0; c < m.map_xy.cols; ++c, xy += 2) {
      if (xy[0] < 0 || xy[1] < 0) continue;
      x0 = std::min(x0, int(xy[0])), x1 = std::max(x1, int(xy[0]));
      y0 = std::min(y0, int(xy[1])), y1 = std::max(y1, int(xy[1]));
    }
  }
  if (x1 < 0) return {};
  // + 1: the bilinear neighbours; + 1: exclusive end.
  return cv::Rect(cv::Point(x0, y0), cv::Point(x1 + 2, y1 + 2)) & cv::Rect(0, 0, w, h);
}

}  // namespace

RectifyMap BuildRectifyMap(const ScreenCalibration& calibration, const SlabLayout& layout,
                           const Eigen::Vector2d& centre_mm, double screen_w_mm, double screen_h_mm,
                           int samples_per_texel) {
  RectifyMap m;
  m.res_x = layout.res_x;
  m.res_y = layout.res_y;
  TexelCorners corners = CornerPixels(calibration, layout, centre_mm);
  PhotoBounds photo{float(calibration.image_width - 1), float(calibration.image_height - 1)};
  const double median_px = MeasureTexels(corners, photo, &m);
  const int f = samples_per_texel > 0 ? 1 : std::max(1, int(std::lround(median_px / 3)));
  m.samples_per_texel = samples_per_texel > 0 ? samples_per_texel
                                              : std::clamp(int(std::ceil(m.max_texel_px / f)), 2,
                                                           kMaxSamplesPerTexel);
  m.downsample = f;
  // Pixel p of the photo is at (p - (F - 1) / 2) / F in the F x F averaged image, whose size is
  // floor(size / F).
  if (f > 1) {
    const float shift = 0.5f * (f - 1), scale = 1.0f / f;
    for (auto& p : corners.pixel) p = (p.array() - shift) * scale;
    photo = {float(calibration.image_width / f - 1), float(calibration.image_height / f - 1)};
  }
  MarkInside(corners, photo, calibration, f, m.samples_per_texel, screen_w_mm, screen_h_mm, &m);
  WriteRemapTables(corners, &m);
  m.read_region = ReadRegion(m, calibration.image_width / f, calibration.image_height / f);
  return m;
}

cv::Mat Rectify(const cv::Mat& signal, const RectifyMap& map) {
  LUMISLAB_CHECK(signal.type() == CV_32FC4 || signal.type() == CV_32FC3,
                 "Rectify: expects a CV_32FC3/4 image");
  // The samples (K x K per texel: 1800 x 1800 x 4 floats, 52 MB, for the bench's 6000 x 4000
  // photos) in huge pages (NewPhotoImage): in 4 kB pages, the page faults of the first touch
  // are a large part of the remap's time (docs/testing.md §3).
  cv::Mat samples = NewPhotoImage(map.map_xy.rows, map.map_xy.cols, signal.type()), texels;
  cv::remap(signal, samples, map.map_xy, map.map_frac, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar::all(0));
  if (map.samples_per_texel == 1 && map.sample_weight.empty()) return samples;
  const cv::Size size(map.res_x, map.res_y);
  if (map.sample_weight.empty()) {
    cv::resize(samples, texels, size, 0, 0, cv::INTER_AREA);
    return texels;
  }
  // Near the screen's edge: the mean of the samples that read only the screen (BuildRectifyMap).
  // Each sample's channels times its weight, in place (the same products as a per-plane
  // multiply, without three more images of the samples' size).
  const int channels = samples.channels();
  for (int row = 0; row < samples.rows; ++row) {
    float* s = samples.ptr<float>(row);
    const float* w = map.sample_weight.ptr<float>(row);
    for (int col = 0; col < samples.cols; ++col)
      for (int ch = 0; ch < channels; ++ch) s[col * channels + ch] *= w[col];
  }
  cv::Mat kept;
  cv::resize(samples, texels, size, 0, 0, cv::INTER_AREA);
  cv::resize(map.sample_weight, kept, size, 0, 0, cv::INTER_AREA);
  for (int row = 0; row < texels.rows; ++row) {
    float* t = texels.ptr<float>(row);
    const float* w = kept.ptr<float>(row);
    for (int col = 0; col < texels.cols; ++col)
      for (int ch = 0; ch < texels.channels(); ++ch)
        t[col * texels.channels() + ch] =
            w[col] > 0 ? t[col * texels.channels() + ch] / w[col] : 0.f;
  }
  return texels;
}

}  // namespace lumislab
