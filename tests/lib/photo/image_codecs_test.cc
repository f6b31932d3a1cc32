// lib/photo's PNG, TIFF and JPEG codecs (lib/photo/image_codecs.h, jpeg_decode.h: libpng, libtiff
// and libjpeg, not OpenCV's imgcodecs): every layout a camera or an image tool writes decodes to
// the pixels that were written, in OpenCV's conventions (B, G, R; host byte order), as OpenCV's own
// decoder gives them; the writers' files read back through OpenCV; the JPEG encoder writes OpenCV's
// bytes; what lumislab does not read is refused naming the file and the field.
#include "lib/photo/image_codecs.h"

#include <gtest/gtest.h>
#include <jpeglib.h>
#include <png.h>
#include <tiffio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "core/error.h"
#include "lib/photo/jpeg_decode.h"
#include "lib/photo/photo_io.h"
#include "lib/photo/photo_write.h"
#include "photo_test_util.h"

namespace lumislab {
namespace {

using testing::ScratchDir;
using testing::ThrowsBadInputNaming;

// A picture whose every sample differs from its neighbours' (rows, columns and channels are told
// apart), of `type` (8 or 16 bits, 1, 3 or 4 channels, B, G, R, A); 16-bit samples use both bytes.
cv::Mat Picture(int type, int rows = 37, int cols = 53) {
  cv::Mat m(rows, cols, type);
  const int channels = m.channels();
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x)
      for (int c = 0; c < channels; ++c) {
        const int v = (x * 7 + y * 131 + c * 61) % 256;
        if (m.depth() == CV_8U)
          m.ptr<uint8_t>(y)[x * channels + c] = uint8_t(v);
        else
          m.ptr<uint16_t>(y)[x * channels + c] = uint16_t(v * 257 + (x + c) % 200);
      }
  return m;
}

// The first 1 or 3 channels (what the decoder keeps of an image with alpha).
cv::Mat WithoutAlpha(const cv::Mat& m) {
  if (m.channels() != 4 && m.channels() != 2) return m;
  cv::Mat out;
  std::vector<cv::Mat> planes;
  cv::split(m, planes);
  planes.pop_back();
  cv::merge(planes, out);
  return out;
}

::testing::AssertionResult SameImage(const cv::Mat& a, const cv::Mat& b) {
  if (a.type() != b.type() || a.size() != b.size())
    return ::testing::AssertionFailure()
           << "type " << a.type() << " vs " << b.type() << ", " << a.cols << "x" << a.rows << " vs "
           << b.cols << "x" << b.rows;
  const double d = cv::norm(a, b, cv::NORM_INF);
  if (d != 0) return ::testing::AssertionFailure() << "largest difference " << d;
  return ::testing::AssertionSuccess();
}

// Writes `bgr` (8 or 16 bits, 1 or 3 channels) with libtiff in a layout OpenCV's writer does not
// make: tiled or strips, contiguous or planar, in the byte order of `mode` ("w" little, "wb"
// big-endian), with `extra` alpha samples of 0.
void WriteTiffLayout(const std::string& path, const cv::Mat& bgr, const char* mode, bool tiled,
                     bool planar, int extra = 0, uint16_t compression = COMPRESSION_NONE,
                     uint16_t orientation = ORIENTATION_TOPLEFT) {
  TIFF* tif = TIFFOpen(path.c_str(), mode);
  ASSERT_NE(tif, nullptr);
  const int channels = bgr.channels(), samples = channels + extra;
  const int bytes = int(bgr.elemSize1());
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, uint32_t(bgr.cols));
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, uint32_t(bgr.rows));
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, bytes * 8);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, samples);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, channels == 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, planar ? PLANARCONFIG_SEPARATE : PLANARCONFIG_CONTIG);
  TIFFSetField(tif, TIFFTAG_COMPRESSION, compression);
  TIFFSetField(tif, TIFFTAG_ORIENTATION, orientation);
  if (extra) {
    const uint16_t kinds[1] = {EXTRASAMPLE_UNASSALPHA};
    TIFFSetField(tif, TIFFTAG_EXTRASAMPLES, uint16_t(1), kinds);
  }
  // The value of sample s (R, G, B order in the file) of pixel (x, y).
  auto sample = [&](int y, int x, int s) -> uint32_t {
    if (s >= channels) return 0;
    const int c = channels == 3 ? 2 - s : s;
    return bytes == 1 ? bgr.ptr<uint8_t>(y)[x * channels + c]
                      : bgr.ptr<uint16_t>(y)[x * channels + c];
  };
  auto put = [&](std::vector<uint8_t>& buf, size_t at, uint32_t v) {
    if (bytes == 1)
      buf[at] = uint8_t(v);
    else
      std::memcpy(&buf[at * 2], &v, 2);  // host order: libtiff swaps for a big-endian file
  };
  const int planes = planar ? samples : 1, stride = planar ? 1 : samples;
  if (tiled) {
    const uint32_t tw = 16, th = 16;
    TIFFSetField(tif, TIFFTAG_TILEWIDTH, tw);
    TIFFSetField(tif, TIFFTAG_TILELENGTH, th);
    std::vector<uint8_t> tile(size_t(tw) * th * stride * bytes);
    for (int p = 0; p < planes; ++p)
      for (uint32_t ty = 0; ty < uint32_t(bgr.rows); ty += th)
        for (uint32_t tx = 0; tx < uint32_t(bgr.cols); tx += tw) {
          std::fill(tile.begin(), tile.end(), 0);
          for (uint32_t y = 0; y < th && ty + y < uint32_t(bgr.rows); ++y)
            for (uint32_t x = 0; x < tw && tx + x < uint32_t(bgr.cols); ++x)
              for (int s = 0; s < stride; ++s)
                put(tile, (size_t(y) * tw + x) * stride + s,
                    sample(int(ty + y), int(tx + x), planar ? p : s));
          ASSERT_GE(TIFFWriteEncodedTile(tif, TIFFComputeTile(tif, tx, ty, 0, uint16_t(p)),
                                         tile.data(), tmsize_t(tile.size())),
                    0);
        }
  } else {
    TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, 5);
    std::vector<uint8_t> line(size_t(bgr.cols) * stride * bytes);
    for (int p = 0; p < planes; ++p)
      for (int y = 0; y < bgr.rows; ++y) {
        for (int x = 0; x < bgr.cols; ++x)
          for (int s = 0; s < stride; ++s)
            put(line, size_t(x) * stride + s, sample(y, x, planar ? p : s));
        ASSERT_EQ(TIFFWriteScanline(tif, line.data(), uint32_t(y), uint16_t(p)), 1);
      }
  }
  TIFFClose(tif);
}

