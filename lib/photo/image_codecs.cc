#include "lib/photo/image_codecs.h"

#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <csetjmp>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/error.h"
#include "lib/photo/photo_allocator.h"
#include "lib/photo/photo_format.h"

namespace lumislab {
namespace {

constexpr bool kLittleEndian = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;
// Samples per pixel a TIFF may have (R, G, B and extra samples; libtiff allows 65535, and a
// scanline buffer grows with them).
constexpr int kMaxTiffSamples = 16;

// ---- PNG ----

// libpng reports a fatal error through the error function, which must not return: it keeps the
// message and jumps back to the setjmp of the caller (no C++ object with a destructor is created
// between that setjmp and the libpng calls that may jump). Warnings (an odd ICC profile, an
// ancillary chunk's CRC) are dropped, as OpenCV's decoder did.
struct PngMessage {
  char text[256] = "";
};
void PngError(png_structp png, png_const_charp message) {
  auto* m = static_cast<PngMessage*>(png_get_error_ptr(png));
  std::snprintf(m->text, sizeof m->text, "%s", message);
  png_longjmp(png, 1);
}
void PngWarning(png_structp, png_const_charp) {}

// libpng's structs, destroyed with the guard (also when a C++ exception leaves, e.g. from an
// allocation): declared before the setjmp and not changed after it.
struct PngReader {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~PngReader() { png_destroy_read_struct(&png, info ? &info : nullptr, nullptr); }
};
struct PngWriter {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~PngWriter() { png_destroy_write_struct(&png, info ? &info : nullptr); }
};

// ---- TIFF ----

int CollectTiffMessage(TIFF*, void* user_data, const char* module, const char* fmt, va_list ap) {
  char buffer[512];
  std::vsnprintf(buffer, sizeof buffer, fmt, ap);
  auto* message = static_cast<std::string*>(user_data);
  if (message->empty()) *message = std::string(module ? module : "libtiff") + ": " + buffer;
  return 1;
}
int IgnoreTiffMessage(TIFF*, void*, const char*, const char*, va_list) { return 1; }

// Copies `pixels` pixels of `samples` interleaved samples each (of `bytes` bytes) into `out`,
// which holds `channels` per pixel: the first 1 or 3 samples, the latter as B, G, R.
void CopySamples(const uint8_t* in, int samples, int channels, int bytes, int pixels,
                 uint8_t* out) {
  for (int x = 0; x < pixels; ++x) {
    const uint8_t* p = in + size_t(x) * samples * bytes;
    uint8_t* o = out + size_t(x) * channels * bytes;
    for (int c = 0; c < channels; ++c)
      std::memcpy(o + c * bytes, p + (channels == 3 ? 2 - c : c) * bytes, size_t(bytes));
  }
}

// R, G, B samples of `pixels` pixels to B, G, R in place.
template <typename T>
void SwapRedBlue(T* rgb, uint32_t pixels) {
  for (uint32_t x = 0; x < pixels; ++x) std::swap(rgb[3 * size_t(x)], rgb[3 * size_t(x) + 2]);
}

}  // namespace

cv::Mat DecodePng(const std::string& path) {
  CodecFile file(std::fopen(path.c_str(), "rb"));
  if (!file) throw BadInput(path + ": cannot open the photo");
  PngMessage message;
  PngReader reader;  // created before the setjmp and not changed after it: destroys the structs
  reader.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &message, PngError, PngWarning);
  reader.info = reader.png ? png_create_info_struct(reader.png) : nullptr;
  if (!reader.info) throw Failure("libpng: out of memory");
  png_structp png = reader.png;
  png_infop info = reader.info;
  cv::Mat out;  // created before the setjmp: a jump back leaves them to their destructors
  std::vector<png_bytep> rows;
  if (setjmp(png_jmpbuf(png)))
    throw BadInput(path + ": cannot decode the PNG (" + message.text + ")");
  png_init_io(png, file.get());
  png_read_info(png, info);
  png_uint_32 width = 0, height = 0;
  int bit_depth = 0, colour_type = 0;
  png_get_IHDR(png, info, &width, &height, &bit_depth, &colour_type, nullptr, nullptr, nullptr);
  if (uint64_t(width) * height > uint64_t(kMaxPhotoPixels))
    throw InputError(path, "IHDR",
                     "an image of 1 .. " + std::to_string(kMaxPhotoPixels) + " pixels",
                     std::to_string(width) + "x" + std::to_string(height));
  if (colour_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (colour_type == PNG_COLOR_TYPE_GRAY && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  // Alpha, and the alpha a palette's transparency (tRNS) becomes when it is expanded, dropped.
  if ((colour_type & PNG_COLOR_MASK_ALPHA) || png_get_valid(png, info, PNG_INFO_tRNS))
    png_set_strip_alpha(png);
  if (bit_depth == 16 && kLittleEndian) png_set_swap(png);  // PNG stores big-endian samples
  if (colour_type & PNG_COLOR_MASK_COLOR) png_set_bgr(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  const int channels = png_get_channels(png, info);
  const int depth = png_get_bit_depth(png, info) == 16 ? CV_16U : CV_8U;
  if (channels != 1 && channels != 3) png_error(png, "unexpected channel count after expansion");
  out = NewPhotoImage(int(height), int(width), CV_MAKETYPE(depth, channels));
  rows.resize(height);
  for (png_uint_32 y = 0; y < height; ++y) rows[y] = out.ptr(int(y));
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);  // the chunks after the image data, to IEND
  return out;
}

void EncodePng(const std::string& file_name, const cv::Mat& image, const std::string& path) {
  LUMISLAB_CHECK((image.depth() == CV_8U || image.depth() == CV_16U) && !image.empty() &&
                     (image.channels() == 1 || image.channels() == 3 || image.channels() == 4),
                 "EncodePng: an 8-bit or 16-bit image of 1, 3 or 4 channels");
  CodecFile file(std::fopen(file_name.c_str(), "wb"));
  if (!file) throw IoError(path, "cannot create the file");
  PngMessage message;
  PngWriter writer;
  writer.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &message, PngError, PngWarning);
  writer.info = writer.png ? png_create_info_struct(writer.png) : nullptr;
  if (!writer.info) throw Failure("libpng: out of memory");
  png_structp png = writer.png;
  png_infop info = writer.info;
  if (setjmp(png_jmpbuf(png)))
    throw IoError(path, std::string("cannot write the PNG: ") + message.text);
  png_init_io(png, file.get());
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_compression_level(png, Z_BEST_SPEED);
  png_set_compression_strategy(png, Z_RLE);
  const int channels = image.channels();
  const int colour_type = channels == 1   ? PNG_COLOR_TYPE_GRAY
                          : channels == 3 ? PNG_COLOR_TYPE_RGB
                                          : PNG_COLOR_TYPE_RGB_ALPHA;
  png_set_IHDR(png, info, png_uint_32(image.cols), png_uint_32(image.rows),
               int(image.elemSize1() * 8), colour_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (image.depth() == CV_16U && kLittleEndian) png_set_swap(png);
  if (channels >= 3) png_set_bgr(png);
  for (int y = 0; y < image.rows; ++y) png_write_row(png, image.ptr(y));
  png_write_end(png, info);
  std::FILE* f = file.release();
  const bool failed = std::ferror(f) != 0;
  if (std::fclose(f) != 0 || failed) throw IoError(path, "cannot write the PNG");
}

TiffFile OpenTiff(const std::string& path, const char* mode, std::string& error) {
  std::unique_ptr<TIFFOpenOptions, void (*)(TIFFOpenOptions*)> options(TIFFOpenOptionsAlloc(),
                                                                       TIFFOpenOptionsFree);
  TIFFOpenOptionsSetErrorHandlerExtR(options.get(), &CollectTiffMessage, &error);
  TIFFOpenOptionsSetWarningHandlerExtR(options.get(), &IgnoreTiffMessage, nullptr);
  return TiffFile(TIFFOpenExt(path.c_str(), mode, options.get()), TIFFClose);
}

cv::Mat DecodeTiff(const std::string& path) {
  std::string error;
  // "m": read(), not a memory map of the file: each first touch of a mapped 4 kB page is a page
  // fault, which made the bench's 137 MB photos markedly slower to decode mapped.
  const TiffFile file = OpenTiff(path, "rm", error);
  auto corrupt = [&] { return BadInput(path + ": cannot decode the TIFF (" + error + ")"); };
  if (!file) throw corrupt();
  TIFF* tif = file.get();
  uint32_t width = 0, height = 0;
  uint16_t bits = 1, samples = 1, format = SAMPLEFORMAT_UINT, planar = PLANARCONFIG_CONTIG;
  uint16_t photometric = 0, compression = COMPRESSION_NONE;
  if (!TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &width) ||
      !TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &height) || width == 0 || height == 0 ||
      uint64_t(width) * height > uint64_t(kMaxPhotoPixels))
    throw InputError(path, "ImageWidth, ImageLength",
                     "an image of 1 .. " + std::to_string(kMaxPhotoPixels) + " pixels",
                     std::to_string(width) + "x" + std::to_string(height));
  TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &bits);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &samples);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &format);
  TIFFGetFieldDefaulted(tif, TIFFTAG_PLANARCONFIG, &planar);
  TIFFGetFieldDefaulted(tif, TIFFTAG_COMPRESSION, &compression);
  if (!TIFFGetField(tif, TIFFTAG_PHOTOMETRIC, &photometric))
    throw InputError(path, "PhotometricInterpretation", "grey (MinIsBlack) or RGB", "none");
  if (format != SAMPLEFORMAT_UINT)
    throw InputError(path, "SampleFormat", "unsigned integers (1)", std::to_string(format));
  if (bits != 8 && bits != 16)
    throw InputError(path, "BitsPerSample", "8 or 16", std::to_string(bits));
  if (samples > kMaxTiffSamples)
    throw InputError(path, "SamplesPerPixel", "1 .. " + std::to_string(kMaxTiffSamples),
                     std::to_string(samples));
  // A JPEG-compressed TIFF stores Y, Cb, Cr: libtiff's JPEG codec converts them to R, G, B.
  if (photometric == PHOTOMETRIC_YCBCR && compression == COMPRESSION_JPEG && bits == 8 &&
      samples == 3 && TIFFSetField(tif, TIFFTAG_JPEGCOLORMODE, JPEGCOLORMODE_RGB))
    photometric = PHOTOMETRIC_RGB;
  const bool rgb = photometric == PHOTOMETRIC_RGB && samples >= 3;
  if (!rgb && !(photometric == PHOTOMETRIC_MINISBLACK && samples >= 1))
    throw InputError(
        path, "PhotometricInterpretation", "grey (MinIsBlack, 1) or RGB (2) with as many samples",
        std::to_string(photometric) + " with " + std::to_string(samples) + " sample(s) per pixel");
  if (!TIFFIsCODECConfigured(compression))
    throw InputError(path, "Compression", "a compression libtiff decodes",
                     std::to_string(compression));
  const int channels = rgb ? 3 : 1, bytes = bits / 8;
  const bool contiguous = planar == PLANARCONFIG_CONTIG || samples == 1;
  // Samples per pixel in one read buffer: all (contiguous) or one plane's.
  const int stride = contiguous ? samples : 1;
  cv::Mat out =
      NewPhotoImage(int(height), int(width), CV_MAKETYPE(bits == 16 ? CV_16U : CV_8U, channels));
  // Sample s of `pixels` pixels (of `stride` samples each) into out's channel for s.
  auto scatter = [&](const uint8_t* in, int plane, uint32_t y, uint32_t x0, uint32_t pixels) {
    uint8_t* row = out.ptr(int(y)) + size_t(x0) * channels * bytes;
    if (contiguous) return CopySamples(in, stride, channels, bytes, int(pixels), row);
    const int c = channels == 3 ? 2 - plane : plane;
    for (uint32_t x = 0; x < pixels; ++x)
      std::memcpy(row + (size_t(x) * channels + c) * bytes, in + size_t(x) * bytes, size_t(bytes));
  };
  const int planes = contiguous ? 1 : channels;
  if (TIFFIsTiled(tif)) {
    uint32_t tw = 0, th = 0;
    // A tile larger than the image (padded to whole tiles of 16) or than a few megapixels is
    // refused before its buffer is allocated: the sizes are the file's claim.
    const uint64_t cap = std::max<uint64_t>(uint64_t(width + 15) * (height + 15), 1 << 22);
    if (!TIFFGetField(tif, TIFFTAG_TILEWIDTH, &tw) || !TIFFGetField(tif, TIFFTAG_TILELENGTH, &th) ||
        tw == 0 || th == 0 || uint64_t(tw) * th > cap)
      throw InputError(path, "TileWidth, TileLength",
                       "tiles of 1 .. " + std::to_string(cap) + " pixels",
                       std::to_string(tw) + "x" + std::to_string(th));
    const tmsize_t tile_bytes = TIFFTileSize(tif);
    if (tile_bytes <= 0 || uint64_t(tile_bytes) < uint64_t(tw) * th * stride * bytes)
      throw corrupt();
    std::vector<uint8_t> tile(static_cast<size_t>(tile_bytes));
    for (int plane = 0; plane < planes; ++plane)
      for (uint32_t ty = 0; ty < height; ty += th)
        for (uint32_t tx = 0; tx < width; tx += tw) {
          if (TIFFReadTile(tif, tile.data(), tx, ty, 0, uint16_t(plane)) < 0) throw corrupt();
          const uint32_t w = std::min(tw, width - tx), h = std::min(th, height - ty);
          for (uint32_t y = 0; y < h; ++y)
            scatter(&tile[size_t(y) * tw * stride * bytes], plane, ty + y, tx, w);
        }
  } else {
    const tmsize_t line_bytes = TIFFScanlineSize(tif);
    if (line_bytes <= 0 || uint64_t(line_bytes) < uint64_t(width) * stride * bytes) throw corrupt();
    // A grey or RGB image without extra samples is read straight into its rows.
    const bool direct = contiguous && samples == channels;
    std::vector<uint8_t> line(direct ? 0 : static_cast<size_t>(line_bytes));
    for (int plane = 0; plane < planes; ++plane)  // compressed planes are read in file order
      for (uint32_t y = 0; y < height; ++y) {
        uint8_t* buffer = direct ? out.ptr(int(y)) : line.data();
        if (TIFFReadScanline(tif, buffer, y, uint16_t(plane)) < 0) throw corrupt();
        if (!direct) {
          scatter(buffer, plane, y, 0, width);
        } else if (channels == 3 && bytes == 2) {  // R, G, B in place to B, G, R
          SwapRedBlue(reinterpret_cast<uint16_t*>(buffer), width);
        } else if (channels == 3) {
          SwapRedBlue(buffer, width);
        }
      }
  }
  uint16_t orientation = ORIENTATION_TOPLEFT;
  TIFFGetFieldDefaulted(tif, TIFFTAG_ORIENTATION, &orientation);
  ApplyOrientation(orientation, out);
  return out;
}

void ApplyOrientation(int orientation, cv::Mat& image) {
  switch (orientation) {
    case 2:
      cv::flip(image, image, 1);
      break;
    case 3:
      cv::flip(image, image, -1);
      break;
    case 4:
      cv::flip(image, image, 0);
      break;
    case 5:
      cv::transpose(image, image);
      break;
    case 6:
      cv::transpose(image, image);
      cv::flip(image, image, 1);
      break;
    case 7:
      cv::transpose(image, image);
      cv::flip(image, image, -1);
      break;
    case 8:
      cv::transpose(image, image);
      cv::flip(image, image, 0);
      break;
    default:
      break;
  }
}

}  // namespace lumislab
