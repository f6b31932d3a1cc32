#include "core/exr_io.h"

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

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
// walked here first: magic, version, then per part the attributes (name, type, int32 size,
// value) up to the empty name; every size must fit in what is left of the file. Throws
// BadInput naming the file and what is wrong; `strict` false returns false instead.
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
  const bool multipart = start[5] & 0x10;  // version flags, bit 12
  auto read_string = [&](std::string* out) {
    out->clear();
    for (char c; in.get(c);) {
      if (c == '\0') return true;
      if (out->size() >= 255) return false;
      *out += c;
    }
    return false;
  };
  for (int part = 0;; ++part) {
    std::string name, type;
    int attributes = 0;
    for (;; ++attributes) {
      if (!read_string(&name)) return fail("an attribute name that does not end");
      if (name.empty()) break;  // end of this part's header
      if (!read_string(&type)) return fail("attribute " + name + ": a type that does not end");
      unsigned char size_bytes[4];
      if (!in.read(reinterpret_cast<char*>(size_bytes), 4))
        return fail("attribute " + name + ": no size");
      const int64_t size = int32_t(uint32_t(size_bytes[0]) | uint32_t(size_bytes[1]) << 8 |
                                   uint32_t(size_bytes[2]) << 16 | uint32_t(size_bytes[3]) << 24);
      if (size < 0 || size > file_size - in.tellg())
        return fail("attribute " + name + ": size " + std::to_string(size) +
                    " bytes, more than the file holds");
      in.seekg(size, std::ios::cur);
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