TEST(ImageCodecs, PngOfEveryDepthAndChannelCountDecodesToItsPixels) {
  const std::string dir = ScratchDir();
  for (int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    const cv::Mat picture = Picture(type);
    const std::string path = dir + "/p" + std::to_string(type) + ".png";
    ASSERT_TRUE(cv::imwrite(path, picture));
    const Photo photo = DecodePhoto(path);
    EXPECT_TRUE(SameImage(photo.pixels, WithoutAlpha(picture))) << type;
    EXPECT_TRUE(
        SameImage(photo.pixels, cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR)))
        << type;
  }
}

// A palette PNG, an interlaced one and a 1-bit grey one (no OpenCV writer makes the first two),
// through libpng: the codes as OpenCV's decoder expands them.
TEST(ImageCodecs, PalettedInterlacedAndOneBitPngsAreExpanded) {
  const std::string dir = ScratchDir();
  struct Case {
    const char* name;
    int colour_type, bit_depth, interlace;
  };
  for (const Case& c : {Case{"palette", PNG_COLOR_TYPE_PALETTE, 8, PNG_INTERLACE_NONE},
                        Case{"adam7", PNG_COLOR_TYPE_RGB, 16, PNG_INTERLACE_ADAM7},
                        Case{"bilevel", PNG_COLOR_TYPE_GRAY, 1, PNG_INTERLACE_NONE}}) {
    const std::string path = dir + "/" + c.name + ".png";
    const int w = 21, h = 13;
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(png);
    png_init_io(png, f);
    png_set_IHDR(png, info, w, h, c.bit_depth, c.colour_type, c.interlace,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    std::vector<png_color> palette(16);
    for (int k = 0; k < 16; ++k)
      palette[k] = {png_byte(k * 16), png_byte(255 - k * 16), png_byte(k * 5)};
    if (c.colour_type == PNG_COLOR_TYPE_PALETTE)
      png_set_PLTE(png, info, palette.data(), int(palette.size()));
    png_write_info(png, info);
    const int row_bytes = int(png_get_rowbytes(png, info));
    std::vector<std::vector<png_byte>> rows(h, std::vector<png_byte>(size_t(row_bytes)));
    cv::Mat expect(h, w,
                   c.colour_type == PNG_COLOR_TYPE_GRAY ? CV_8UC1
                   : c.bit_depth == 16                  ? CV_16UC3
                                                        : CV_8UC3);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (c.colour_type == PNG_COLOR_TYPE_PALETTE) {
          const int k = (x + 3 * y) % 16;
          rows[y][x] = png_byte(k);
          expect.at<cv::Vec3b>(y, x) = {palette[k].blue, palette[k].green, palette[k].red};
        } else if (c.bit_depth == 1) {
          const bool on = (x * y + x) % 3 == 0;
          if (on) rows[y][x / 8] |= png_byte(0x80 >> (x % 8));
          expect.at<uint8_t>(y, x) = on ? 255 : 0;
        } else {
          for (int s = 0; s < 3; ++s) {
            const uint16_t v = uint16_t(x * 3001 + y * 17 + s * 20011);
            rows[y][(x * 3 + s) * 2] = png_byte(v >> 8);  // PNG: big-endian
            rows[y][(x * 3 + s) * 2 + 1] = png_byte(v & 255);
            expect.at<cv::Vec3w>(y, x)[2 - s] = v;
          }
        }
      }
    std::vector<png_bytep> pointers;
    for (auto& r : rows) pointers.push_back(r.data());
    png_write_image(png, pointers.data());
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    const Photo photo = DecodePhoto(path);
    EXPECT_TRUE(SameImage(photo.pixels, expect)) << c.name;
    EXPECT_TRUE(
        SameImage(photo.pixels, cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR)))
        << c.name;
  }
}

