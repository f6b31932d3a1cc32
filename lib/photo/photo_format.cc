#include "lib/photo/photo_format.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>

#include "core/error.h"
#include "core/input_file.h"
#include "lib/photo/raw_decode.h"

namespace lumislab {
namespace {

// Which of DNGVersion (50706) and Make (271) the first IFD of a TIFF container holds. Reads the
// IFD's entries only (at most 4096); a cut or odd IFD counts as holding neither, and the
// decoder then reports what is wrong with the file.
struct TiffTags {
  bool dng_version = false, make = false;
};
TiffTags ScanFirstIfd(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char header[8];
  TiffTags tags;
  if (!in.read(reinterpret_cast<char*>(header), 8)) return tags;
  const bool big = header[0] == 'M';
  auto get = [&](const unsigned char* b, int n) {
    uint32_t v = 0;
    for (int k = 0; k < n; ++k) v |= uint32_t(b[big ? k : n - 1 - k]) << (8 * (n - 1 - k));
    return v;
  };
  unsigned char count_bytes[2];
  in.seekg(std::streamoff(get(header + 4, 4)));
  if (!in.read(reinterpret_cast<char*>(count_bytes), 2)) return tags;
  const uint32_t count = std::min<uint32_t>(get(count_bytes, 2), 4096);
  for (uint32_t k = 0; k < count; ++k) {
    unsigned char entry[12];
    if (!in.read(reinterpret_cast<char*>(entry), 12)) break;
    const uint32_t tag = get(entry, 2);
    tags.dng_version |= tag == 50706;
    tags.make |= tag == 271;
  }
  return tags;
}

// Camera RAW containers other than TIFF that LibRaw is asked about (ORF, RW2, RAF, CR3). Only
// these: LibRaw also identifies headerless RAWs by their file size alone, which garbage can
// match.
bool RawMagic(const unsigned char* m) {
  return std::memcmp(m, "IIRO", 4) == 0 || std::memcmp(m, "IIRS", 4) == 0 ||
         std::memcmp(m, "MMOR", 4) == 0 || std::memcmp(m, "IIU\0", 4) == 0 ||
         std::memcmp(m, "FUJIFILM", 8) == 0 || std::memcmp(m + 4, "ftypcrx ", 8) == 0;
}

}  // namespace

const char* PhotoFormatName(PhotoFormat format) {
  switch (format) {
    case PhotoFormat::kPng:
      return "PNG";
    case PhotoFormat::kJpeg:
      return "JPEG";
    case PhotoFormat::kTiff:
      return "TIFF";
    case PhotoFormat::kExr:
      return "EXR";
    case PhotoFormat::kRaw:
      return "camera RAW";
  }
  return "?";
}

PhotoFormat DetectPhotoFormat(const std::string& path) {
  CheckInputFile(path, "photo");
  unsigned char magic[12] = {};
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(magic), sizeof magic);
  if (!in && in.gcount() < 4) throw BadInput(path + ": not a photo (file too short)");
  if (std::memcmp(magic, "\x89PNG\r\n\x1a\n", 8) == 0) return PhotoFormat::kPng;
  if (magic[0] == 0xff && magic[1] == 0xd8 && magic[2] == 0xff) return PhotoFormat::kJpeg;
  if (std::memcmp(magic, "II*\0", 4) == 0 || std::memcmp(magic, "MM\0*", 4) == 0) {
    const TiffTags tags = ScanFirstIfd(path);
    const bool cr2 = magic[8] == 'C' && magic[9] == 'R';
    if (tags.dng_version || cr2 || (tags.make && LibRawIdentifiesRaw(path)))
      return PhotoFormat::kRaw;
    return PhotoFormat::kTiff;
  }
  if (std::memcmp(magic, "\x76\x2f\x31\x01", 4) == 0) return PhotoFormat::kExr;
  if (RawMagic(magic) && LibRawIdentifiesRaw(path)) return PhotoFormat::kRaw;
  throw BadInput(path + ": not a photo lumislab reads (PNG, JPEG, TIFF, OpenEXR or camera RAW)");
}

}  // namespace lumislab
