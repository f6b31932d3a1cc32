// Camera RAW through DecodePhoto, against known truth: a synthetic RGGB mosaic of linear values
// (black level 512, white level 16383) written as a DNG (WriteDng) and read back through LibRaw.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "lib/photo/camera_write.h"
#include "lib/photo/photo_io.h"
#include "lib/photo/photo_write.h"
#include "photo_test_util.h"

namespace lumislab {
namespace {

using testing::ScratchDir;
using testing::ThrowsBadInputNaming;

constexpr int kWidth = 64, kHeight = 48, kBlack = 512, kWhite = 16383;

// Linear truth per channel (R, G, B), affine in x and y, inside (0, 1).
double Truth(int c, int x, int y) {
  static const double base[3] = {0.1, 0.2, 0.05}, dx[3] = {0.005, 0.004, 0.002},
                      dy[3] = {0.003, 0.006, 0.01};
  return base[c] + dx[c] * x + dy[c] * y;
}
int BayerChannel(int x, int y) {
  return (y & 1) == 0 ? ((x & 1) == 0 ? 0 : 1) : ((x & 1) == 0 ? 1 : 2);
}

cv::Mat TruthMosaic() {
  cv::Mat mosaic(kHeight, kWidth, CV_16UC1);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      mosaic.at<uint16_t>(y, x) =
          uint16_t(std::lround(kBlack + Truth(BayerChannel(x, y), x, y) * (kWhite - kBlack)));
  return mosaic;
}

double Normalised(const cv::Mat& mosaic, int x, int y) {
  return (mosaic.at<uint16_t>(y, x) - double(kBlack)) / (kWhite - kBlack);
}

std::string WriteTruthDng(const std::string& dir, const cv::Mat& mosaic,
                          std::array<double, 3> neutral = {1, 1, 1}) {
  DngInfo info;
  info.black_level = kBlack;
  info.white_level = kWhite;
  info.as_shot_neutral = neutral;
  info.exif.make = "LumisLab";
  info.exif.model = "SynthCam 1";
  const std::string path = dir + "/shot.dng";
  WriteDng(path, mosaic, info);
  return path;
}

TEST(Raw, DngFullSizeUnityWhiteBalanceMatchesTruth) {
  const std::string dir = ScratchDir();
  const std::string path = WriteTruthDng(dir, TruthMosaic(), {0.5, 1, 0.8});
  EXPECT_EQ(DetectPhotoFormat(path), PhotoFormat::kRaw);
  const Photo photo = DecodePhoto(path);  // unity white balance by default
  ASSERT_EQ(photo.pixels.type(), CV_32FC3);
  ASSERT_EQ(photo.pixels.cols, kWidth);
  ASSERT_EQ(photo.pixels.rows, kHeight);
  EXPECT_TRUE(photo.UnityWhiteBalance());
  const LinearReader reader(photo);
  double max_error = 0;
  // Bilinear demosaic is exact for affine values wherever the 3x3 window is whole.
  for (int y = 1; y < kHeight - 1; ++y)
    for (int x = 1; x < kWidth - 1; ++x) {
      float rgb[3];
      bool clipped[3];
      reader.Read(y, x, rgb, clipped);
      for (int c = 0; c < 3; ++c) {
        max_error = std::max(max_error, std::abs(rgb[c] - Truth(c, x, y)));
        EXPECT_FALSE(clipped[c]);
      }
    }
  EXPECT_LT(max_error, 1e-3);
  std::cout << "full size, unity WB: max |decoded - truth| = " << max_error << "\n";
  // The samples themselves are the file's codes with black and white level applied.
  const cv::Mat mosaic = TruthMosaic();
  double max_sample_error = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const int c = BayerChannel(x, y);
      max_sample_error = std::max(max_sample_error, std::abs(photo.pixels.at<cv::Vec3f>(y, x)[c] -
                                                             Normalised(mosaic, x, y)));
    }
  EXPECT_LT(max_sample_error, 1e-6);
  std::cout << "full size: max |sample - (code - 512) / 15871| = " << max_sample_error << "\n";
}

TEST(Raw, DngHalfSizeIsExactQuadAverage) {
  const std::string dir = ScratchDir();
  const cv::Mat mosaic = TruthMosaic();
  const std::string path = WriteTruthDng(dir, mosaic);
  PhotoSpec spec;
  spec.raw_half_size = true;
  const Photo photo = DecodePhoto(path, spec);
  ASSERT_EQ(photo.pixels.cols, kWidth / 2);
  ASSERT_EQ(photo.pixels.rows, kHeight / 2);
  const LinearReader reader(photo);
  double max_error = 0;
  for (int y = 0; y < kHeight / 2; ++y)
    for (int x = 0; x < kWidth / 2; ++x) {
      float rgb[3];
      bool clipped[3];
      reader.Read(y, x, rgb, clipped);
      const double expected[3] = {
          Normalised(mosaic, 2 * x, 2 * y),
          (Normalised(mosaic, 2 * x + 1, 2 * y) + Normalised(mosaic, 2 * x, 2 * y + 1)) / 2,
          Normalised(mosaic, 2 * x + 1, 2 * y + 1)};
      for (int c = 0; c < 3; ++c) max_error = std::max(max_error, std::abs(rgb[c] - expected[c]));
    }
  EXPECT_LT(max_error, 1e-6);
  std::cout << "half size: max |decoded - 2x2 average| = " << max_error << "\n";
}

TEST(Raw, AsShotWhiteBalanceAppliesMultipliersAfterClipping) {
  const std::string dir = ScratchDir();
  cv::Mat mosaic = TruthMosaic();
  mosaic.at<uint16_t>(0, 0) = kWhite;                                      // a clipped red sample
  mosaic.at<uint16_t>(1, 1) = uint16_t(kBlack + 0.9 * (kWhite - kBlack));  // blue, not clipped
  const std::string path = WriteTruthDng(dir, mosaic, {0.5, 1, 0.8});
  PhotoSpec unity, as_shot;
  unity.raw_half_size = as_shot.raw_half_size = true;
  as_shot.raw_white_balance = RawWhiteBalance::kAsShot;
  const Photo plain = DecodePhoto(path, unity), balanced = DecodePhoto(path, as_shot);
  EXPECT_NEAR(balanced.white_balance[0], 2.0, 1e-5);  // 1 / AsShotNeutral
  EXPECT_NEAR(balanced.white_balance[1], 1.0, 1e-6);
  EXPECT_NEAR(balanced.white_balance[2], 1.25, 1e-5);
  EXPECT_FALSE(balanced.UnityWhiteBalance());
  const LinearReader a(plain), b(balanced);
  double max_error = 0;
  for (int y = 0; y < kHeight / 2; ++y)
    for (int x = 0; x < kWidth / 2; ++x) {
      float u[3], w[3];
      bool cu[3], cw[3];
      a.Read(y, x, u, cu);
      b.Read(y, x, w, cw);
      const double mul[3] = {2.0, 1.0, 1.25};
      for (int c = 0; c < 3; ++c) {
        max_error = std::max(max_error, std::abs(w[c] - u[c] * mul[c]) / std::max(u[c], 1e-3f));
        EXPECT_EQ(cu[c], cw[c]) << "white balance must not change which samples are clipped";
      }
    }
  EXPECT_LT(max_error, 1e-5);
  float rgb[3];
  bool clipped[3];
  b.Read(0, 0, rgb, clipped);
  EXPECT_TRUE(clipped[0]);   // the sensor clipped red
  EXPECT_FALSE(clipped[2]);  // blue 0.9 x 1.25 = 1.125 > 1, but the sensor did not clip it
  EXPECT_NEAR(rgb[2], 0.9 * 1.25, 1e-4);
  std::cout << "as shot: multipliers " << balanced.white_balance[0] << " "
            << balanced.white_balance[1] << " " << balanced.white_balance[2]
            << ", max relative error " << max_error << "\n";
}

// A clipped sample leaves the values interpolated from it unknown: the demosaic flags them as
// clipped (a hot or saturated red site at (4, 4) spoils the red of its 8 neighbours, which
// otherwise read as a plausible, too dark value and passed into the merge).
TEST(Raw, DemosaicedValuesFromAClippedSampleCountAsClipped) {
  const std::string dir = ScratchDir();
  cv::Mat mosaic = TruthMosaic();
  mosaic.at<uint16_t>(4, 4) = kWhite;  // red site (even row, even column)
  const Photo photo = DecodePhoto(WriteTruthDng(dir, mosaic));
  const LinearReader reader(photo);
  int clipped_red = 0, clipped_other = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      float rgb[3];
      bool clipped[3];
      reader.Read(y, x, rgb, clipped);
      const bool near = std::abs(x - 4) <= 1 && std::abs(y - 4) <= 1;
      EXPECT_EQ(clipped[0], near) << "red at " << x << "," << y;
      clipped_red += clipped[0];
      clipped_other += clipped[1] + clipped[2];
    }
  EXPECT_EQ(clipped_red, 9);
  EXPECT_EQ(clipped_other, 0);  // green and blue did not use the site
  // Half size: the quad holding the site has its red clipped, no other quad.
  PhotoSpec half;
  half.raw_half_size = true;
  const Photo quads = DecodePhoto(WriteTruthDng(dir, mosaic), half);
  const LinearReader quad_reader(quads);
  float rgb[3];
  bool clipped[3];
  quad_reader.Read(2, 2, rgb, clipped);
  EXPECT_TRUE(clipped[0]);
  quad_reader.Read(2, 3, rgb, clipped);
  EXPECT_FALSE(clipped[0]);
}