TEST(ImageCodecs, TiffOfEveryLayoutDecodesToItsPixels) {
  const std::string dir = ScratchDir();
  int n = 0;
  // OpenCV's writer: uncompressed, LZW and Deflate; grey, RGB and RGBA; 8 and 16 bits.
  for (int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4})
    for (int compression : {COMPRESSION_NONE, COMPRESSION_LZW, COMPRESSION_ADOBE_DEFLATE}) {
      const cv::Mat picture = Picture(type);
      const std::string path = dir + "/t" + std::to_string(n++) + ".tif";
      ASSERT_TRUE(cv::imwrite(path, picture, {cv::IMWRITE_TIFF_COMPRESSION, compression}));
      EXPECT_TRUE(SameImage(DecodePhoto(path).pixels, WithoutAlpha(picture)))
          << type << " compression " << compression;
    }
  // libtiff: tiles, planar (separate) samples, big-endian files, an extra sample, compression.
  struct Layout {
    const char* mode;
    bool tiled, planar;
    int extra;
    uint16_t compression;
  };
  for (int type : {CV_8UC1, CV_8UC3, CV_16UC1, CV_16UC3})
    for (const Layout& l : {Layout{"w", true, false, 0, COMPRESSION_NONE},
                            Layout{"wb", false, false, 0, COMPRESSION_NONE},
                            Layout{"wb", true, true, 0, COMPRESSION_ADOBE_DEFLATE},
                            Layout{"w", false, true, 1, COMPRESSION_LZW},
                            Layout{"wb", false, false, 1, COMPRESSION_NONE}}) {
      const cv::Mat picture = Picture(type, 41, 35);  // not a whole number of tiles or strips
      const std::string path = dir + "/t" + std::to_string(n++) + ".tif";
      WriteTiffLayout(path, picture, l.mode, l.tiled, l.planar, l.extra, l.compression);
      EXPECT_TRUE(SameImage(DecodePhoto(path).pixels, picture))
          << type << " " << l.mode << (l.tiled ? " tiled" : " strips")
          << (l.planar ? " planar" : " contiguous") << " extra " << l.extra;
    }
}

