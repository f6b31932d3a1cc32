#include "lib/photo/camera_write.h"

#include <libexif/exif-data.h>
#include <tiffio.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "lib/photo/image_codecs.h"
#include "lib/photo/jpeg_decode.h"

namespace lumislab {
namespace {

// ---- DNG through libtiff ----

// Sets an array-valued tag; libtiff wants the count before the pointer only for tags of
// variable length, and rationals as float or double depending on the tag.
template <typename T>
void SetArray(TIFF* tif, uint32_t tag, const std::vector<T>& values) {
  const TIFFField* field = TIFFFieldWithTag(tif, tag);
  LUMISLAB_CHECK(field, "TIFF writer: libtiff does not know tag " + std::to_string(tag));
  const int ok = TIFFFieldPassCount(field)
                     ? TIFFSetField(tif, tag, int(values.size()), values.data())
                     : TIFFSetField(tif, tag, values.data());
  LUMISLAB_CHECK(ok, "TIFF writer: libtiff refused tag " + std::to_string(tag));
}
void SetReals(TIFF* tif, uint32_t tag, const std::vector<double>& values) {
  const TIFFField* field = TIFFFieldWithTag(tif, tag);
  LUMISLAB_CHECK(field, "TIFF writer: libtiff does not know tag " + std::to_string(tag));
  if (TIFFFieldSetGetSize(field) == 4)
    SetArray(tif, tag, std::vector<float>(values.begin(), values.end()));
  else
    SetArray(tif, tag, values);
}
template <typename... A>
void Set(TIFF* tif, uint32_t tag, A... values) {
  LUMISLAB_CHECK(TIFFSetField(tif, tag, values...),
                 "TIFF writer: libtiff refused tag " + std::to_string(tag));
}

bool HasExifDirectory(const PhotoExif& e) {
  return e.exposure_time || e.f_number || e.iso || e.lens_model || e.date_time || e.focal_length;
}

// The EXIF directory, written before IFD0 (libtiff appends it, unlinked; IFD0 then points to
// it through ExifIFD). Returns its offset.
uint64_t WriteExifDirectory(TIFF* tif, const PhotoExif& e) {
  LUMISLAB_CHECK(TIFFCreateEXIFDirectory(tif) == 0,
                 "TIFF writer: cannot create the EXIF directory");
  SetArray(tif, EXIFTAG_EXIFVERSION, std::vector<uint8_t>{'0', '2', '3', '0'});
  if (e.exposure_time) Set(tif, EXIFTAG_EXPOSURETIME, *e.exposure_time);
  if (e.f_number) Set(tif, EXIFTAG_FNUMBER, *e.f_number);
  if (e.iso) SetArray(tif, EXIFTAG_ISOSPEEDRATINGS, std::vector<uint16_t>{uint16_t(*e.iso)});
  if (e.lens_model) Set(tif, EXIFTAG_LENSMODEL, e.lens_model->c_str());
  if (e.focal_length) Set(tif, EXIFTAG_FOCALLENGTH, *e.focal_length);
  if (e.date_time) Set(tif, EXIFTAG_DATETIMEORIGINAL, e.date_time->c_str());
  uint64_t offset = 0;
  if (!TIFFWriteCustomDirectory(tif, &offset)) throw Failure("TIFF writer: cannot write EXIF");
  TIFFFreeDirectory(tif);
  TIFFCreateDirectory(tif);  // back to a main IFD
  return offset;
}

// Creates `tmp` for writing, libtiff's errors going into `error` (closed when the handle goes).
TiffFile CreateTiff(const std::string& tmp, std::string& error) {
  TiffFile file = OpenTiff(tmp, "w", error);
  if (!file) throw IoError(tmp, "cannot create the file: " + error);
  return file;
}

// Make, model, date-time and orientation (top-left unless `e` states another) in IFD0, and the
// pointer to the EXIF directory.
void SetCameraTags(TIFF* tif, const PhotoExif& e, uint64_t exif_offset) {
  Set(tif, TIFFTAG_ORIENTATION, uint16_t(e.orientation.value_or(ORIENTATION_TOPLEFT)));
  Set(tif, TIFFTAG_SOFTWARE, "lumislab");
  if (e.make) Set(tif, TIFFTAG_MAKE, e.make->c_str());
  if (e.model) Set(tif, TIFFTAG_MODEL, e.model->c_str());
  if (e.date_time) Set(tif, TIFFTAG_DATETIME, e.date_time->c_str());
  if (exif_offset) Set(tif, TIFFTAG_EXIFIFD, exif_offset);
}

void WriteDngFile(const std::string& tmp, const cv::Mat& mosaic, const DngInfo& info,
                  std::string& error) {
  const TiffFile file = CreateTiff(tmp, error);
  TIFF* tif = file.get();
  const PhotoExif& e = info.exif;
  const uint64_t exif_offset = HasExifDirectory(e) ? WriteExifDirectory(tif, e) : 0;

  Set(tif, TIFFTAG_SUBFILETYPE, 0);  // the full-resolution image
  Set(tif, TIFFTAG_IMAGEWIDTH, uint32_t(mosaic.cols));
  Set(tif, TIFFTAG_IMAGELENGTH, uint32_t(mosaic.rows));
  Set(tif, TIFFTAG_BITSPERSAMPLE, 16);
  Set(tif, TIFFTAG_SAMPLESPERPIXEL, 1);
  Set(tif, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
  Set(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_CFA);
  Set(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  Set(tif, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(tif, 0));
  SetCameraTags(tif, e, exif_offset);
  SetArray(tif, TIFFTAG_CFAREPEATPATTERNDIM, std::vector<uint16_t>{2, 2});
  SetArray(tif, TIFFTAG_CFAPATTERN, std::vector<uint8_t>{0, 1, 1, 2});  // R G / G B
  SetArray(tif, TIFFTAG_DNGVERSION, std::vector<uint8_t>{1, 4, 0, 0});
  SetArray(tif, TIFFTAG_DNGBACKWARDVERSION, std::vector<uint8_t>{1, 1, 0, 0});
  const std::string camera = (e.make ? *e.make + " " : "") + (e.model ? *e.model : "lumislab");
  Set(tif, TIFFTAG_UNIQUECAMERAMODEL, camera.c_str());
  SetArray(tif, TIFFTAG_CFAPLANECOLOR, std::vector<uint8_t>{0, 1, 2});
  Set(tif, TIFFTAG_CFALAYOUT, 1);  // rectangular
  SetArray(tif, TIFFTAG_BLACKLEVELREPEATDIM, std::vector<uint16_t>{1, 1});
  SetReals(tif, TIFFTAG_BLACKLEVEL, {double(info.black_level)});
  SetArray(tif, TIFFTAG_WHITELEVEL, std::vector<uint32_t>{uint32_t(info.white_level)});
  SetReals(tif, TIFFTAG_COLORMATRIX1, {1, 0, 0, 0, 1, 0, 0, 0, 1});
  Set(tif, TIFFTAG_CALIBRATIONILLUMINANT1, 21);  // D65
  const auto& n = info.as_shot_neutral;
  SetReals(tif, TIFFTAG_ASSHOTNEUTRAL, {n[0], n[1], n[2]});

  std::vector<uint16_t> row(size_t(mosaic.cols));
  for (int y = 0; y < mosaic.rows; ++y) {
    std::memcpy(row.data(), mosaic.ptr<uint16_t>(y), row.size() * sizeof(uint16_t));
    if (TIFFWriteScanline(tif, row.data(), uint32_t(y), 0) < 0)
      throw IoError(tmp, "cannot write the DNG: " + error);
  }
  if (!TIFFWriteDirectory(tif)) throw IoError(tmp, "cannot write the DNG: " + error);
}

void WriteTiffFile(const std::string& tmp, const cv::Mat& image, const PhotoExif& exif,
                   std::string& error) {
  const TiffFile file = CreateTiff(tmp, error);
  TIFF* tif = file.get();
  const uint64_t exif_offset = HasExifDirectory(exif) ? WriteExifDirectory(tif, exif) : 0;
  const int channels = image.channels();
  Set(tif, TIFFTAG_IMAGEWIDTH, uint32_t(image.cols));
  Set(tif, TIFFTAG_IMAGELENGTH, uint32_t(image.rows));
  Set(tif, TIFFTAG_BITSPERSAMPLE, int(image.elemSize1() * 8));
  Set(tif, TIFFTAG_SAMPLESPERPIXEL, channels);
  Set(tif, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
  Set(tif, TIFFTAG_PHOTOMETRIC, channels >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK);
  if (channels == 4) {
    const uint16_t alpha[1] = {EXTRASAMPLE_UNASSALPHA};
    Set(tif, TIFFTAG_EXTRASAMPLES, uint16_t(1), alpha);
  }
  Set(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  Set(tif, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(tif, 0));
  SetCameraTags(tif, exif, exif_offset);
  cv::Mat rgb;  // TIFF stores R, G, B (a new buffer: the caller's image stays as it is)
  if (channels == 3)
    cv::cvtColor(image, rgb, cv::COLOR_BGR2RGB);
  else if (channels == 4)
    cv::cvtColor(image, rgb, cv::COLOR_BGRA2RGBA);
  else
    rgb = image;
  for (int y = 0; y < rgb.rows; ++y)
    if (TIFFWriteScanline(tif, rgb.ptr(y), uint32_t(y), 0) < 0)
      throw IoError(tmp, "cannot write the TIFF: " + error);
  if (!TIFFWriteDirectory(tif)) throw IoError(tmp, "cannot write the TIFF: " + error);
}

// ---- EXIF for JPEG through libexif ----

ExifRational ToRational(double v) {
  if (v > 0 && v < 1) {  // exposure times: 1/n when it is one
    const double n = 1 / v;
    if (std::abs(n - std::round(n)) < 1e-6 * n && n < 4e9) return {1, ExifLong(std::round(n))};
  }
  ExifLong den = 10000;
  while (den > 1 && v * den > 4e9) den /= 10;
  const ExifLong num = ExifLong(std::round(std::max(v, 0.0) * den));
  const ExifLong g = std::gcd(num, den);
  return {g ? num / g : 0, g ? den / g : 1};
}

// The APP1 payload: "Exif\0\0" and a little-endian TIFF structure (IFD0 + EXIF IFD).
std::vector<unsigned char> BuildExifPayload(const PhotoExif& exif) {
  std::unique_ptr<ExifMem, void (*)(ExifMem*)> mem(exif_mem_new_default(), exif_mem_unref);
  std::unique_ptr<ExifData, void (*)(ExifData*)> ed(exif_data_new_mem(mem.get()), exif_data_unref);
  LUMISLAB_CHECK(mem && ed, "WriteJpeg: out of memory");
  exif_data_unset_option(ed.get(), EXIF_DATA_OPTION_FOLLOW_SPECIFICATION);  // no made-up tags
  const ExifByteOrder order = EXIF_BYTE_ORDER_INTEL;
  exif_data_set_byte_order(ed.get(), order);
  auto add = [&](ExifIfd ifd, ExifTag tag, ExifFormat format, unsigned long components) {
    ExifEntry* entry = exif_entry_new_mem(mem.get());
    LUMISLAB_CHECK(entry, "WriteJpeg: out of memory");
    entry->tag = tag;
    entry->format = format;
    entry->components = components;
    entry->size = exif_format_get_size(format) * components;
    entry->data = static_cast<unsigned char*>(exif_mem_alloc(mem.get(), entry->size));
    exif_content_add_entry(ed->ifd[ifd], entry);
    exif_entry_unref(entry);  // the IFD holds it
    LUMISLAB_CHECK(entry->data, "WriteJpeg: out of memory");
    return entry;
  };
  auto text = [&](ExifIfd ifd, ExifTag tag, const std::optional<std::string>& s) {
    if (!s) return;
    ExifEntry* entry = add(ifd, tag, EXIF_FORMAT_ASCII, s->size() + 1);
    std::memcpy(entry->data, s->c_str(), s->size() + 1);
  };
  auto rational = [&](ExifTag tag, const std::optional<double>& v) {
    if (v)
      exif_set_rational(add(EXIF_IFD_EXIF, tag, EXIF_FORMAT_RATIONAL, 1)->data, order,
                        ToRational(*v));
  };
  text(EXIF_IFD_0, EXIF_TAG_MAKE, exif.make);
  text(EXIF_IFD_0, EXIF_TAG_MODEL, exif.model);
  text(EXIF_IFD_0, EXIF_TAG_DATE_TIME, exif.date_time);
  if (exif.orientation)
    exif_set_short(add(EXIF_IFD_0, EXIF_TAG_ORIENTATION, EXIF_FORMAT_SHORT, 1)->data, order,
                   ExifShort(*exif.orientation));
  std::memcpy(add(EXIF_IFD_EXIF, EXIF_TAG_EXIF_VERSION, EXIF_FORMAT_UNDEFINED, 4)->data, "0230", 4);
  rational(EXIF_TAG_EXPOSURE_TIME, exif.exposure_time);
  rational(EXIF_TAG_FNUMBER, exif.f_number);
  rational(EXIF_TAG_FOCAL_LENGTH, exif.focal_length);
  if (exif.iso)
    exif_set_short(add(EXIF_IFD_EXIF, EXIF_TAG_ISO_SPEED_RATINGS, EXIF_FORMAT_SHORT, 1)->data,
                   order, ExifShort(std::clamp(std::round(*exif.iso), 0.0, 65535.0)));
  text(EXIF_IFD_EXIF, EXIF_TAG_DATE_TIME_ORIGINAL, exif.date_time);
  text(EXIF_IFD_EXIF, EXIF_TAG_LENS_MODEL, exif.lens_model);
  unsigned char* data = nullptr;
  unsigned int size = 0;
  exif_data_save_data(ed.get(), &data, &size);
  LUMISLAB_CHECK(data && size > 0, "WriteJpeg: libexif could not build the EXIF block");
  std::vector<unsigned char> payload(data, data + size);
  exif_mem_free(mem.get(), data);
  return payload;
}

}  // namespace

void WriteDng(const std::string& path, const cv::Mat& mosaic, const DngInfo& info) {
  LUMISLAB_CHECK(mosaic.type() == CV_16UC1 && mosaic.rows >= 2 && mosaic.cols >= 2 &&
                     mosaic.rows % 2 == 0 && mosaic.cols % 2 == 0,
                 "WriteDng: a CV_16UC1 mosaic of even width and height");
  LUMISLAB_CHECK(
      info.black_level >= 0 && info.white_level > info.black_level && info.white_level <= 65535,
      "WriteDng: 0 <= black_level < white_level <= 65535");
  WriteAtomically(path, [&](const std::string& tmp) {
    std::string error;
    WriteDngFile(tmp, mosaic, info, error);  // TIFFClose when it returns or throws
    if (!error.empty()) throw IoError(path, "cannot write the DNG: " + error);
  });
}

void WriteTiff(const std::string& path, const cv::Mat& image, const PhotoExif& exif) {
  LUMISLAB_CHECK((image.depth() == CV_8U || image.depth() == CV_16U) &&
                     (image.channels() == 1 || image.channels() == 3 || image.channels() == 4) &&
                     !image.empty(),
                 "WriteTiff: an 8-bit or 16-bit image of 1, 3 or 4 channels");
  WriteAtomically(path, [&](const std::string& tmp) {
    std::string error;
    WriteTiffFile(tmp, image, exif, error);
    if (!error.empty()) throw IoError(path, "cannot write the TIFF: " + error);
  });
}

void WriteJpeg(const std::string& path, const cv::Mat& bgr8, int quality, const PhotoExif& exif) {
  LUMISLAB_CHECK(bgr8.type() == CV_8UC3 || bgr8.type() == CV_8UC1, "WriteJpeg: an 8-bit image");
  LUMISLAB_CHECK(quality >= 1 && quality <= 100, "WriteJpeg: quality in [1, 100]");
  const std::vector<unsigned char> jpeg = EncodeJpeg(bgr8, quality);
  LUMISLAB_CHECK(jpeg.size() > 4 && jpeg[0] == 0xff && jpeg[1] == 0xd8, "WriteJpeg: no SOI");
  // A camera writes SOI, then APP1 EXIF; libjpeg's JFIF APP0 segment is dropped. Without a field
  // to write, the JPEG is written as libjpeg encoded it (an empty EXIF block reads as corrupt).
  const bool any = exif.exposure_time || exif.f_number || exif.iso || exif.make || exif.model ||
                   exif.lens_model || exif.date_time || exif.focal_length || exif.orientation;
  if (!any) {
    WriteAtomically(path, [&](const std::string& tmp) {
      std::ofstream file(tmp, std::ios::binary);
      file.write(reinterpret_cast<const char*>(jpeg.data()), std::streamsize(jpeg.size()));
      file.close();
      if (!file) throw IoError(path, "cannot write the JPEG");
    });
    return;
  }
  size_t rest = 2;
  if (jpeg[2] == 0xff && jpeg[3] == 0xe0 && jpeg.size() > 11 &&
      std::memcmp(&jpeg[6], "JFIF\0", 5) == 0)
    rest = 4 + (size_t(jpeg[4]) << 8 | jpeg[5]);
  const std::vector<unsigned char> payload = BuildExifPayload(exif);
  LUMISLAB_CHECK(payload.size() + 2 <= 65535, "WriteJpeg: EXIF block over 64 KiB");
  const size_t length = payload.size() + 2;
  std::vector<unsigned char> out;
  out.reserve(6 + payload.size() + jpeg.size());
  for (unsigned char b : {0xff, 0xd8, 0xff, 0xe1}) out.push_back(b);
  out.push_back((unsigned char)(length >> 8));
  out.push_back((unsigned char)(length & 0xff));
  out.insert(out.end(), payload.begin(), payload.end());
  out.insert(out.end(), jpeg.begin() + rest, jpeg.end());
  WriteAtomically(path, [&](const std::string& tmp) {
    std::ofstream file(tmp, std::ios::binary);
    file.write(reinterpret_cast<const char*>(out.data()), std::streamsize(out.size()));
    file.close();
    if (!file) throw IoError(path, "cannot write the JPEG");
  });
}

}  // namespace lumislab
