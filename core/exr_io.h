// The one EXR reader/writer (OpenEXR). Float channels plus typed header attributes.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/image.h"

namespace lumislab {

struct ExrAttributes {
  std::map<std::string, std::string> strings;
  std::map<std::string, double> doubles;
  std::map<std::string, int> ints;
};

enum class ExrCompression {
  kNone,
  kRle,  // run lengths: cheap to write; on smooth half-float photos much smaller than none
  kPiz,  // wavelet + Huffman: the smallest on half data, but slower to write than RLE there;
         // on 32-bit float photos much smaller than none but many times slower to write
};

struct ExrOptions {
  bool half = false;  // store HALF instead of FLOAT
  ExrCompression compression = ExrCompression::kPiz;
};

// Writes image channels named `channel_names` (size == image.channels) atomically.
void WriteExr(const std::string& path, const ImageF& image,
              const std::vector<std::string>& channel_names, const ExrAttributes& attributes = {},
              const ExrOptions& options = {});
// Reads the named channels (missing channel -> BadInput naming file and channel). If
// `attributes` is given, fills it with the string/double/int attributes of the header.
ImageF ReadExr(const std::string& path, const std::vector<std::string>& channel_names,
               ExrAttributes* attributes = nullptr);
std::vector<std::string> ExrChannelNames(const std::string& path);

// Largest image ReadExr allocates (pixels): a header may claim any size, the file need not hold it.
constexpr long long kMaxExrPixels = 1LL << 26;  // 8192 x 8192
// True when `path` is a complete EXR file (every line block present) of width x height pixels:
// what a resumed run checks before it trusts a file it skips.
bool ExrComplete(const std::string& path, int width, int height);

}  // namespace lumislab