TEST(ImageCodecs, WritersFilesReadBackThroughOpenCv) {
  const std::string dir = ScratchDir();
  for (int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4})
    for (const char* ext : {".png", ".tif"}) {
      const cv::Mat picture = Picture(type);
      const std::string path = dir + "/w" + std::to_string(type) + ext;
      WriteImageFile(path, picture);
      // (OpenCV reads an 8-bit RGBA TIFF through libtiff's RGBA interface, which premultiplies
      // the alpha: that one is not compared.)
      if (!(type == CV_8UC4 && std::string(ext) == ".tif")) {
        EXPECT_TRUE(SameImage(cv::imread(path, cv::IMREAD_UNCHANGED), picture)) << type << ext;
      }
      EXPECT_TRUE(SameImage(DecodePhoto(path).pixels, WithoutAlpha(picture))) << type << ext;
    }
}

// The same encoder settings as OpenCV's (libjpeg's defaults at the quality): the same bytes, so
// the synthetic camera's JPEG photos did not change when the writer did.
TEST(ImageCodecs, JpegEncoderWritesOpenCvsBytes) {
  for (int type : {CV_8UC1, CV_8UC3})
    for (int quality : {40, 75, 95, 100}) {
      const cv::Mat picture = Picture(type, 67, 91);
      std::vector<unsigned char> opencv;
      ASSERT_TRUE(cv::imencode(".jpg", picture, opencv, {cv::IMWRITE_JPEG_QUALITY, quality}));
      EXPECT_TRUE(EncodeJpeg(picture, quality) == opencv) << type << " quality " << quality;
    }
  const std::string path = ScratchDir() + "/q.jpg";
  WriteImageFile(path, Picture(CV_8UC3), 80);
  std::vector<unsigned char> opencv;
  ASSERT_TRUE(cv::imencode(".jpg", Picture(CV_8UC3), opencv, {cv::IMWRITE_JPEG_QUALITY, 80}));
  std::ifstream in(path, std::ios::binary);
  const std::vector<unsigned char> file((std::istreambuf_iterator<char>(in)),
                                        std::istreambuf_iterator<char>());
  EXPECT_TRUE(file == opencv);
}

// Sets the value of the first IFD's entry for `tag` (a classic little-endian TIFF, a SHORT or
// LONG value held in the entry) to `value`: a file whose header claims what libtiff would not
// write.
void PatchTiffTag(const std::string& path, uint16_t tag, uint32_t value) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  auto read = [&](std::streamoff at, int n) {
    uint32_t v = 0;
    f.seekg(at);
    for (int k = 0; k < n; ++k) v |= uint32_t(uint8_t(f.get())) << (8 * k);
    return v;
  };
  const uint32_t ifd = read(4, 4), count = read(ifd, 2);
  for (uint32_t k = 0; k < count; ++k) {
    const std::streamoff entry = ifd + 2 + 12 * k;
    if (read(entry, 2) != tag) continue;
    const int bytes = read(entry + 2, 2) == 3 ? 2 : 4;  // SHORT or LONG
    f.seekp(entry + 8);
    for (int b = 0; b < bytes; ++b) f.put(char((value >> (8 * b)) & 255));
    return;
  }
  ADD_FAILURE() << "no tag " << tag << " in " << path;
}

