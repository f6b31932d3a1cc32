#include "core/exr_io.h"

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"

namespace lumislab {

void WriteExr(const std::string& path, const ImageF& image,
              const std::vector<std::string>& channel_names, const ExrAttributes& attributes,
              const ExrOptions& options) {
  if (int(channel_names.size()) != image.channels || image.empty())
    throw Failure(path + ": WriteExr: channel names do not match the image");
  // A non-finite value never reaches a file.
  for (float v : image.data)
    if (!std::isfinite(v)) throw Failure(path + ": refusing to write a NaN or infinite value");
  WriteAtomically(path, [&](const std::string& tmp) {
    try {
      Imf::Header header(image.width, image.height);
      header.compression() = options.compression == ExrCompression::kPiz   ? Imf::PIZ_COMPRESSION
                             : options.compression == ExrCompression::kRle ? Imf::RLE_COMPRESSION
                                                                           : Imf::NO_COMPRESSION;
      const Imf::PixelType type = options.half ? Imf::HALF : Imf::FLOAT;
      for (const auto& name : channel_names) header.channels().insert(name, Imf::Channel(type));
      for (const auto& [k, v] : attributes.strings) header.insert(k, Imf::StringAttribute(v));
      for (const auto& [k, v] : attributes.doubles) header.insert(k, Imf::DoubleAttribute(v));
      for (const auto& [k, v] : attributes.ints) header.insert(k, Imf::IntAttribute(v));
      // Half channels need half data: one interleaved copy, converted in one pass.
      std::vector<half> halves(options.half ? image.data.size() : 0);
      for (size_t k = 0; k < halves.size(); ++k) halves[k] = half(image.data[k]);
      Imf::FrameBuffer fb;
      const size_t size = options.half ? sizeof(half) : sizeof(float);
      const size_t xs = size * image.channels;
      char* base = options.half ? reinterpret_cast<char*>(halves.data())
                                : reinterpret_cast<char*>(const_cast<float*>(image.data.data()));
      for (int c = 0; c < image.channels; ++c)
        fb.insert(channel_names[c], Imf::Slice(options.half ? Imf::HALF : Imf::FLOAT,
                                               base + c * size, xs, xs * image.width));
      Imf::OutputFile file(tmp.c_str(), header);
      file.setFrameBuffer(fb);
      file.writePixels(image.height);
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      throw IoError(path, std::string("cannot write EXR: ") + e.what());
    }
  });
}

namespace {

// OpenEXR allocates each header attribute at the size the file states before reading it, so a
// 1 KB file claiming a 2 GB attribute costs 2 GB (found by fuzz_slab_position). The header is
// walked here first, the way OpenEXR reads it: magic, version, then per part the attributes
// (name, type, int32 size, value) up to the empty name. Names and type names must end within
// OpenEXR's limit (31 bytes, 255 with the long-names flag); every size must fit in what is left
// of the file; and since OpenEXR reads a known type by its own rules, not by the stated size
// (fixed-size types their bytes, a channel list up to its empty name, a preview image its
// width x height pixels), the stated size must be exactly what that reading takes, so that
// OpenEXR and this walk never part ways. Throws BadInput naming the file and what is wrong;
// `strict` false returns false instead.
int FixedAttributeSize(const std::string& type) {
  static const std::pair<const char*, int> kFixed[] = {
      {"int", 4},         {"float", 4},     {"double", 8},   {"box2i", 16},         {"box2f", 16},
      {"v2i", 8},         {"v2f", 8},       {"v2d", 16},     {"v3i", 12},           {"v3f", 12},
      {"v3d", 24},        {"m33f", 36},     {"m33d", 72},    {"m44f", 64},          {"m44d", 128},
      {"compression", 1}, {"lineOrder", 1}, {"envmap", 1},   {"deepImageState", 1}, {"rational", 8},
      {"tiledesc", 9},    {"timecode", 8},  {"keycode", 28}, {"chromaticities", 32}};
  for (const auto& [name, size] : kFixed)
    if (type == name) return size;
  return -1;
}

bool CheckExrHeader(const std::string& path, bool strict) {
  auto fail = [&](const std::string& what) -> bool {
    if (strict) throw BadInput(path + ": not a readable EXR file: header: " + what);
    return false;
  };
  std::ifstream in(path, std::ios::binary);
  in.seekg(0, std::ios::end);
  const std::streamoff file_size = in.tellg();
  in.seekg(0);
  unsigned char start[8];
  if (!in.read(reinterpret_cast<char*>(start), 8)) return fail("shorter than 8 bytes");
  if (!(start[0] == 0x76 && start[1] == 0x2f && start[2] == 0x31 && start[3] == 0x01))
    return fail("no EXR magic number");
  const bool long_names = start[5] & 0x04;  // version flags, bit 10
  const bool multipart = start[5] & 0x10;   // bit 12
  const size_t max_name = long_names ? 255 : 31;
  auto read_string = [&](std::string* out, size_t max = 0) {
    out->clear();
    for (char c; in.get(c);) {
      if (c == '\0') return true;
      if (out->size() >= (max ? max : max_name)) return false;
      *out += c;
    }
    return false;
  };
  auto read_int = [&](int64_t* v) {
    unsigned char b[4];
    if (!in.read(reinterpret_cast<char*>(b), 4)) return false;
    *v =
        int32_t(uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24);
    return true;
  };
  for (int part = 0;; ++part) {
    std::string name, type;
    int attributes = 0;
    // What OpenEXR sizes its buffers by when it opens the file, checked after the part's header.
    int64_t window[4] = {0, 0, -1, -1};  // dataWindow xMin, yMin, xMax, yMax
    bool has_window = false;
    int compression = 0, channels = 0;
    int64_t tile_x = 0, tile_y = 0;  // 0: scan lines
    for (;; ++attributes) {
      if (!read_string(&name)) return fail("an attribute name that does not end in time");
      if (name.empty()) break;  // end of this part's header
      const std::string what = "attribute " + name.substr(0, 31) + ": ";
      if (!read_string(&type)) return fail(what + "a type name that does not end in time");
      int64_t size = 0;
      if (!read_int(&size)) return fail(what + "no size");
      const std::streamoff value_start = in.tellg();
      if (size < 0 || size > file_size - value_start)
        return fail(what + "size " + std::to_string(size) + " bytes, more than the file holds");
      const int fixed = FixedAttributeSize(type);
      if (fixed >= 0 && size != fixed)
        return fail(what + "a " + type + " of " + std::to_string(fixed) + " bytes, stated as " +
                    std::to_string(size));
      if (name == "dataWindow" && type == "box2i") {
        for (int64_t& v : window)
          if (!read_int(&v)) return fail(what + "shorter than its 16 bytes");
        has_window = true;
      } else if (name == "compression" && type == "compression") {
        compression = in.get();
      } else if (name == "tiles" && type == "tiledesc") {
        if (!read_int(&tile_x) || !read_int(&tile_y)) return fail(what + "shorter than 9 bytes");
        tile_x = uint32_t(tile_x), tile_y = uint32_t(tile_y);  // unsigned in the file
      }
      if (type == "chlist") {  // channels up to an empty name, 16 bytes after each name
        std::string channel;
        do {
          if (!read_string(&channel, 255)) return fail(what + "a channel name that does not end");
          if (!channel.empty()) in.seekg(16, std::ios::cur), ++channels;
        } while (!channel.empty() && in && in.tellg() - value_start <= size);
        if (!in || in.tellg() - value_start != size)
          return fail(what + "a channel list that does not fill its " + std::to_string(size) +
                      " bytes");
      } else if (type == "preview") {  // width, height, then width x height RGBA bytes
        int64_t width = 0, height = 0;
        // Each side at most the size first, so that the product cannot overflow.
        if (size < 8 || !read_int(&width) || !read_int(&height) || width < 0 || height < 0 ||
            width > size || height > size || 8 + 4 * width * height != size)
          return fail(what + "a preview image whose pixels are not its " + std::to_string(size) +
                      " bytes");
      } else if (type == "stringvector") {  // strings of int32 length each, within the size
        int64_t read = 0;
        while (read < size) {
          int64_t length = 0;
          if (!read_int(&length) || length < 0 || read + 4 + length > size)
            return fail(what + "a string longer than the attribute");
          in.seekg(length, std::ios::cur);
          read += 4 + length;
        }
      }
      in.seekg(value_start + size);
    }
    if (attributes > 0) {
      // OpenEXR allocates a line or tile buffer (and an offset table) from these before reading
      // a pixel: a 1 KB file claiming a 2^31-wide window made it allocate and clear gigabytes
      // (found by fuzz_slab_position). Bound them by what lumislab reads: at most 2^15 pixels a
      // side, kMaxExrPixels in all, and a decode buffer of at most 256 MiB.
      if (!has_window) return fail("no dataWindow");
      const int64_t width = window[2] - window[0] + 1, height = window[3] - window[1] + 1;
      if (width <= 0 || height <= 0 || width > 1 << 15 || height > 1 << 15 ||
          width * height > kMaxExrPixels)
        return fail("dataWindow of " + std::to_string(width) + " x " + std::to_string(height) +
                    " pixels, not within 1 .. 32768 a side and " + std::to_string(kMaxExrPixels) +
                    " in all");
      // Scan lines per compressed block, by OpenEXR's compression codes (NO, RLE, ZIPS: 1; ZIP,
      // PXR24: 16; PIZ, B44, B44A, DWAA: 32; DWAB: 256).
      static const int kLines[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
      const int64_t lines = compression >= 0 && compression < 10 ? kLines[compression] : 256;
      const int64_t block = tile_x > 0 || tile_y > 0 ? std::min<int64_t>(tile_x, width) *
                                                           std::min<int64_t>(tile_y, height)
                                                     : width * std::min(lines, height);
      if (tile_x < 0 || tile_y < 0 || ((tile_x > 0 || tile_y > 0) && (tile_x == 0 || tile_y == 0)))
        return fail("a tile size of " + std::to_string(tile_x) + " x " + std::to_string(tile_y));
      if (tile_x > 0 && (width + tile_x - 1) / tile_x * ((height + tile_y - 1) / tile_y) > 1 << 20)
        return fail("more than 2^20 tiles of " + std::to_string(tile_x) + " x " +
                    std::to_string(tile_y));
      if (block * std::max(channels, 1) * 4 > int64_t(256) << 20)
        return fail(std::to_string(channels) + " channels of " + std::to_string(width) +
                    " pixels a line: a decode buffer over 256 MiB");
    }
    // A single part ends with its header; multipart headers end with an empty one.
    if (!multipart || attributes == 0) break;
    if (part > 4096) return fail("more than 4096 parts");
  }
  return true;
}

}  // namespace

ImageF ReadExr(const std::string& path, const std::vector<std::string>& channel_names,
               ExrAttributes* attributes) {
  CheckInputFile(path, "EXR file");
  CheckExrHeader(path, true);
  try {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    const Imath::Box2i dw = header.dataWindow();
    const int width = dw.max.x - dw.min.x + 1, height = dw.max.y - dw.min.y + 1;
    if (width <= 0 || height <= 0 || width > 1 << 15 || height > 1 << 15 ||
        (long long)width * height > kMaxExrPixels)
      throw InputError(path, "dataWindow",
                       "an image of at most " + std::to_string(kMaxExrPixels) + " pixels",
                       std::to_string(width) + "x" + std::to_string(height));
    ImageF image(width, height, int(channel_names.size()));
    Imf::FrameBuffer fb;
    const size_t xs = sizeof(float) * image.channels;
    for (int c = 0; c < image.channels; ++c) {
      if (header.channels().findChannel(channel_names[c]) == nullptr)
        throw InputError(path, "channel " + channel_names[c], "present", "missing");
      // Offset so that pixel (dw.min.x, dw.min.y) lands at index 0.
      char* base = reinterpret_cast<char*>(image.data.data() + c) -
                   (ptrdiff_t(dw.min.x) + ptrdiff_t(dw.min.y) * width) * ptrdiff_t(xs);
      fb.insert(channel_names[c], Imf::Slice(Imf::FLOAT, base, xs, xs * width));
    }
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    if (attributes) {
      for (auto it = header.begin(); it != header.end(); ++it) {
        const std::string name = it.name();
        if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
          attributes->strings[name] = s->value();
        else if (auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&it.attribute()))
          attributes->doubles[name] = d->value();
        else if (auto* i = dynamic_cast<const Imf::IntAttribute*>(&it.attribute()))
          attributes->ints[name] = i->value();
      }
    }
    return image;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw BadInput(path + ": not a readable EXR file: " + e.what());
  }
}

bool ExrComplete(const std::string& path, int width, int height) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec) || !CheckExrHeader(path, false)) return false;
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    if (dw.max.x - dw.min.x + 1 != width || dw.max.y - dw.min.y + 1 != height || !file.isComplete())
      return false;
    // isComplete() only checks the offset table: read the last block's bytes too, which a
    // truncated file does not hold.
    const char* data = nullptr;
    int size = 0;
    file.rawPixelData(dw.max.y, data, size);
    return size > 0;
  } catch (const std::exception&) {
    return false;
  }
}

std::vector<std::string> ExrChannelNames(const std::string& path) {
  CheckInputFile(path, "EXR file");
  CheckExrHeader(path, true);
  try {
    Imf::InputFile file(path.c_str());
    std::vector<std::string> names;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it)
      names.push_back(it.name());
    return names;
  } catch (const std::exception& e) {
    throw BadInput(path + ": not a readable EXR file: " + e.what());
  }
}

}  // namespace lumislab