// Sets a LONG value held in IFD0 (little-endian TIFF) and returns the old one.
uint32_t PatchLong(std::string& bytes, uint16_t tag, uint32_t value);

TEST(Raw, TruncatedDngIsBadInputNamingTheFile) {
  const std::string dir = ScratchDir();
  const std::string full = WriteTruthDng(dir, TruthMosaic());
  std::ifstream in(full, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // libtiff writes IFD0 after the pixels: a cut file has lost its DNG tags and is a corrupt TIFF.
  for (const double keep : {0.5, 0.1}) {
    const std::string path = dir + "/cut_" + std::to_string(int(keep * 100)) + ".dng";
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size() * keep));
    std::string message;
    EXPECT_TRUE(ThrowsBadInputNaming([&] { DecodePhoto(path); }, path, &message)) << message;
    std::cout << "cut to " << keep << ": " << message << "\n";
  }
  // Tags intact, pixel data running past the end of the file (a camera's file cut short): the
  // strip starts 100 bytes before the end.
  std::string short_data = bytes;
  PatchLong(short_data, 273, uint32_t(bytes.size() - 100));
  const std::string path = dir + "/short_data.dng";
  std::ofstream(path, std::ios::binary).write(short_data.data(), std::streamsize(bytes.size()));
  EXPECT_EQ(DetectPhotoFormat(path), PhotoFormat::kRaw);
  std::string message;
  EXPECT_TRUE(ThrowsBadInputNaming([&] { DecodePhoto(path); }, path, &message)) << message;
  std::cout << "data cut short: " << message << "\n";
}