// A palette PNG with transparency (tRNS) and grey + alpha: alpha dropped, as lumislab's photos
// have 1 or 3 channels; grey + alpha as 1 channel where OpenCV gave 3 equal ones.
TEST(ImageCodecs, TransparencyIsDroppedFromPaletteAndGreyPngs) {
  const std::string dir = ScratchDir();
  const std::string palette = dir + "/trns.png";
  {
    std::FILE* f = std::fopen(palette.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(png);
    png_init_io(png, f);
    png_set_IHDR(png, info, 4, 2, 8, PNG_COLOR_TYPE_PALETTE, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_color colours[2] = {{10, 20, 30}, {200, 100, 50}};
    png_set_PLTE(png, info, colours, 2);
    png_byte alpha[2] = {0, 128};
    png_set_tRNS(png, info, alpha, 2, nullptr);
    png_write_info(png, info);
    png_byte row[4] = {0, 1, 1, 0};
    for (int y = 0; y < 2; ++y) png_write_row(png, row);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
  }
  const Photo p = DecodePhoto(palette);
  ASSERT_EQ(p.pixels.type(), CV_8UC3);
  EXPECT_EQ(p.pixels.at<cv::Vec3b>(1, 1), cv::Vec3b(50, 100, 200));
  EXPECT_EQ(p.pixels.at<cv::Vec3b>(0, 0), cv::Vec3b(30, 20, 10));
  EXPECT_TRUE(SameImage(p.pixels, cv::imread(palette, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR)));
  for (int bits : {8, 16}) {
    // Grey + alpha through libpng (OpenCV writes no two-channel PNG).
    const std::string grey = dir + "/ga" + std::to_string(bits) + ".png";
    const int w = 7, h = 5, bytes = bits / 8;
    std::FILE* f = std::fopen(grey.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(png);
    png_init_io(png, f);
    png_set_IHDR(png, info, w, h, bits, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    cv::Mat expect(h, w, bits == 8 ? CV_8UC1 : CV_16UC1);
    std::vector<png_byte> row(size_t(w) * 2 * bytes);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const int v = (1000 * x + 37 * y) % (bits == 8 ? 256 : 65536);
        if (bits == 8) {
          expect.at<uint8_t>(y, x) = uint8_t(v);
          row[2 * x] = png_byte(v), row[2 * x + 1] = 77;
        } else {
          expect.at<uint16_t>(y, x) = uint16_t(v);
          row[4 * x] = png_byte(v >> 8), row[4 * x + 1] = png_byte(v & 255);  // big-endian
          row[4 * x + 2] = 0, row[4 * x + 3] = 77;
        }
      }
      png_write_row(png, row.data());
    }
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    EXPECT_TRUE(SameImage(DecodePhoto(grey).pixels, expect)) << bits;
  }
}

// The TIFF Orientation tag turns the image as OpenCV turns it; a JPEG-compressed YCbCr TIFF is
// converted to R, G, B by libtiff.
TEST(ImageCodecs, TiffOrientationAndJpegCompressedTiffs) {
  const std::string dir = ScratchDir();
  for (uint16_t orientation : {ORIENTATION_BOTRIGHT, ORIENTATION_RIGHTTOP, ORIENTATION_LEFTBOT})
    for (int type : {CV_8UC3, CV_16UC1}) {
      const cv::Mat picture = Picture(type, 9, 14);
      const std::string path =
          dir + "/o" + std::to_string(orientation) + "_" + std::to_string(type) + ".tif";
      WriteTiffLayout(path, picture, "w", false, false, 0, COMPRESSION_NONE, orientation);
      cv::Mat turned = picture.clone();
      ApplyOrientation(orientation, turned);
      const cv::Mat decoded = DecodePhoto(path).pixels;
      EXPECT_TRUE(SameImage(decoded, turned)) << orientation << " " << type;
      EXPECT_TRUE(SameImage(decoded, cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR)))
          << orientation << " " << type;
    }
  // orientation 3 is a half turn: the first pixel is the last one written.
  cv::Mat turned = Picture(CV_8UC3, 9, 14);
  ApplyOrientation(3, turned);
  EXPECT_EQ(turned.at<cv::Vec3b>(0, 0), Picture(CV_8UC3, 9, 14).at<cv::Vec3b>(8, 13));

  const std::string jpeg_tiff = dir + "/jpeg.tif";
  const int w = 48, h = 32;
  cv::Mat smooth(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      smooth.at<cv::Vec3b>(y, x) = {uint8_t(40 + 3 * x), uint8_t(60 + 2 * y), uint8_t(90 + x + y)};
  TIFF* tif = TIFFOpen(jpeg_tiff.c_str(), "w");
  ASSERT_NE(tif, nullptr);
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, uint32_t(w));
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, uint32_t(h));
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, 8);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 3);
  TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_JPEG);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_YCBCR);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, 16);
  TIFFSetField(tif, TIFFTAG_JPEGQUALITY, 95);
  TIFFSetField(tif, TIFFTAG_JPEGCOLORMODE, JPEGCOLORMODE_RGB);  // we give R, G, B
  std::vector<uint8_t> row(size_t(w) * 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x)
      for (int s = 0; s < 3; ++s) row[size_t(x) * 3 + s] = smooth.at<cv::Vec3b>(y, x)[2 - s];
    ASSERT_EQ(TIFFWriteScanline(tif, row.data(), uint32_t(y), 0), 1);
  }
  TIFFClose(tif);
  const cv::Mat decoded = DecodePhoto(jpeg_tiff).pixels;
  ASSERT_EQ(decoded.type(), CV_8UC3);
  EXPECT_LE(cv::norm(decoded, smooth, cv::NORM_INF), 6);  // JPEG at quality 95, a smooth picture
}

