#include "lib/photo/photo_write.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "lib/photo/camera_write.h"
#include "lib/photo/image_codecs.h"
#include "lib/photo/jpeg_decode.h"

namespace lumislab {
namespace {

double LinearToSrgb(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
}

}  // namespace

void WriteImageFile(const std::string& path, const cv::Mat& image, int jpeg_quality) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (ext == ".tif" || ext == ".tiff") return WriteTiff(path, image, PhotoExif{});
  LUMISLAB_CHECK(ext == ".png" || ext == ".jpg" || ext == ".jpeg",
                 "WriteImageFile: a .png, .jpg or .tif path, got " + path);
  WriteAtomically(path, [&](const std::string& tmp) {
    if (ext == ".png") return EncodePng(tmp, image, path);
    const std::vector<unsigned char> jpeg = EncodeJpeg(image, jpeg_quality);
    std::ofstream file(tmp, std::ios::binary);
    file.write(reinterpret_cast<const char*>(jpeg.data()), std::streamsize(jpeg.size()));
    file.close();
    if (!file) throw IoError(path, "cannot write the JPEG");
  });
}

void WriteRgb8File(const std::string& path, int width, int height,
                   const std::vector<uint8_t>& rgb) {
  if (rgb.size() != size_t(width) * height * 3) throw Failure(path + ": RGB buffer size mismatch");
  cv::Mat bgr(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const uint8_t* p = &rgb[(size_t(y) * width + x) * 3];
      bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(p[2], p[1], p[0]);
    }
  WriteImageFile(path, bgr);
}

cv::Mat PhotoCodes(const ImageF& linear, PhotoEncoding encoding) {
  LUMISLAB_CHECK(linear.channels == 3 || linear.channels == 1, "PhotoCodes: 1 or 3 channels");
  const bool srgb = encoding == PhotoEncoding::kSrgb8Png;
  const bool eight_bit = srgb || encoding == PhotoEncoding::kCurve8Jpeg;
  const int type = eight_bit ? CV_8UC(linear.channels) : CV_16UC(linear.channels);
  const double max = eight_bit ? 255.0 : 65535.0;
  cv::Mat out(linear.height, linear.width, type);
  for (int y = 0; y < linear.height; ++y)
    for (int x = 0; x < linear.width; ++x)
      for (int c = 0; c < linear.channels; ++c) {
        const double v = linear.at(x, y, c);
        const double code = std::round((srgb ? LinearToSrgb(v) : std::clamp(v, 0.0, 1.0)) * max);
        const int oc = linear.channels == 3 ? 2 - c : 0;  // OpenCV stores BGR
        if (eight_bit)
          out.ptr<uint8_t>(y)[x * linear.channels + oc] = uint8_t(code);
        else
          out.ptr<uint16_t>(y)[x * linear.channels + oc] = uint16_t(code);
      }
  return out;
}

void WritePhoto(const std::string& path, const ImageF& linear, PhotoEncoding encoding,
                int jpeg_quality) {
  LUMISLAB_CHECK(linear.channels == 3 || linear.channels == 1, "WritePhoto: 1 or 3 channels");
  if (encoding == PhotoEncoding::kHalfExr || encoding == PhotoEncoding::kFloatExr ||
      encoding == PhotoEncoding::kFloatExrPiz) {
    ExrOptions options;
    options.half = encoding == PhotoEncoding::kHalfExr;
    options.compression = encoding == PhotoEncoding::kHalfExr       ? ExrCompression::kRle
                          : encoding == PhotoEncoding::kFloatExrPiz ? ExrCompression::kPiz
                                                                    : ExrCompression::kNone;
    const std::vector<std::string> names = linear.channels == 3
                                               ? std::vector<std::string>{"R", "G", "B"}
                                               : std::vector<std::string>{"Y"};
    WriteExr(path, linear, names, {}, options);
    return;
  }
  const cv::Mat out = PhotoCodes(linear, encoding);
  const bool jpeg = encoding == PhotoEncoding::kCurve8Jpeg;
  WriteImageFile(path, out, jpeg ? jpeg_quality : 95);
}

}  // namespace lumislab
