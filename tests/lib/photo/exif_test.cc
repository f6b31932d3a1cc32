// EXIF as the synthetic camera writes it (DNG through libtiff, JPEG through libexif) and as
// ReadPhotoExif reads it back (LibRaw for DNG, libexif for JPEG).
#include "lib/photo/exif.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lib/photo/camera_write.h"
#include "lib/photo/photo_io.h"
#include "lib/photo/photo_write.h"
#include "photo_test_util.h"

namespace lumislab {
namespace {

using testing::ScratchDir;
using testing::ThrowsBadInputNaming;

PhotoExif Shot() {
  PhotoExif exif;
  exif.exposure_time = 1.0 / 30;
  exif.f_number = 8;
  exif.iso = 200;
  exif.make = "LumisLab";
  exif.model = "SynthCam 1";
  exif.lens_model = "Pinhole 50 mm";
  exif.date_time = "2026:12:01 15:30:00";
  return exif;
}

cv::Mat Gradient() {
  cv::Mat bgr(24, 32, CV_8UC3);
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x) bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(x * 8, y * 10, 128);
  return bgr;
}

void ExpectShot(const PhotoExif& read, bool lens) {
  ASSERT_TRUE(read.exposure_time && read.f_number && read.iso);
  EXPECT_NEAR(*read.exposure_time, 1.0 / 30, 1e-6 / 30);
  EXPECT_NEAR(*read.f_number, 8, 1e-6);
  EXPECT_EQ(*read.iso, 200);
  EXPECT_EQ(read.make.value_or("?"), "LumisLab");
  EXPECT_EQ(read.model.value_or("?"), "SynthCam 1");
  if (lens) {
    EXPECT_EQ(read.lens_model.value_or("?"), "Pinhole 50 mm");
  }
  EXPECT_EQ(read.date_time.value_or("?"), "2026:12:01 15:30:00");
  ASSERT_TRUE(read.RelativeExposure());
  EXPECT_NEAR(*read.RelativeExposure(), (1.0 / 30) * 200 / 64, 1e-8);  // 0.1041667 s
}

TEST(Exif, DngRoundTrip) {
  const std::string dir = ScratchDir();
  DngInfo info;
  info.black_level = 512;
  info.white_level = 16383;
  info.exif = Shot();
  const std::string path = dir + "/shot.dng";
  WriteDng(path, cv::Mat(48, 64, CV_16UC1, cv::Scalar(4000)), info);  // LibRaw: >= 22 px
  const PhotoExif read = ReadPhotoExif(path);
  ExpectShot(read, /*lens=*/true);
  std::cout << "DNG: t = " << *read.exposure_time << " s, N = " << *read.f_number << ", ISO "
            << *read.iso << ", relative exposure " << *read.RelativeExposure() << ", lens "
            << read.lens_model.value_or("(none)") << "\n";
}

TEST(Exif, JpegRoundTrip) {
  const std::string dir = ScratchDir();
  const std::string path = dir + "/shot.jpg";
  WriteJpeg(path, Gradient(), 90, Shot());
  std::ifstream in(path, std::ios::binary);
  unsigned char head[4];
  in.read(reinterpret_cast<char*>(head), 4);
  EXPECT_EQ(head[2], 0xff);
  EXPECT_EQ(head[3], 0xe1) << "APP1 EXIF right after SOI";
  const PhotoExif read = ReadPhotoExif(path);
  ExpectShot(read, /*lens=*/true);
  const Photo photo = DecodePhoto(path);  // still an ordinary JPEG
  EXPECT_EQ(photo.format, PhotoFormat::kJpeg);
  EXPECT_EQ(photo.pixels.cols, 32);
  EXPECT_EQ(photo.pixels.rows, 24);
  // Quality 90 on a smooth gradient: within a few codes of the original.
  ASSERT_TRUE(photo.fractional_codes && photo.rgb_order);
  cv::Mat bgr, diff;
  cv::cvtColor(Codes8(photo), bgr, cv::COLOR_RGB2BGR);
  cv::absdiff(bgr, Gradient(), diff);
  double max_diff = 0;
  cv::minMaxLoc(diff.reshape(1), nullptr, &max_diff);
  EXPECT_LE(max_diff, 12);
  std::cout << "JPEG q90: max code difference " << max_diff << "\n";
}

TEST(Exif, Tiff16RoundTrip) {
  const std::string dir = ScratchDir();
  const std::string path = dir + "/shot.tif";
  cv::Mat bgr16;
  Gradient().convertTo(bgr16, CV_16UC3, 257);
  WriteTiff(path, bgr16, Shot());
  ExpectShot(ReadPhotoExif(path), /*lens=*/true);
  // A camera's TIFF names its maker but holds RGB, not a mosaic: OpenCV decodes it.
  EXPECT_EQ(DetectPhotoFormat(path), PhotoFormat::kTiff);
  const Photo photo = DecodePhoto(path);
  ASSERT_EQ(photo.pixels.type(), CV_16UC3);
  EXPECT_EQ(cv::norm(photo.pixels, bgr16, cv::NORM_INF), 0);  // lossless, same channel order
}

// The camera's geometry (focal length, orientation; acquire's camera.same_geometry) round-trips
// through each writer and reader: libexif (JPEG), libtiff (TIFF), LibRaw's focal_len and flip
// (DNG). Orientation 3 (turned 180 degrees) keeps the image size.
TEST(Exif, FocalLengthAndOrientationRoundTrip) {
  const std::string dir = ScratchDir();
  PhotoExif exif = Shot();
  exif.focal_length = 35;
  exif.orientation = 3;
  WriteJpeg(dir + "/shot.jpg", Gradient(), 90, exif);
  cv::Mat bgr16;
  Gradient().convertTo(bgr16, CV_16UC3, 257);
  WriteTiff(dir + "/shot.tif", bgr16, exif);
  DngInfo info;
  info.exif = exif;
  WriteDng(dir + "/shot.dng", cv::Mat(48, 64, CV_16UC1, cv::Scalar(4000)), info);
  for (const char* name : {"shot.jpg", "shot.tif", "shot.dng"}) {
    const PhotoExif read = ReadPhotoExif(dir + "/" + name);
    EXPECT_NEAR(read.focal_length.value_or(0), 35, 1e-4) << name;
    EXPECT_EQ(read.orientation.value_or(0), 3) << name;
  }
  // Not written: a JPEG states neither; a TIFF is upright (its Orientation tag is always there).
  WriteJpeg(dir + "/plain.jpg", Gradient(), 90, Shot());
  WriteTiff(dir + "/plain.tif", bgr16, Shot());
  EXPECT_FALSE(ReadPhotoExif(dir + "/plain.jpg").focal_length);
  EXPECT_FALSE(ReadPhotoExif(dir + "/plain.jpg").orientation);
  EXPECT_EQ(ReadPhotoExif(dir + "/plain.tif").orientation.value_or(0), 1);
}

TEST(Exif, JpegWithoutExifHasNoFields) {
  const std::string dir = ScratchDir();
  const std::string path = dir + "/plain.jpg";
  ASSERT_TRUE(cv::imwrite(path, Gradient()));
  const PhotoExif read = ReadPhotoExif(path);
  EXPECT_FALSE(read.exposure_time || read.f_number || read.iso || read.make || read.model ||
               read.lens_model || read.date_time);
  EXPECT_FALSE(read.RelativeExposure());
}

TEST(Exif, PartialExifGivesNulloptForMissingTags) {
  const std::string dir = ScratchDir();
  const std::string path = dir + "/partial.jpg";
  PhotoExif exif;
  exif.exposure_time = 0.5;
  exif.make = "LumisLab";
  WriteJpeg(path, Gradient(), 75, exif);
  const PhotoExif read = ReadPhotoExif(path);
  EXPECT_NEAR(read.exposure_time.value_or(0), 0.5, 1e-12);
  EXPECT_EQ(read.make.value_or("?"), "LumisLab");
  EXPECT_FALSE(read.f_number || read.iso || read.model || read.date_time);
  EXPECT_FALSE(read.RelativeExposure());
}

TEST(Exif, CorruptExifIsBadInputNamingTheFile) {
  const std::string dir = ScratchDir();
  const std::string good = dir + "/good.jpg";
  WriteJpeg(good, Gradient(), 90, Shot());
  std::ifstream in(good, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Bytes 6..11 are "Exif\0\0"; the TIFF header follows. Break its byte-order mark.
  ASSERT_EQ(bytes.substr(6, 4), std::string("Exif"));
  std::string broken = bytes;
  broken[12] = 'X';
  broken[13] = 'Y';
  const std::string path = dir + "/broken.jpg";
  std::ofstream(path, std::ios::binary).write(broken.data(), std::streamsize(broken.size()));
  std::string message;
  EXPECT_TRUE(ThrowsBadInputNaming([&] { ReadPhotoExif(path); }, path, &message)) << message;
  // IFD0 pointing past the segment.
  broken = bytes;
  broken[16] = '\xff';
  broken[17] = '\xff';
  const std::string far = dir + "/far.jpg";
  std::ofstream(far, std::ios::binary).write(broken.data(), std::streamsize(broken.size()));
  EXPECT_TRUE(ThrowsBadInputNaming([&] { ReadPhotoExif(far); }, far, &message)) << message;
  std::cout << message << "\n";
}

TEST(Exif, PngAndPlainTiffHaveNone) {
  const std::string dir = ScratchDir();
  const std::string path = dir + "/plain.png";
  WriteImageFile(path, Gradient());
  EXPECT_FALSE(ReadPhotoExif(path).make);
  const std::string tiff = dir + "/plain.tif";  // read through libtiff: no EXIF directory
  WriteImageFile(tiff, Gradient());
  const PhotoExif read = ReadPhotoExif(tiff);
  EXPECT_FALSE(read.exposure_time || read.f_number || read.iso || read.make || read.model);
  std::string message;
  const std::string missing = dir + "/missing.jpg";
  EXPECT_TRUE(ThrowsBadInputNaming([&] { ReadPhotoExif(missing); }, missing, &message));
}

}  // namespace
}  // namespace lumislab