// Patches IFD0's ImageWidth and ImageLength (SHORT values in a little-endian TIFF).
void PatchSize(std::string& bytes, uint16_t width, uint16_t height) {
  auto u16 = [&](size_t at) { return uint16_t(uint8_t(bytes[at]) | uint8_t(bytes[at + 1]) << 8); };
  const size_t ifd = uint8_t(bytes[4]) | uint8_t(bytes[5]) << 8 | uint8_t(bytes[6]) << 16 |
                     size_t(uint8_t(bytes[7])) << 24;
  for (int k = 0; k < u16(ifd); ++k) {
    const size_t entry = ifd + 2 + 12 * size_t(k);
    const uint16_t tag = u16(entry), type = u16(entry + 2);
    if ((tag == 256 || tag == 257) && type == 3) {
      const uint16_t v = tag == 256 ? width : height;
      bytes[entry + 8] = char(v & 0xff);
      bytes[entry + 9] = char(v >> 8);
    }
  }
}

uint32_t PatchLong(std::string& bytes, uint16_t tag, uint32_t value) {
  auto u16 = [&](size_t at) { return uint16_t(uint8_t(bytes[at]) | uint8_t(bytes[at + 1]) << 8); };
  const size_t ifd = uint8_t(bytes[4]) | uint8_t(bytes[5]) << 8 | uint8_t(bytes[6]) << 16 |
                     size_t(uint8_t(bytes[7])) << 24;
  for (int k = 0; k < u16(ifd); ++k) {
    const size_t entry = ifd + 2 + 12 * size_t(k);
    if (u16(entry) != tag || u16(entry + 2) != 4) continue;
    uint32_t old = 0;
    for (int b = 0; b < 4; ++b) {
      old |= uint32_t(uint8_t(bytes[entry + 8 + b])) << (8 * b);
      bytes[entry + 8 + b] = char(value >> (8 * b) & 0xff);
    }
    return old;
  }
  ADD_FAILURE() << "no LONG tag " << tag << " in IFD0";
  return 0;
}

