#include "lib/photo/exif.h"

#include <libexif/exif-data.h>
#include <tiffio.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <vector>

#include "core/error.h"
#include "lib/photo/photo_format.h"
#include "lib/photo/raw_decode.h"

namespace lumislab {
namespace {

std::optional<std::string> Text(const char* data, size_t size) {
  std::string s(data, strnlen(data, size));
  while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
  if (s.empty()) return std::nullopt;
  return s;
}

std::optional<double> Positive(double v) {
  if (!(v > 0) || !std::isfinite(v)) return std::nullopt;
  return v;
}

// EXIF Orientation is 1 .. 8; another value is no statement (decoders take it as 1).
std::optional<int> ValidOrientation(std::optional<double> v) {
  if (!v || *v < 1 || *v > 8 || *v != std::floor(*v)) return std::nullopt;
  return int(*v);
}

// The payload of a JPEG's EXIF APP1 segment ("Exif\0\0" + TIFF structure); empty when there is
// none. Walks the marker segments up to the start of the image data.
std::vector<unsigned char> JpegExifSegment(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char b[4];
  if (!in.read(reinterpret_cast<char*>(b), 2) || b[0] != 0xff || b[1] != 0xd8) return {};
  for (;;) {
    if (!in.read(reinterpret_cast<char*>(b), 2) || b[0] != 0xff) return {};
    const int marker = b[1];
    if (marker == 0xd9 || marker == 0xda) return {};  // EOI, SOS: no more metadata
    if (marker == 0xff || marker == 0x01 || (marker >= 0xd0 && marker <= 0xd7)) {
      if (marker == 0xff) in.seekg(-1, std::ios::cur);  // fill byte
      continue;
    }
    if (!in.read(reinterpret_cast<char*>(b), 2)) return {};
    const int length = (b[0] << 8 | b[1]) - 2;
    if (length < 0) return {};
    if (marker == 0xe1 && length >= 6) {
      std::vector<unsigned char> data(size_t(length), 0);
      if (!in.read(reinterpret_cast<char*>(data.data()), length))
        throw BadInput(path + ": corrupt EXIF (the APP1 segment runs past the end of the file)");
      if (std::memcmp(data.data(), "Exif\0\0", 6) == 0) return data;
    } else {
      in.seekg(length, std::ios::cur);
    }
  }
}

PhotoExif ReadJpegExif(const std::string& path) {
  const std::vector<unsigned char> data = JpegExifSegment(path);
  PhotoExif exif;
  if (data.empty()) return exif;
  // The TIFF header inside: byte order, 42, and an IFD0 offset within the segment.
  const unsigned char* t = data.data() + 6;
  const size_t size = data.size() - 6;
  const bool le = size >= 8 && std::memcmp(t, "II*\0", 4) == 0;
  const bool be = size >= 8 && std::memcmp(t, "MM\0*", 4) == 0;
  const uint32_t ifd0 = size < 8 ? 0
                        : le     ? uint32_t(t[4] | t[5] << 8 | t[6] << 16 | uint32_t(t[7]) << 24)
                                 : uint32_t(uint32_t(t[4]) << 24 | t[5] << 16 | t[6] << 8 | t[7]);
  if (!(le || be) || ifd0 < 8 || size_t(ifd0) + 2 > size)
    throw BadInput(path + ": corrupt EXIF (no valid TIFF header in the APP1 segment)");

  std::unique_ptr<ExifData, void (*)(ExifData*)> ed(exif_data_new(), exif_data_unref);
  if (!ed) throw Failure("ReadPhotoExif: out of memory");
  // Read what is there: no "fixing" (libexif would add mandatory tags with made-up values).
  exif_data_unset_option(ed.get(), EXIF_DATA_OPTION_FOLLOW_SPECIFICATION);
  exif_data_load_data(ed.get(), data.data(), unsigned(data.size()));
  if (!ed->ifd[EXIF_IFD_0] || ed->ifd[EXIF_IFD_0]->count == 0)
    throw BadInput(path + ": corrupt EXIF (IFD0 holds no readable entry)");
  const ExifByteOrder order = exif_data_get_byte_order(ed.get());

  auto entry = [&](ExifIfd ifd, ExifTag tag) -> ExifEntry* {
    ExifEntry* e = ed->ifd[ifd] ? exif_content_get_entry(ed->ifd[ifd], tag) : nullptr;
    if (!e || !e->data || e->components == 0) return nullptr;
    if (e->size < exif_format_get_size(e->format) * e->components) return nullptr;
    return e;
  };
  auto real = [&](ExifIfd ifd, ExifTag tag) -> std::optional<double> {
    const ExifEntry* e = entry(ifd, tag);
    if (!e) return std::nullopt;
    if (e->format == EXIF_FORMAT_RATIONAL) {
      const ExifRational r = exif_get_rational(e->data, order);
      return r.denominator ? Positive(double(r.numerator) / r.denominator) : std::nullopt;
    }
    if (e->format == EXIF_FORMAT_SHORT) return Positive(exif_get_short(e->data, order));
    if (e->format == EXIF_FORMAT_LONG) return Positive(exif_get_long(e->data, order));
    return std::nullopt;
  };
  auto text = [&](ExifIfd ifd, ExifTag tag) -> std::optional<std::string> {
    const ExifEntry* e = entry(ifd, tag);
    if (!e || e->format != EXIF_FORMAT_ASCII) return std::nullopt;
    return Text(reinterpret_cast<const char*>(e->data), e->size);
  };
  exif.exposure_time = real(EXIF_IFD_EXIF, EXIF_TAG_EXPOSURE_TIME);
  exif.f_number = real(EXIF_IFD_EXIF, EXIF_TAG_FNUMBER);
  exif.iso = real(EXIF_IFD_EXIF, EXIF_TAG_ISO_SPEED_RATINGS);
  exif.make = text(EXIF_IFD_0, EXIF_TAG_MAKE);
  exif.model = text(EXIF_IFD_0, EXIF_TAG_MODEL);
  exif.lens_model = text(EXIF_IFD_EXIF, EXIF_TAG_LENS_MODEL);
  exif.focal_length = real(EXIF_IFD_EXIF, EXIF_TAG_FOCAL_LENGTH);
  exif.orientation = ValidOrientation(real(EXIF_IFD_0, EXIF_TAG_ORIENTATION));
  exif.date_time = text(EXIF_IFD_EXIF, EXIF_TAG_DATE_TIME_ORIGINAL);
  if (!exif.date_time) exif.date_time = text(EXIF_IFD_0, EXIF_TAG_DATE_TIME);
  return exif;
}

// libtiff's messages are collected rather than printed; the caller reports the file.
int QuietTiff(TIFF*, void*, const char*, const char*, va_list) { return 1; }

PhotoExif ReadTiffExif(const std::string& path) {
  std::unique_ptr<TIFFOpenOptions, void (*)(TIFFOpenOptions*)> options(TIFFOpenOptionsAlloc(),
                                                                       TIFFOpenOptionsFree);
  TIFFOpenOptionsSetErrorHandlerExtR(options.get(), &QuietTiff, nullptr);
  TIFFOpenOptionsSetWarningHandlerExtR(options.get(), &QuietTiff, nullptr);
  std::unique_ptr<TIFF, void (*)(TIFF*)> tif(TIFFOpenExt(path.c_str(), "r", options.get()),
                                             TIFFClose);
  if (!tif) throw BadInput(path + ": cannot read the TIFF's tags (corrupt file)");
  PhotoExif exif;
  auto text = [&](uint32_t tag) -> std::optional<std::string> {
    const char* s = nullptr;
    if (!TIFFGetField(tif.get(), tag, &s) || !s) return std::nullopt;
    return Text(s, std::strlen(s));
  };
  exif.make = text(TIFFTAG_MAKE);
  exif.model = text(TIFFTAG_MODEL);
  exif.date_time = text(TIFFTAG_DATETIME);
  uint16_t orientation = 0;  // IFD0's, read before the EXIF directory replaces it
  if (TIFFGetField(tif.get(), TIFFTAG_ORIENTATION, &orientation))
    exif.orientation = ValidOrientation(double(orientation));
  uint64_t offset = 0;
  if (!TIFFGetField(tif.get(), TIFFTAG_EXIFIFD, &offset)) return exif;
  if (!TIFFReadEXIFDirectory(tif.get(), offset))
    throw BadInput(path + ": corrupt EXIF (the EXIF directory cannot be read)");
  auto real = [&](uint32_t tag) -> std::optional<double> {
    const TIFFField* field = TIFFFieldWithTag(tif.get(), tag);
    if (!field) return std::nullopt;
    if (TIFFFieldSetGetSize(field) == 4) {
      float v = 0;
      return TIFFGetField(tif.get(), tag, &v) ? Positive(v) : std::nullopt;
    }
    double v = 0;
    return TIFFGetField(tif.get(), tag, &v) ? Positive(v) : std::nullopt;
  };
  exif.exposure_time = real(EXIFTAG_EXPOSURETIME);
  exif.f_number = real(EXIFTAG_FNUMBER);
  uint16_t count = 0;
  uint16_t* iso = nullptr;
  if (TIFFGetField(tif.get(), EXIFTAG_ISOSPEEDRATINGS, &count, &iso) && count > 0 && iso)
    exif.iso = Positive(iso[0]);
  exif.lens_model = text(EXIFTAG_LENSMODEL);
  exif.focal_length = real(EXIFTAG_FOCALLENGTH);
  if (auto original = text(EXIFTAG_DATETIMEORIGINAL)) exif.date_time = original;
  return exif;
}

}  // namespace

std::optional<double> PhotoExif::RelativeExposure() const {
  if (!exposure_time || !f_number || !iso) return std::nullopt;
  return *exposure_time * *iso / (*f_number * *f_number);
}

PhotoExif ReadPhotoExif(const std::string& path) {
  switch (DetectPhotoFormat(path)) {  // BadInput when not a photo
    case PhotoFormat::kJpeg:
      return ReadJpegExif(path);
    case PhotoFormat::kTiff:
      return ReadTiffExif(path);
    case PhotoFormat::kRaw:
      return ReadRawExif(path);
    case PhotoFormat::kPng:
    case PhotoFormat::kExr:
      break;
  }
  return {};
}

}  // namespace lumislab