// Sizes a TIFF claims are checked before a buffer is made for them: tiles far larger than the
// image, thousands of samples per pixel.
TEST(ImageCodecs, TiffClaimingHugeTilesOrSamplesIsRefusedBeforeAllocating) {
  const std::string dir = ScratchDir();
  const std::string tiles = dir + "/tiles.tif", samples = dir + "/samples.tif";
  WriteTiffLayout(tiles, Picture(CV_8UC1, 16, 16), "w", true, false);
  PatchTiffTag(tiles, TIFFTAG_TILEWIDTH, 16384);  // 256 M pixels a tile, 1.6 GB of RGB16
  PatchTiffTag(tiles, TIFFTAG_TILELENGTH, 16384);
  WriteTiffLayout(samples, Picture(CV_8UC1, 16, 16), "w", false, false);
  PatchTiffTag(samples, TIFFTAG_SAMPLESPERPIXEL, 60000);
  // (Not a structured binding: C++17 lambdas cannot capture one, and clang refuses it.)
  for (const auto& c :
       {std::pair<std::string, std::string>{tiles, "TileWidth"}, {samples, "SamplesPerPixel"}}) {
    const std::string& path = c.first;
    const std::string& field = c.second;
    std::string message;
    EXPECT_TRUE(ThrowsBadInputNaming([&] { DecodePhoto(path); }, path, &message)) << path;
    EXPECT_NE(message.find(field), std::string::npos) << message;
  }
}

// Writes `pixels` (8-bit, `components` interleaved samples per pixel in the file's order) as a
// JPEG whose components are stored in `space` (libjpeg converts nothing: in = out space).
void WriteJpegIn(const std::string& path, const std::vector<uint8_t>& pixels, int w, int h,
                 int components, J_COLOR_SPACE space) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  jpeg_compress_struct c;
  jpeg_error_mgr error;
  c.err = jpeg_std_error(&error);
  jpeg_create_compress(&c);
  jpeg_stdio_dest(&c, f);
  c.image_width = JDIMENSION(w);
  c.image_height = JDIMENSION(h);
  c.input_components = components;
  c.in_color_space = space;
  jpeg_set_defaults(&c);
  jpeg_set_colorspace(&c, space);
  jpeg_set_quality(&c, 100, TRUE);
  jpeg_start_compress(&c, TRUE);
  for (int y = 0; y < h; ++y) {
    JSAMPROW row = const_cast<JSAMPROW>(&pixels[size_t(y) * w * components]);
    jpeg_write_scanlines(&c, &row, 1);
  }
  jpeg_finish_compress(&c);
  jpeg_destroy_compress(&c);
  std::fclose(f);
}