TEST(Raw, GarbageClaimingDngIsBadInputWithoutHugeAllocation) {
  const std::string dir = ScratchDir();
  const std::string good = WriteTruthDng(dir, TruthMosaic());
  std::ifstream in(good, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  rusage before{};
  getrusage(RUSAGE_SELF, &before);
  // A DNG header claiming 60000 x 60000 pixels (3.6e9 > kMaxPhotoPixels) over 6 KB of data.
  std::string huge = bytes;
  PatchSize(huge, 60000, 60000);
  const std::string huge_path = dir + "/huge.dng";
  std::ofstream(huge_path, std::ios::binary).write(huge.data(), std::streamsize(huge.size()));
  std::string message;
  EXPECT_TRUE(ThrowsBadInputNaming([&] { DecodePhoto(huge_path); }, huge_path, &message))
      << message;
  std::cout << "huge: " << message << "\n";
  // The DNG's header followed by garbage where the IFD and data were.
  std::string garbage = bytes.substr(0, 8);
  uint32_t state = 12345;
  for (int k = 0; k < 4096; ++k) garbage += char((state = state * 1103515245u + 12345u) >> 24);
  const std::string garbage_path = dir + "/garbage.dng";
  std::ofstream(garbage_path, std::ios::binary)
      .write(garbage.data(), std::streamsize(garbage.size()));
  EXPECT_TRUE(ThrowsBadInputNaming([&] { DecodePhoto(garbage_path); }, garbage_path, &message))
      << message;
  std::cout << "garbage: " << message << "\n";
  rusage after{};
  getrusage(RUSAGE_SELF, &after);
  EXPECT_LT(after.ru_maxrss - before.ru_maxrss, 100 * 1024) << "kB of peak memory";
}

TEST(Raw, PlainTiffStaysWithOpenCv) {
  const std::string dir = ScratchDir();
  const std::string path = dir + "/plain.tif";
  WriteImageFile(path, cv::Mat(4, 6, CV_16UC3, cv::Scalar(1000, 2000, 3000)));
  EXPECT_EQ(DetectPhotoFormat(path), PhotoFormat::kTiff);
  const Photo photo = DecodePhoto(path);
  EXPECT_EQ(photo.pixels.type(), CV_16UC3);
}

}  // namespace
}  // namespace lumislab
