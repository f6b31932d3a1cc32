// The colour JPEG decoder (lib/photo/jpeg_decode.h): the same picture as OpenCV's decoder, less
// the rounding of the colour conversion; truncated files refused; other JPEGs left to OpenCV.
// Also the reading of its fractional codes (ReadBetweenCodes, FractionalCodeTable) and its images'
// buffers (NewPhotoImage).
#include "lib/photo/jpeg_decode.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "lib/photo/photo_allocator.h"
#include "lib/photo/photo_io.h"
#include "photo_test_util.h"

namespace lumislab {
namespace {

using testing::ScratchDir;
using testing::ThrowsBadInputNaming;

// The sRGB curve (IEC 61966-2-1), as the decoder's tables hold it.
float SrgbToLinear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

// A smooth colour picture with noise, as a camera's JPEG holds (BGR).
cv::Mat Picture() {
  cv::Mat bgr(48, 64, CV_8UC3);
  cv::RNG rng(7);
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x)
      for (int c = 0; c < 3; ++c)
        bgr.at<cv::Vec3b>(y, x)[c] =
            cv::saturate_cast<uint8_t>(40 + 2.5 * x + (c + 1) * y + rng.gaussian(2.0));
  return bgr;
}

TEST(JpegDecode, OpenCvsPictureWithTheConversionsFractions) {
  const std::string path = ScratchDir() + "/p.jpg";
  ASSERT_TRUE(cv::imwrite(path, Picture(), {cv::IMWRITE_JPEG_QUALITY, 95}));
  const DecodedJpeg decoded = DecodeJpeg(path);
  ASSERT_TRUE(decoded.fractional);
  const cv::Mat& fixed = decoded.pixels;
  ASSERT_EQ(fixed.type(), CV_16UC3);  // code x 256
  cv::Mat ours;
  fixed.convertTo(ours, CV_32F, 1.0 / kFractionalCodeOne);
  cv::Mat opencv = cv::imread(path), opencv_rgb, opencv_f;
  cv::cvtColor(opencv, opencv_rgb, cv::COLOR_BGR2RGB);
  opencv_rgb.convertTo(opencv_f, CV_32F);
  // OpenCV (libjpeg's integer tables) rounds the same conversion: within about half a code
  // (and half a step of the fixed point).
  cv::Mat diff = cv::abs(ours - opencv_f);
  double max_diff = 0;
  cv::minMaxLoc(diff.reshape(1), nullptr, &max_diff);
  EXPECT_LE(max_diff, 0.51 + 0.5 / kFractionalCodeOne + 1e-3);
  // Codes8 (the detectors' and the response fit's codes) rounds them to OpenCV's codes but for
  // the conversion's own rounding: within one code.
  cv::Mat codes8_diff;
  cv::absdiff(Codes8(DecodePhoto(path)), opencv_rgb, codes8_diff);
  cv::minMaxLoc(codes8_diff.reshape(1), nullptr, &max_diff);
  EXPECT_LE(max_diff, 1);
  // And the fractions are there: a code is rarely whole.
  int whole = 0;
  const cv::Mat values = ours.reshape(1);
  for (int y = 0; y < values.rows; ++y)
    for (int x = 0; x < values.cols; ++x)
      whole += values.at<float>(y, x) == std::floor(values.at<float>(y, x));
  EXPECT_LT(whole, int(ours.total()));  // of 3 x total values
  std::printf("whole codes: %d of %d values\n", whole, int(3 * ours.total()));
  // DecodePhoto takes them as 8-bit codes, read through the sRGB curve between codes.
  const Photo photo = DecodePhoto(path);
  EXPECT_TRUE(photo.fractional_codes);
  EXPECT_TRUE(photo.EightBitCodes());
  EXPECT_EQ(photo.CodeBits(), 8);
  EXPECT_EQ(photo.CodeMax(), 255);
  EXPECT_EQ(photo.transfer, Transfer::kSrgb);
  const LinearReader reader(photo);
  float rgb[3];
  bool clipped[3];
  reader.Read(10, 20, rgb, clipped);
  const cv::Vec3f code = ours.at<cv::Vec3f>(10, 20);
  for (int c = 0; c < 3; ++c) {
    const int k = int(code[c]);
    const float f = code[c] - k;
    const float expect =
        SrgbToLinear(k / 255.f) + f * (SrgbToLinear((k + 1) / 255.f) - SrgbToLinear(k / 255.f));
    EXPECT_NEAR(rgb[c], expect, 1e-6) << c;
    EXPECT_FALSE(clipped[c]);
  }
}

// A grey JPEG's codes are stored as such: they come back as OpenCV's decoder gives them.
TEST(JpegDecode, GrayJpegGivesItsCodesAsStored) {
  const std::string path = ScratchDir() + "/g.jpg";
  cv::Mat gray;
  cv::cvtColor(Picture(), gray, cv::COLOR_BGR2GRAY);
  ASSERT_TRUE(cv::imwrite(path, gray));
  const DecodedJpeg decoded = DecodeJpeg(path);
  EXPECT_FALSE(decoded.fractional);
  const Photo photo = DecodePhoto(path);
  EXPECT_FALSE(photo.fractional_codes);
  ASSERT_EQ(photo.pixels.type(), CV_8UC1);
  EXPECT_EQ(cv::norm(photo.pixels, cv::imread(path, cv::IMREAD_UNCHANGED), cv::NORM_INF), 0);
}

TEST(JpegDecode, TruncatedJpegIsRefusedNamingIt) {
  const std::string path = ScratchDir() + "/t.jpg";
  ASSERT_TRUE(cv::imwrite(path, Picture(), {cv::IMWRITE_JPEG_QUALITY, 95}));
  std::filesystem::resize_file(path, std::filesystem::file_size(path) / 2);
  std::string message;
  EXPECT_TRUE(ThrowsBadInputNaming([&] { DecodePhoto(path); }, path, &message));
  EXPECT_NE(message.find("JPEG"), std::string::npos) << message;
}

// Between codes the table is read linearly; at a whole code its entry is returned exactly, even
// where the next code up is clipped (NaN), which a code above the whole one reads.
TEST(ReadBetweenCodes, LinearBetweenCodesExactAtWholeCodes) {
  std::vector<float> table(256);
  for (int k = 0; k < 256; ++k) table[k] = 0.001f * float(k * k) + 0.1f;
  table[201] = std::numeric_limits<float>::quiet_NaN();  // clipped from code 201 up
  for (int k = 0; k < 200; ++k) {
    EXPECT_EQ(ReadBetweenCodes(table.data(), uint16_t(k * kFractionalCodeOne)), table[k]);
    const float half = ReadBetweenCodes(table.data(), uint16_t(k * kFractionalCodeOne + 128));
    EXPECT_NEAR(half, 0.5f * (table[k] + table[k + 1]), 1e-6f * table[k + 1]) << k;
  }
  EXPECT_EQ(ReadBetweenCodes(table.data(), uint16_t(200 * kFractionalCodeOne)), table[200]);
  EXPECT_TRUE(std::isnan(ReadBetweenCodes(table.data(), uint16_t(200 * kFractionalCodeOne + 1))));
  EXPECT_EQ(ReadBetweenCodes(table.data(), uint16_t(255 * kFractionalCodeOne)), table[255]);
}

// The precomputed table gives what ReadBetweenCodes gives at every fractional code, bit for bit
// (NaN where it reads a clipped code), and the value at code 255 above the largest code.
TEST(FractionalCodeTable, EveryCodeAsReadBetweenCodes) {
  std::vector<float> table(256);
  for (int k = 0; k < 256; ++k) table[k] = 0.001f * float(k * k) + 0.1f;
  table[201] = std::numeric_limits<float>::quiet_NaN();  // clipped from code 201 up
  const std::vector<float> entries = FractionalCodeTable(table.data());
  ASSERT_EQ(entries.size(), size_t(kFractionalCodeTable));
  int nan = 0;
  for (int c = 0; c <= 255 * kFractionalCodeOne; ++c) {
    const float expected = ReadBetweenCodes(table.data(), uint16_t(c));
    if (std::isnan(expected)) {
      ++nan;
      EXPECT_TRUE(std::isnan(entries[c])) << c;
    } else {
      EXPECT_EQ(std::memcmp(&entries[c], &expected, sizeof(float)), 0) << c;
    }
  }
  EXPECT_EQ(nan, 2 * kFractionalCodeOne - 1);  // (200, 202): 200 + f and 201 + f read code 201
  for (int c = 255 * kFractionalCodeOne + 1; c < kFractionalCodeTable; ++c)
    EXPECT_EQ(entries[c], table[255]) << c;
}

// A large image's buffer (>= 4 MB) is kept when released and given to the next image of the
// same size (no fresh pages for the kernel to zero); one of another size gets its own buffer.
TEST(NewPhotoImage, ReleasedLargeBufferServesTheNextImageOfItsSize) {
  cv::Mat a = NewPhotoImage(1000, 1500, CV_16UC3);  // 9 MB
  a.setTo(cv::Scalar::all(7));
  const uchar* data = a.data;
  a.release();
  cv::Mat b = NewPhotoImage(1000, 1500, CV_16UC3);
  EXPECT_EQ(b.data, data);
  // The same pages, not fresh (zeroed) ones at the same address: a's values are still there.
  EXPECT_EQ(b.at<cv::Vec3w>(0, 0)[0], 7);
  EXPECT_EQ(b.at<cv::Vec3w>(999, 1499)[2], 7);
  cv::Mat c = NewPhotoImage(1000, 1600, CV_16UC3);
  EXPECT_NE(c.data, data);
  EXPECT_EQ(c.total(), size_t(1000) * 1600);
  // Both in use at once: two buffers.
  cv::Mat d = NewPhotoImage(1000, 1500, CV_16UC3);
  EXPECT_NE(d.data, b.data);
}

// PNG, TIFF and grey JPEG photos are OpenCV's decode (cv::imdecode of the file's bytes): the same
// pixels as cv::imread, bit for bit (an alpha channel dropped), and a large photo lies in
// NewPhotoImage's buffers: released, its buffer serves the next photo of its size. A truncated
// TIFF is refused naming the file.
TEST(NewPhotoImage, OpenCvPhotosAsImreadInKeptBuffers) {
  const std::string dir = ScratchDir();
  cv::Mat big(1000, 1100, CV_16UC3);  // 6.6 MB: a kept buffer
  cv::randu(big, 0, 65536);
  cv::Mat bgra(40, 50, CV_8UC4), gray;
  cv::randu(bgra, 0, 256);
  cv::cvtColor(Picture(), gray, cv::COLOR_BGR2GRAY);
  const std::vector<std::pair<std::string, cv::Mat>> files = {{dir + "/big.tif", big},
                                                              {dir + "/big.png", big},
                                                              {dir + "/a.png", bgra},
                                                              {dir + "/g.jpg", gray}};
  for (const auto& [path, image] : files) {
    ASSERT_TRUE(cv::imwrite(path, image)) << path;
    cv::Mat expected = cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR);
    if (expected.channels() == 4) cv::cvtColor(expected, expected, cv::COLOR_BGRA2BGR);
    Photo photo = DecodePhoto(path);
    ASSERT_EQ(photo.pixels.type(), expected.type()) << path;
    ASSERT_EQ(photo.pixels.size(), expected.size()) << path;
    EXPECT_EQ(cv::norm(photo.pixels, expected, cv::NORM_INF), 0) << path;
    if (path.find("big") == std::string::npos) continue;
    const uchar* data = photo.pixels.data;
    photo = Photo();
    EXPECT_EQ(DecodePhoto(path).pixels.data, data) << path;
  }
  const std::string truncated = dir + "/t.tif";
  std::filesystem::copy_file(dir + "/big.tif", truncated,
                             std::filesystem::copy_options::overwrite_existing);
  std::filesystem::resize_file(truncated, std::filesystem::file_size(truncated) / 2);
  std::string message;
  EXPECT_TRUE(ThrowsBadInputNaming([&] { DecodePhoto(truncated); }, truncated, &message))
      << message;
}

}  // namespace
}  // namespace lumislab