// A JPEG whose components are R, G, B (an Adobe-marked file) gives its codes as stored, as
// OpenCV's decoder does; a CMYK one is refused naming the colour space.
TEST(ImageCodecs, RgbCodedJpegGivesItsCodesAndCmykIsRefused) {
  const std::string dir = ScratchDir();
  const int w = 24, h = 16;
  std::vector<uint8_t> rgb(size_t(w) * h * 3), cmyk(size_t(w) * h * 4);
  for (int k = 0; k < w * h; ++k) {
    for (int s = 0; s < 3; ++s) rgb[size_t(k) * 3 + s] = uint8_t(40 + 60 * s + (k % w) * 3);
    for (int s = 0; s < 4; ++s) cmyk[size_t(k) * 4 + s] = uint8_t(20 * s + k % 50);
  }
  const std::string rgb_path = dir + "/rgb.jpg", cmyk_path = dir + "/cmyk.jpg";
  WriteJpegIn(rgb_path, rgb, w, h, 3, JCS_RGB);
  WriteJpegIn(cmyk_path, cmyk, w, h, 4, JCS_CMYK);
  const DecodedJpeg decoded = DecodeJpeg(rgb_path);
  EXPECT_FALSE(decoded.fractional);
  ASSERT_EQ(decoded.pixels.type(), CV_8UC3);
  EXPECT_TRUE(SameImage(decoded.pixels, cv::imread(rgb_path, cv::IMREAD_COLOR)));
  // Quality 100 without chroma subsampling of R, G, B: each code within a few of the written one.
  double worst = 0;
  for (int k = 0; k < w * h; ++k)
    for (int s = 0; s < 3; ++s)
      worst = std::max(worst, std::abs(double(decoded.pixels.at<cv::Vec3b>(k / w, k % w)[2 - s]) -
                                       rgb[size_t(k) * 3 + s]));
  EXPECT_LE(worst, 4);
  std::string message;
  EXPECT_TRUE(ThrowsBadInputNaming([&] { DecodePhoto(cmyk_path); }, cmyk_path, &message));
  EXPECT_NE(message.find("colour space"), std::string::npos) << message;
  EXPECT_NE(message.find("CMYK"), std::string::npos) << message;
}

// What lumislab does not read is refused before any pixel is used, naming the file and the TIFF
// field; a damaged file names the file and what the library found.
TEST(ImageCodecs, UnreadableTiffsAndDamagedPngsAreRefusedNamingTheFileAndField) {
  const std::string dir = ScratchDir();
  auto refused = [&](const std::string& path, const std::string& field) {
    std::string message;
    EXPECT_TRUE(ThrowsBadInputNaming([&] { DecodePhoto(path); }, path, &message)) << path;
    EXPECT_NE(message.find(field), std::string::npos) << message;
  };
  const std::string float_tiff = dir + "/float.tif";
  ASSERT_TRUE(cv::imwrite(float_tiff, cv::Mat(8, 8, CV_32FC1, cv::Scalar(0.5))));
  refused(float_tiff, "SampleFormat");
  const std::string palette_tiff = dir + "/palette.tif";
  {
    TIFF* tif = TIFFOpen(palette_tiff.c_str(), "w");
    ASSERT_NE(tif, nullptr);
    TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, 4u);
    TIFFSetField(tif, TIFFTAG_IMAGELENGTH, 2u);
    TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, 8);
    TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 1);
    TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_PALETTE);
    std::vector<uint16_t> map(256, 1000);
    TIFFSetField(tif, TIFFTAG_COLORMAP, map.data(), map.data(), map.data());
    uint8_t row[4] = {0, 1, 2, 3};
    for (uint32_t y = 0; y < 2; ++y) TIFFWriteScanline(tif, row, y, 0);
    TIFFClose(tif);
  }
  refused(palette_tiff, "PhotometricInterpretation");
  const std::string bilevel_tiff = dir + "/bilevel.tif";
  ASSERT_TRUE(cv::imwrite(bilevel_tiff, Picture(CV_8UC3), {cv::IMWRITE_TIFF_COMPRESSION, 5}));
  {
    // The same file cut short, its directory (written last) lost: libtiff's message, the file
    // named. (Strip data cut short with the directory intact is BadInput too: an outside
    // review of these decoders tried it.)
    const auto size = std::filesystem::file_size(bilevel_tiff);
    std::filesystem::resize_file(bilevel_tiff, size / 2);
  }
  refused(bilevel_tiff, "TIFF");
  const std::string damaged_png = dir + "/damaged.png";
  ASSERT_TRUE(cv::imwrite(damaged_png, Picture(CV_16UC3)));
  {
    // One byte of the image data changed: the chunk's CRC no longer matches.
    std::fstream f(damaged_png, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(60);
    f.put(char(0x5a));
  }
  refused(damaged_png, "PNG");
}

}  // namespace
}  // namespace lumislab
