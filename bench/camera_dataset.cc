#include "camera_dataset.h"

#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>
#include <thread>

#include "core/error.h"
#include "core/parallel.h"
#include "lib/photo/camera_write.h"
#include "synthetic_dataset.h"

namespace lumislab::bench {

namespace {

double Srgb(double l) {  // linear -> sRGB-encoded, as a camera's JPEG stores it
  return l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1 / 2.4) - 0.055;
}

// Deterministic noise in [-1, 1) from a pixel index (a hash; no state shared between rows).
double Hash(uint64_t k) {
  k ^= k >> 33, k *= 0xff51afd7ed558ccdULL, k ^= k >> 33, k *= 0xc4ceb9fe1a85ec53ULL;
  k ^= k >> 33;
  return double(k >> 11) / double(1ULL << 52) - 1.0;
}

}  // namespace

const char* CameraFormatName(CameraFormat format) {
  switch (format) {
    case CameraFormat::kJpeg:
      return "JPEG 8-bit";
    case CameraFormat::kTiff16:
      return "TIFF 16-bit";
    case CameraFormat::kDng:
      return "DNG 14-bit";
  }
  return "?";
}

void MakeCameraDataset(const std::string& dir, CameraFormat format, int width, int height,
                       const std::vector<double>& exposures) {
  std::filesystem::remove_all(dir);
  testing::SyntheticOptions o;
  o.nu = o.nv = 1;
  o.screen_mm = 1200;
  o.image_px = width;
  o.px_per_mm = 0.9 * std::min(width, height) / 1200.0;
  o.ext = format == CameraFormat::kJpeg     ? ".jpg"
          : format == CameraFormat::kTiff16 ? ".tif"
                                            : ".dng";
  o.exposures = exposures;
  o.write_calibration = false;
  testing::SyntheticDataset s = testing::MakeSyntheticDataset(dir, o, false);
  // A width x height camera looking at the screen slightly obliquely: image_from_screen
  // u = (a x + cx) / w, v = (-a y + cy) / w, w = 1 + 2e-4 x.
  const double a = o.px_per_mm, cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
  Eigen::Matrix3d image_from_screen;
  image_from_screen << a, 0, cx, 0, -a, cy, 2e-4, 0, 1;
  s.calibration.image_width = width;
  s.calibration.image_height = height;
  s.calibration.screen_from_image = image_from_screen.inverse();
  s.calibration.centre_px = {cx, cy};
  s.calibration.scale_px = 0.5 * std::max(width, height);
  s.calibration.Save(dir + "/calib/screen.json");
  // The analytic light is ~100 mm wide on a 1200 mm screen: widen it by sampling the photo at
  // lab point / 10 (the slab then holds a broad light, as a real luminaire's).
  for (const auto& e : s.dataset.PhotosOf(0, 0)) {
    cv::Mat rgb(height, width, CV_32FC3);  // linear, at the photo's exposure, RGB
    ParallelFor(height, int(std::thread::hardware_concurrency()), [&](int y) {
      for (int x = 0; x < width; ++x) {
        const Eigen::Vector2d lab = s.calibration.ScreenFromImage(Eigen::Vector2d(x, y)) / 10;
        for (int c = 0; c < 3; ++c) {
          const double noise =
              0.003 * Hash(uint64_t(y) * width * 3 + x * 3 + c + (e.positive ? 0 : 1ULL << 40));
          const double v = e.exposure * s.Photo(0, 0, e.positive, c, lab.x(), lab.y()) + noise;
          rgb.at<cv::Vec3f>(y, x)[c] = float(std::clamp(v, 0.0, 1.0));
        }
      }
    });
    PhotoExif exif;
    exif.exposure_time = e.exposure / 100;
    exif.f_number = 1;
    exif.iso = 100;
    exif.make = "lumislab";
    exif.model = "bench camera";
    const std::string path = s.dataset.Path(e.file);
    if (format == CameraFormat::kDng) {
      DngInfo info;
      info.black_level = 512;
      info.white_level = 16383;
      info.exif = exif;
      cv::Mat mosaic(height, width, CV_16UC1);
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
          const int c = (y % 2 == 0) ? (x % 2 == 0 ? 0 : 1) : (x % 2 == 0 ? 1 : 2);  // RGGB
          const double v = rgb.at<cv::Vec3f>(y, x)[c];
          mosaic.at<uint16_t>(y, x) = uint16_t(std::lround(512 + v * (16383 - 512)));
        }
      WriteDng(path, mosaic, info);
      continue;
    }
    const bool jpeg = format == CameraFormat::kJpeg;
    cv::Mat bgr(height, width, jpeg ? CV_8UC3 : CV_16UC3);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        for (int c = 0; c < 3; ++c) {
          const double v = rgb.at<cv::Vec3f>(y, x)[c];
          if (jpeg)
            bgr.at<cv::Vec3b>(y, x)[2 - c] = uint8_t(std::lround(255 * Srgb(v)));
          else
            bgr.at<cv::Vec<uint16_t, 3>>(y, x)[2 - c] = uint16_t(std::lround(65535 * v));
        }
    if (jpeg)
      WriteJpeg(path, bgr, 95, exif);
    else
      WriteTiff(path, bgr, exif);
  }
}

}  // namespace lumislab::bench
