// The bad-input catalogue: one table of cases over the five tools, each a mutation of a small
// valid input, the command that must refuse it, and what the refusal must look like
// (docs/architecture.md §7): exit code 2, one error line naming the file and the field, no crash,
// no hang, and nothing under the case folder changed (every file's bytes hashed before and after;
// only what a case allows may change) with no temporary file ('.' names, docs/architecture.md §7.5)
// left behind.
//
// The cases are written to the contract, not to today's behaviour: a failing case is a bug in a
// tool (or a contract to settle), never a reason to edit the expectation.
//
// Each case is a TEST_P; ctest runs them in 8 shards (Cli/Catalogue.shard<i>of8, each one process
// running every 8th case: tests/e2e/CMakeLists.txt; ctest -L catalogue runs them all; one case
// alone: bad_input_catalogue_test --gtest_filter='*/<name>'). The valid inputs (a 2x2 grid of
// 320x240 photos, 16-bit PNG and half-float EXR, calibrated, a 40x40 slab) are made once per build
// of the tools under a lock in the build tree (see Masters) and copied into a fresh folder per
// case; the tools run from the case folder (paths in messages read "ds/dataset.json"), through
// `timeout` and under `ulimit -v` 2 GiB, so a hang or an allocation of gigabytes fails the case
// instead of the machine. LUMISLAB_KEEP_CASES=1 keeps the case folders.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "test_util.h"

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace lumislab {
namespace {

using testing::CommandResult;
using testing::ReadBinaryFile;
using testing::RunToolIn;
using testing::SnapshotTree;
using testing::TreeSnapshot;
using testing::WriteBinaryFile;

const char kSceneFileName[] = "scene.json";
constexpr long kMemoryLimitKb = 2L << 20;  // ulimit -v: 2 GiB for every case
constexpr double kTimeoutS = 20;           // per tool run; a hang ends as exit 124
// The sanitized build runs a quarter of the cases (testing::InSanitizerSample): the ~400 tool
// runs under ASan took a quarter of CI's time.
constexpr int kSanitizerSampleEvery = 4;

// ------------------------------------------------------------------------------------------
// The valid inputs.

// The scene of tests/e2e/cli_bad_input_test.cc with smaller photos: 2x2 grid, 320x240 px.
std::string ValidScene(bool png) {
  json scene = {{"schema_version", 1},
                {"setup",
                 {{"distance_mm", 750},
                  {"grid", {{"nu", 2}, {"nv", 2}, {"spacing_mm", 5}}},
                  {"screen_mm", {1200, 1200}}}},
                {"luminaire",
                 {{"emitters",
                   {{{"position_mm", {1.5, -2, -20}},
                     {"intensity_w_sr", {1.0, 0.9, 0.8}},
                     {"lobe_exponent", 8}},
                    {{"position_mm", {-3, 1, -12}},
                     {"intensity_w_sr", {0.5, 0.6, 0.9}},
                     {"lobe_exponent", 3}}}}}},
                {"camera",
                 {{"size_px", {320, 240}},
                  {"focal_px", 280},
                  {"position_mm", {0, -200, 2400}},
                  {"look_at_mm", {0, 0, 750}}}},
                {"effects", png ? json::array({{{"type", "quantization"}, {"bit_depth", 16}}})
                                : json::array()}};
  return scene.dump(2) + "\n";
}

// What a case starts from (all under the case folder): scene.json (always), and ds/ at a stage.
enum class Input {
  kScene,          // scene.json only
  kDataset,        // ds/: acquired (16-bit PNG photos), no calib/, no slab/
  kCalibrated,     // ds/: + calib/screen.json
  kSlab,           // ds/: + slab/ (40x40, complete)
  kExrCalibrated,  // ds/: acquired with half-float EXR photos, + calib/screen.json
};

// The valid datasets, made once for a build of the tools and shared by every process (the
// shards, which ctest runs side by side, and single cases run by hand): making them in each
// (acquire, calibrate, reconstruct, each time) is what this saves. They live in the build tree
// under a key of the sizes and times of the tools and of this test, are made under an exclusive
// lock (flock) into a staging folder that is renamed into place, and are only ever read (each case
// works on its own copy).
class Masters {
 public:
  // The master dataset folder for `input` ("" for kScene); "" and `error` when making it failed.
  static std::string Get(Input input, std::string* error) {
    if (input == Input::kScene) return "";
    const std::string root = Root(error);
    if (root.empty()) return "";
    return root + (input == Input::kExrCalibrated ? "/exr/ds" : "/png/ds");
  }

 private:
  static std::string Key() {
    uint64_t key = 1469598103934665603ull;
    const std::string bin = std::string(LUMISLAB_BIN_DIR) + "/";
    // The tools that make the masters, and this test (which holds the scene).
    for (const std::string& file : {bin + "lumislab-acquire", bin + "lumislab-calibrate",
                                    bin + "lumislab-reconstruct", std::string("/proc/self/exe")}) {
      struct stat st {};
      stat(file.c_str(), &st);
      for (const uint64_t v :
           {uint64_t(st.st_size), uint64_t(st.st_mtim.tv_sec), uint64_t(st.st_mtim.tv_nsec)})
        key = (key ^ v) * 1099511628211ull;
    }
    std::ostringstream os;
    os << std::hex << key;
    return os.str();
  }
  static std::string Root(std::string* error) {
    static std::string root, failure;
    if (!root.empty() || !failure.empty()) {
      *error = failure;
      return root;
    }
    const std::string cache = LUMISLAB_CATALOGUE_CACHE;
    fs::create_directories(cache);
    const std::string dir = cache + "/" + Key();
    const int lock = open((cache + "/lock").c_str(), O_CREAT | O_RDWR, 0644);
    if (lock < 0 || flock(lock, LOCK_EX) != 0) {
      failure = "cannot lock " + cache + "/lock";
    } else {
      if (!fs::exists(dir + "/complete")) {
        // Masters of other builds of the tools are stale: remove them with any staging folder.
        for (const auto& entry : fs::directory_iterator(cache))
          if (entry.is_directory()) fs::remove_all(entry.path());
        const std::string staging = cache + "/.staging" + std::to_string(getpid());
        if (Build(staging + "/png", true, &failure) && Build(staging + "/exr", false, &failure)) {
          testing::WriteFile(staging + "/complete", "");
          fs::rename(staging, dir);
        }
        fs::remove_all(staging);
      }
      flock(lock, LOCK_UN);
    }
    if (lock >= 0) close(lock);
    if (failure.empty()) root = dir;
    *error = failure;
    return root;
  }
  // acquire + calibrate (+ reconstruct at 40x40 for the PNG dataset) into dir/ds.
  static bool Build(const std::string& dir, bool png, std::string* error) {
    auto run = [&](const std::string& tool, const std::string& args) {
      const CommandResult r = RunToolIn(dir, tool, args, 120);
      if (r.exit_code != 0)
        *error += tool + " " + args + " -> " + std::to_string(r.exit_code) + "\n" + r.output;
      return r.exit_code == 0;
    };
    fs::create_directories(dir);
    testing::WriteFile(dir + "/scene.json", ValidScene(png));
    return run("lumislab-acquire", "synth --scene scene.json --out ds --truth-resolution 40") &&
           run("lumislab-calibrate", "screen --dataset ds") &&
           (!png || run("lumislab-reconstruct", "--dataset ds --resolution 40"));
  }
};

// ------------------------------------------------------------------------------------------
// Mutations: each changes the copy in the case folder (paths relative to it).

using Mutation = std::function<void(const std::string& dir)>;

json ReadJson(const std::string& path) { return json::parse(ReadBinaryFile(path)); }
void WriteJson(const std::string& path, const json& value) {
  WriteBinaryFile(path, value.dump(2) + "\n");
}

Mutation EditJson(const std::string& file, std::function<void(json&)> edit) {
  return [=](const std::string& dir) {
    json value = ReadJson(dir + "/" + file);
    edit(value);
    WriteJson(dir + "/" + file, value);
  };
}
Mutation SetJson(const std::string& file, const std::string& pointer, const json& value) {
  return EditJson(file, [=](json& j) { j[json::json_pointer(pointer)] = value; });
}
// Puts `raw` text (not necessarily JSON: NaN, 1e999, 100000 nested arrays) where `pointer` is.
Mutation SetRaw(const std::string& file, const std::string& pointer, const std::string& raw) {
  return [=](const std::string& dir) {
    json value = ReadJson(dir + "/" + file);
    value[json::json_pointer(pointer)] = "@@RAW@@";
    std::string text = value.dump(2);
    text.replace(text.find("\"@@RAW@@\""), 9, raw);
    WriteBinaryFile(dir + "/" + file, text + "\n");
  };
}
Mutation EraseJson(const std::string& file, const std::string& pointer) {
  return EditJson(file, [=](json& j) {
    const json::json_pointer ptr(pointer);
    json& parent = j[ptr.parent_pointer()];
    const std::string last = ptr.back();
    if (parent.is_array())
      parent.erase(size_t(std::stoul(last)));
    else
      parent.erase(last);
  });
}
Mutation WriteText(const std::string& file, const std::string& text) {
  return [=](const std::string& dir) { WriteBinaryFile(dir + "/" + file, text); };
}
Mutation Truncate(const std::string& file, double keep_fraction) {
  return [=](const std::string& dir) {
    const std::string bytes = ReadBinaryFile(dir + "/" + file);
    WriteBinaryFile(dir + "/" + file, bytes.substr(0, size_t(bytes.size() * keep_fraction)));
  };
}
Mutation RemovePath(const std::string& path) {
  return [=](const std::string& dir) { fs::remove_all(dir + "/" + path); };
}
Mutation MakeFolder(const std::string& path) {
  return [=](const std::string& dir) {
    fs::remove_all(dir + "/" + path);
    fs::create_directories(dir + "/" + path + "/inside");
  };
}
Mutation MakeFifo(const std::string& path) {
  return [=](const std::string& dir) {
    fs::remove_all(dir + "/" + path);
    if (mkfifo((dir + "/" + path).c_str(), 0644) != 0) throw std::runtime_error("mkfifo failed");
  };
}
// `path` becomes a symbolic link to `target` (as written: relative to the link's folder).
Mutation MakeSymlink(const std::string& path, const std::string& target) {
  return [=](const std::string& dir) {
    fs::remove_all(dir + "/" + path);
    fs::create_symlink(target, dir + "/" + path);
  };
}
Mutation CopyPath(const std::string& from, const std::string& to) {
  return [=](const std::string& dir) {
    fs::remove_all(dir + "/" + to);
    fs::copy(dir + "/" + from, dir + "/" + to, fs::copy_options::recursive);
  };
}
std::string Nested(int depth) {
  return std::string(size_t(depth), '[') + std::string(size_t(depth), ']');
}
// A valid JSON file of `megabytes` MB: the file's own content plus a long string member.
Mutation Bloat(const std::string& file, int megabytes) {
  return EditJson(file, [=](json& j) { j["padding"] = std::string(size_t(megabytes) << 20, 'x'); });
}
std::string Garbage() {
  std::string bytes;
  uint32_t x = 12345;
  for (int k = 0; k < 4096; ++k) {
    x = x * 1664525u + 1013904223u;
    bytes += char(x >> 24);
  }
  return bytes;
}

// --- the lighting industry's files (docs/formats.md §17)

// tests/data/ies/7.ies (a real LM-63-2002 file: 37 gamma angles, one C plane) with `from`
// replaced by `to` (the first occurrence; "" leaves it whole), under `file`; keep_fraction < 1
// cuts it short.
Mutation RealIes(const std::string& file, const std::string& from = "", const std::string& to = "",
                 double keep_fraction = 1) {
  return [=](const std::string& dir) {
    std::string text = ReadBinaryFile(std::string(LUMISLAB_SOURCE_DIR) + "/tests/data/ies/7.ies");
    if (!from.empty()) {
      const size_t at = text.find(from);
      if (at == std::string::npos) throw std::runtime_error("7.ies has no \"" + from + "\"");
      text.replace(at, from.size(), to);
    }
    WriteBinaryFile(dir + "/" + file, text.substr(0, size_t(text.size() * keep_fraction)));
  };
}
// A small valid EULUMDAT file (Isym 1: one C plane, gamma 0, 45, 90 on lines 44-46, the
// intensities 300, 120, 0 on lines 47-49) with the lines of `edits` (1-based) replaced.
Mutation Ldt(const std::string& file, std::map<int, std::string> edits = {}) {
  return [=](const std::string& dir) {
    std::vector<std::string> lines = {
        "lumislab", "1",   "1", "1",  "0",  "3",   "45",   "catalogue", "lamp", "L-1", "lamp.ldt",
        "2026",     "100", "0", "50", "80", "0",   "0",    "0",         "0",    "0",   "100",
        "85",       "1",   "0", "1",  "1",  "LED", "1200", "3000K",     "80",   "15"};
    for (int k = 0; k < 10; ++k) lines.push_back("0.5");
    for (const char* v : {"0", "0", "45", "90", "300", "120", "0"}) lines.push_back(v);
    for (const auto& [line, value] : edits) lines.at(size_t(line - 1)) = value;
    std::string text;
    for (const auto& l : lines) text += l + "\n";
    WriteBinaryFile(dir + "/" + file, text);
  };
}
// A TM-25 ray file (little-endian, docs/formats.md §17) whose header says `header_rays` rays of
// luminous flux and which holds `rays` of them; `poison` >= 0 makes that ray's x NaN, `version`
// is the file version (2013 the valid one).
Mutation Tm25(const std::string& file, uint64_t header_rays, int rays, int poison = -1,
              int32_t version = 2013) {
  return [=](const std::string& dir) {
    std::string b;
    auto put = [&](const auto& v) { b.append(reinterpret_cast<const char*>(&v), sizeof v); };
    b += "TM25";
    put(version);
    put(int32_t(1));                               // measured
    put(float(rays));                              // luminous flux (lm)
    put(std::numeric_limits<float>::quiet_NaN());  // radiant flux: unknown
    put(header_rays);
    b.append(28, '\0');                                       // date
    for (int k = 0; k < 2; ++k) put(int32_t(0));              // ray start, spectral identifier
    for (int k = 0; k < 3; ++k) put(float(0));                // wavelengths
    for (int k = 0; k < 3; ++k) put(int32_t(0));              // tables, extra items, text block
    b.append(168, '\0');                                      // reserved
    for (int32_t flag : {1, 1, 0, 0, 1, 0, 0, 0}) put(flag);  // position, direction, luminous
    b.append(9 * 1000 * 4, '\0');                             // the description block
    for (int r = 0; r < rays; ++r) {
      const float x = r == poison ? std::numeric_limits<float>::quiet_NaN() : float(r);
      for (float v : {x, 0.f, 0.f, 0.f, 0.f, 1.f, 1.f}) put(v);
    }
    WriteBinaryFile(dir + "/" + file, b);
  };
}
// Emitter 0 of scene.json gets a measured distribution {"file": file, ...extra} instead of its
// cos^n lobe.
Mutation SceneDistribution(const std::string& file, json extra = json::object()) {
  return EditJson(kSceneFileName, [=](json& j) {
    json& e = j["luminaire"]["emitters"][0];
    e.erase("lobe_exponent");
    json d = {{"file", file}};
    d.update(extra);
    e["distribution"] = d;
  });
}

// --- images

cv::Mat ReadImage(const std::string& path) { return cv::imread(path, cv::IMREAD_UNCHANGED); }
void WriteImage(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image)) throw std::runtime_error("cannot write " + path);
}
// The same photo as 8-bit (a camera's sRGB output among 16-bit linear photos).
Mutation PngTo8Bit(const std::string& file) {
  return [=](const std::string& dir) {
    cv::Mat image = ReadImage(dir + "/" + file), out;
    image.convertTo(out, CV_8U, 1.0 / 257);
    WriteImage(dir + "/" + file, out);
  };
}
Mutation PngResize(const std::string& file, int width, int height) {
  return [=](const std::string& dir) {
    cv::Mat image = ReadImage(dir + "/" + file), out;
    cv::resize(image, out, cv::Size(width, height), 0, 0, cv::INTER_AREA);
    WriteImage(dir + "/" + file, out);
  };
}
// A 32-bit float TIFF under the photo's name (float data comes only from EXR, docs/formats.md §4).
Mutation FloatTiff(const std::string& file) {
  return [=](const std::string& dir) {
    cv::Mat image = ReadImage(dir + "/" + file), out;
    image.convertTo(out, CV_32F, 1.0 / 65535);
    std::vector<uchar> bytes;
    cv::imencode(".tiff", out, bytes);
    WriteBinaryFile(dir + "/" + file, std::string(bytes.begin(), bytes.end()));
  };
}

uint32_t Crc32(const std::string& bytes) {
  uint32_t crc = 0xffffffffu;
  for (const unsigned char c : bytes) {
    crc ^= c;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}
std::string Be32(uint32_t v) { return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; }
std::string PngChunk(const std::string& type, const std::string& data) {
  return Be32(uint32_t(data.size())) + type + data + Be32(Crc32(type + data));
}
// A PNG whose header claims width x height 16-bit RGB pixels and which holds none of them.
Mutation PngHugeHeader(const std::string& file, uint32_t width, uint32_t height) {
  return [=](const std::string& dir) {
    const std::string ihdr = Be32(width) + Be32(height) + std::string("\x10\x02\x00\x00\x00", 5);
    // A valid zlib stream of a few zero bytes: the decoder would have to allocate first.
    const std::string idat("\x78\x9c\x63\x00\x00\x00\x01\x00\x01", 9);
    WriteBinaryFile(dir + "/" + file, std::string("\x89PNG\r\n\x1a\n", 8) + PngChunk("IHDR", ihdr) +
                                          PngChunk("IDAT", idat) + PngChunk("IEND", ""));
  };
}

// An EXR read as FLOAT channels with its header, to be changed and written back.
struct ExrImage {
  Imf::Header header;
  int width = 0, height = 0;
  std::map<std::string, std::vector<float>> channels;
};
ExrImage ReadAnyExr(const std::string& path) {
  Imf::InputFile in(path.c_str());
  ExrImage image;
  image.header = in.header();
  const Imath::Box2i dw = in.header().dataWindow();
  image.width = dw.max.x - dw.min.x + 1;
  image.height = dw.max.y - dw.min.y + 1;
  Imf::FrameBuffer fb;
  for (auto it = in.header().channels().begin(); it != in.header().channels().end(); ++it) {
    auto& pixels = image.channels[it.name()];
    pixels.assign(size_t(image.width) * image.height, 0.f);
    char* base =
        reinterpret_cast<char*>(pixels.data()) -
        (ptrdiff_t(dw.min.x) + ptrdiff_t(dw.min.y) * image.width) * ptrdiff_t(sizeof(float));
    fb.insert(it.name(), Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * image.width));
  }
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  return image;
}
// Writes `image` as FLOAT channels with its header's attributes and a data window of its size.
void WriteAnyExr(const std::string& path, ExrImage image) {
  Imf::Header header = image.header;
  const Imath::Box2i box(Imath::V2i(0, 0), Imath::V2i(image.width - 1, image.height - 1));
  header.dataWindow() = box;
  header.displayWindow() = box;
  Imf::ChannelList channels;
  for (const auto& entry : image.channels) channels.insert(entry.first, Imf::Channel(Imf::FLOAT));
  header.channels() = channels;
  Imf::OutputFile out(path.c_str(), header);
  Imf::FrameBuffer fb;
  for (auto& entry : image.channels)
    fb.insert(entry.first, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(entry.second.data()),
                                      sizeof(float), sizeof(float) * image.width));
  out.setFrameBuffer(fb);
  out.writePixels(image.height);
}
Mutation EditExr(const std::string& file, std::function<void(ExrImage&)> edit) {
  return [=](const std::string& dir) {
    ExrImage image = ReadAnyExr(dir + "/" + file);
    edit(image);
    WriteAnyExr(dir + "/" + file, image);
  };
}
// A few values of `channel` set to `value` (NaN, Inf) in the middle of the image.
Mutation ExrPoison(const std::string& file, const std::string& channel, float value) {
  return EditExr(file, [=](ExrImage& image) {
    auto& pixels = image.channels.at(channel);
    const size_t centre = size_t(image.height / 2) * image.width + image.width / 2;
    for (size_t k = 0; k < 16; ++k) pixels[centre + k] = value;
  });
}
Mutation ExrResize(const std::string& file, int width, int height) {
  return EditExr(file, [=](ExrImage& image) {
    for (auto& entry : image.channels) {
      cv::Mat in(image.height, image.width, CV_32F, entry.second.data()), out;
      cv::resize(in, out, cv::Size(width, height), 0, 0, cv::INTER_AREA);
      entry.second.assign(out.begin<float>(), out.end<float>());
    }
    image.width = width;
    image.height = height;
  });
}
Mutation ExrDropChannel(const std::string& file, const std::string& channel) {
  return EditExr(file, [=](ExrImage& image) { image.channels.erase(channel); });
}
Mutation ExrSetInt(const std::string& file, const std::string& attribute, int value) {
  return EditExr(
      file, [=](ExrImage& image) { image.header.insert(attribute, Imf::IntAttribute(value)); });
}
// A header that claims width x height pixels of `channels` and not one line of them (OpenEXR
// writes the line-offset table as zeros): a reader must refuse it before allocating.
Mutation ExrHugeHeader(const std::string& file, std::vector<std::string> channels, int width,
                       int height) {
  return [=](const std::string& dir) {
    Imf::Header header(width, height);
    for (const auto& c : channels) header.channels().insert(c, Imf::Channel(Imf::HALF));
    header.compression() = Imf::ZIP_COMPRESSION;
    const std::string path = dir + "/" + file;
    fs::remove(path);
    Imf::OutputFile out(path.c_str(), header);
  };
}

// --- radiometric calibration (docs/formats.md §13 - §16)

// A frame (a dark, flat or bracketed photo) of width x height RGB pixels, `bits` 8 or 16:
// `fill` >= 0 sets every code to that fraction of full scale, otherwise a smooth ramp of codes
// from 5 % to 75 % of full scale (a lit scene, nothing clipped).
Mutation WriteFrame(const std::string& file, int width, int height, int bits, double fill = -1) {
  return [=](const std::string& dir) {
    const double full = bits == 8 ? 255 : 65535;
    cv::Mat image(height, width, bits == 8 ? CV_8UC3 : CV_16UC3);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        for (int c = 0; c < 3; ++c) {
          const double f =
              fill >= 0 ? fill : 0.05 + 0.7 * (x + y + 3.0 * c) / (width + height + 6.0);
          const double v = std::round(f * full);
          if (bits == 8)
            image.at<cv::Vec3b>(y, x)[c] = uchar(v);
          else
            image.at<cv::Vec3w>(y, x)[c] = ushort(v);
        }
    WriteImage(dir + "/" + file, image);
  };
}
// An EXR map of width x height: FLOAT channels, each filled with its value.
void WriteMap(const std::string& path, int width, int height,
              const std::map<std::string, float>& channels) {
  ExrImage image;
  image.header = Imf::Header(width, height);
  image.width = width;
  image.height = height;
  for (const auto& [name, value] : channels)
    image.channels[name].assign(size_t(width) * height, value);
  WriteAnyExr(path, image);
}
// A valid calib/<kind>.json (+ its map) as lumislab-calibrate writes it, for the 320x240
// photos: "dark" a constant level of 0.001 and no hot pixel, "response" code^2.2 per channel,
// "flat" gain 1, "scale" 10 W/m^2.
Mutation WriteCalibration(const std::string& kind) {
  return [=](const std::string& dir) {
    const std::string calib = dir + "/ds/calib/";
    fs::create_directories(calib);
    json j = {{"schema_version", 1}, {"kind", kind}, {"report", json::object()}};
    if (kind == "dark" || kind == "flat") {
      j["image_size"] = {320, 240};
      j["map"] = kind + ".exr";
    }
    if (kind == "dark") {
      j["model"] = "constant";
      WriteMap(calib + "dark.exr", 320, 240,
               {{"R", 1e-3f}, {"G", 1e-3f}, {"B", 1e-3f}, {"hot", 0}});
    } else if (kind == "flat") {
      WriteMap(calib + "flat.exr", 320, 240, {{"R", 1}, {"G", 1}, {"B", 1}});
    } else if (kind == "response") {
      j["bit_depth"] = 8;
      std::vector<double> curve(256);
      for (int k = 0; k < 256; ++k) curve[size_t(k)] = std::pow(k / 255.0, 2.2);
      j["linear_of_code"] = {{"R", curve}, {"G", curve}, {"B", curve}};
    } else {
      j["scale"] = 10.0;
      j["units"] = "W/m^2";
    }
    WriteJson(calib + kind + ".json", j);
  };
}

// ------------------------------------------------------------------------------------------
// The table.

struct Case {
  std::string name;
  Input input = Input::kScene;
  std::string tool;
  std::string args;
  std::vector<Mutation> mutations;
  std::vector<std::string> mentions;  // all on one output line
  int exit_code = 2;
  // 8-bit among 16-bit photos: exit 2 naming the file, or exit 0 with a warning naming it.
  bool warning_ok = false;
  std::vector<std::string> may_change;      // path prefixes, relative to the case folder
  std::vector<std::string> must_not_exist;  // even where may_change allows changes
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

const std::string kPreview = "--slab ds/slab --scene plane --size 32x32 --out r.exr";

// Fluent construction of a Case.
class C {
 public:
  explicit C(std::string name) { c_.name = std::move(name); }
  // lumislab-acquire synth on scene.json into out/ (nothing may appear there).
  C& Synth(const std::string& extra = "") {
    c_.tool = "lumislab-acquire";
    c_.args = "synth --scene scene.json --out out" + (extra.empty() ? "" : " " + extra);
    c_.input = Input::kScene;
    return *this;
  }
  C& Filter(const std::string& args) {
    c_.tool = "lumislab-acquire";
    c_.args = "filter --out filt " + args;
    c_.input = Input::kScene;
    return *this;
  }
  C& Calibrate(const std::string& extra = "") {
    c_.tool = "lumislab-calibrate";
    c_.args = "screen --dataset ds" + (extra.empty() ? "" : " " + extra);
    c_.input = Input::kDataset;
    return *this;
  }
  // lumislab-calibrate dark / response / flat / scale (args after the subcommand's name).
  C& Radiometric(const std::string& args, Input input = Input::kCalibrated) {
    c_.tool = "lumislab-calibrate";
    c_.args = args;
    c_.input = input;
    return *this;
  }
  C& Reconstruct(const std::string& extra = "") {
    c_.tool = "lumislab-reconstruct";
    c_.args = "--dataset ds --resolution 40" + (extra.empty() ? "" : " " + extra);
    c_.input = Input::kCalibrated;
    return *this;
  }
  C& ReconstructArgs(const std::string& args) {
    c_.tool = "lumislab-reconstruct";
    c_.args = args;
    c_.input = Input::kCalibrated;
    return *this;
  }
  C& Preview(const std::string& args = kPreview) {
    c_.tool = "lumislab-preview";
    c_.args = args;
    c_.input = Input::kSlab;
    return *this;
  }
  // lumislab-export (args from the subcommand on), on the complete 40x40 slab.
  C& Export(const std::string& args) {
    c_.tool = "lumislab-export";
    c_.args = args;
    c_.input = Input::kSlab;
    return *this;
  }
  // lumislab-plan (all its arguments), next to scene.json.
  C& Plan(const std::string& args) {
    c_.tool = "lumislab-plan";
    c_.args = args;
    c_.input = Input::kScene;
    return *this;
  }
  C& Args(const std::string& args) {
    c_.args = args;
    return *this;
  }
  C& From(Input input) {
    c_.input = input;
    return *this;
  }
  C& Do(Mutation m) {
    c_.mutations.push_back(std::move(m));
    return *this;
  }
  C& Names(std::vector<std::string> mentions) {
    c_.mentions = std::move(mentions);
    return *this;
  }
  C& Exit(int code) {
    c_.exit_code = code;
    return *this;
  }
  C& WarningOk() {
    c_.warning_ok = true;
    return *this;
  }
  C& MayChange(const std::string& prefix) {
    c_.may_change.push_back(prefix);
    return *this;
  }
  C& MustNotExist(const std::string& path) {
    c_.must_not_exist.push_back(path);
    return *this;
  }
  operator Case() const { return c_; }  // NOLINT: the table reads better without casts

 private:
  Case c_;
};

const std::string kDs = "ds/dataset.json";
const std::string kScr = "ds/calib/screen.json";
const std::string kSlabJson = "ds/slab/slab.json";
const std::string kSceneFile = "scene.json";

std::vector<Case> DatasetCases() {
  std::vector<Case> v;
  auto R = [](const std::string& name) { return C("dataset_" + name).Reconstruct(); };
  auto K = [](const std::string& name) { return C("dataset_" + name).Calibrate(); };
  // Whole file.
  v.push_back(R("missing").Do(RemovePath(kDs)).Names({kDs}));
  v.push_back(R("empty").Do(WriteText(kDs, "")).Names({kDs}));
  v.push_back(R("not_json").Do(WriteText(kDs, "this is not JSON\n")).Names({kDs}));
  v.push_back(R("binary_garbage").Do(WriteText(kDs, Garbage())).Names({kDs}));
  v.push_back(R("truncated").Do(Truncate(kDs, 0.5)).Names({kDs}));
  v.push_back(R("top_level_array").Do(WriteText(kDs, "[1, 2, 3]\n")).Names({kDs}));
  v.push_back(R("top_level_null").Do(WriteText(kDs, "null\n")).Names({kDs}));
  v.push_back(R("nested_100000_arrays").Do(WriteText(kDs, Nested(100000))).Names({kDs}));
  v.push_back(R("nested_100000_in_setup").Do(SetRaw(kDs, "/setup", Nested(100000))).Names({kDs}));
  v.push_back(R("nested_100000_objects")
                  .Do(WriteText(kDs,
                                [] {
                                  std::string s;
                                  for (int k = 0; k < 100000; ++k) s += "{\"a\":";
                                  return s + "1" + std::string(100000, '}');
                                }()))
                  .Names({kDs}));
  v.push_back(R("file_50mb").Do(Bloat(kDs, 50)).Names({kDs}));
  v.push_back(R("is_a_folder").Do(MakeFolder(kDs)).Names({kDs}));
  v.push_back(R("is_a_fifo").Do(MakeFifo(kDs)).Names({kDs}));
  v.push_back(K("is_a_fifo_calibrate").Do(MakeFifo(kDs)).Names({kDs}));
  v.push_back(K("not_json_calibrate").Do(WriteText(kDs, "{\"schema_version\": 2,")).Names({kDs}));
  // schema_version.
  v.push_back(R("schema_version_99")
                  .Do(SetJson(kDs, "/schema_version", 99))
                  .Names({kDs, "schema_version", "99"}));
  v.push_back(R("schema_version_string")
                  .Do(SetJson(kDs, "/schema_version", "2"))
                  .Names({kDs, "schema_version"}));
  v.push_back(R("schema_version_fraction")
                  .Do(SetJson(kDs, "/schema_version", 1.5))
                  .Names({kDs, "schema_version"}));
  v.push_back(R("schema_version_missing")
                  .Do(EraseJson(kDs, "/schema_version"))
                  .Names({kDs, "schema_version"}));
  // setup.distance_mm.
  const std::vector<std::pair<std::string, json>> bad_lengths = {
      {"string", "far"},     {"zero", 0},
      {"negative", -750},    {"tiny", 1e-9},
      {"huge", 1e12},        {"max", 1e308},
      {"nan_string", "NaN"}, {"null", nullptr},
      {"array", {750}},      {"inf_string", "Infinity"}};
  for (const auto& [suffix, value] : bad_lengths)
    v.push_back(R("distance_" + suffix)
                    .Do(SetJson(kDs, "/setup/distance_mm", value))
                    .Names({kDs, "setup.distance_mm"}));
  v.push_back(R("distance_missing")
                  .Do(EraseJson(kDs, "/setup/distance_mm"))
                  .Names({kDs, "setup.distance_mm"}));
  v.push_back(R("distance_1e999").Do(SetRaw(kDs, "/setup/distance_mm", "1e999")).Names({kDs}));
  v.push_back(R("distance_bare_nan").Do(SetRaw(kDs, "/setup/distance_mm", "NaN")).Names({kDs}));
  v.push_back(K("distance_negative_calibrate")
                  .Do(SetJson(kDs, "/setup/distance_mm", -750))
                  .Names({kDs, "setup.distance_mm"}));
  // setup.grid.
  for (const auto& [suffix, value] :
       std::vector<std::pair<std::string, json>>{{"negative", -3},
                                                 {"zero", 0},
                                                 {"1001", 1001},
                                                 {"1e9", 1000000000},
                                                 {"fraction", 2.5},
                                                 {"string", "2"},
                                                 {"huge_float", 1e12}})
    v.push_back(R("grid_nu_" + suffix)
                    .Do(SetJson(kDs, "/setup/grid/nu", value))
                    .Names({kDs, "setup.grid.nu"}));
  v.push_back(
      R("grid_nv_zero").Do(SetJson(kDs, "/setup/grid/nv", 0)).Names({kDs, "setup.grid.nv"}));
  v.push_back(
      R("grid_nv_missing").Do(EraseJson(kDs, "/setup/grid/nv")).Names({kDs, "setup.grid.nv"}));
  v.push_back(
      R("grid_not_object").Do(SetJson(kDs, "/setup/grid", "2x2")).Names({kDs, "setup.grid"}));
  v.push_back(K("grid_nu_negative_calibrate")
                  .Do(SetJson(kDs, "/setup/grid/nu", -3))
                  .Names({kDs, "setup.grid.nu", "-3"}));
  for (const auto& [suffix, value] : std::vector<std::pair<std::string, json>>{
           {"zero", 0}, {"negative", -5}, {"huge", 1e12}, {"nan_string", "NaN"}})
    v.push_back(R("grid_spacing_" + suffix)
                    .Do(SetJson(kDs, "/setup/grid/spacing_mm", value))
                    .Names({kDs, "setup.grid.spacing_mm"}));
  // setup.screen_mm.
  for (const auto& [suffix, value] :
       std::vector<std::pair<std::string, json>>{{"one_value", {1200}},
                                                 {"three_values", {1200, 1200, 1200}},
                                                 {"zero", {0, 1200}},
                                                 {"negative", {1200, -1}},
                                                 {"huge", {1e308, 1200}},
                                                 {"string_element", {1200, "x"}},
                                                 {"string", "wide"}})
    v.push_back(R("screen_" + suffix)
                    .Do(SetJson(kDs, "/setup/screen_mm", value))
                    .Names({kDs, "setup.screen_mm"}));
  // filter.
  v.push_back(R("filter_missing").Do(EraseJson(kDs, "/filter")).Names({kDs, "filter"}));
  v.push_back(
      R("filter_basis_box").Do(SetJson(kDs, "/filter/basis", "box")).Names({kDs, "filter.basis"}));
  v.push_back(R("filter_spacing_mismatch")
                  .Do(SetJson(kDs, "/filter/spacing_mm", 6))
                  .Names({kDs, "filter.spacing_mm"}));
  v.push_back(R("filter_spacing_negative")
                  .Do(SetJson(kDs, "/filter/spacing_mm", -5))
                  .Names({kDs, "filter.spacing_mm"}));
  v.push_back(R("filter_coefficients_empty")
                  .Do(SetJson(kDs, "/filter/dual_coefficients", json::array()))
                  .Names({kDs, "filter.dual_coefficients"}));
  v.push_back(R("filter_coefficients_ten")
                  .Do(SetJson(kDs, "/filter/dual_coefficients", std::vector<double>(10, 0.1)))
                  .Names({kDs, "filter.dual_coefficients"}));
  v.push_back(R("filter_coefficients_string")
                  .Do(SetJson(kDs, "/filter/dual_coefficients", {1.36, "x"}))
                  .Names({kDs, "filter.dual_coefficients"}));
  v.push_back(R("filter_coefficients_nan_string")
                  .Do(SetJson(kDs, "/filter/dual_coefficients/0", "NaN"))
                  .Names({kDs, "filter.dual_coefficients"}));
  v.push_back(
      R("filter_peak_zero").Do(SetJson(kDs, "/filter/peak", 0)).Names({kDs, "filter.peak"}));
  v.push_back(
      R("filter_peak_negative").Do(SetJson(kDs, "/filter/peak", -1.8)).Names({kDs, "filter.peak"}));
  v.push_back(R("filter_peak_inf_string")
                  .Do(SetJson(kDs, "/filter/peak", "Infinity"))
                  .Names({kDs, "filter.peak"}));
  // radiometry.
  v.push_back(R("radiometry_missing").Do(EraseJson(kDs, "/radiometry")).Names({kDs, "radiometry"}));
  v.push_back(R("radiometry_scale_zero")
                  .Do(SetJson(kDs, "/radiometry/scale_w_m2", 0))
                  .Names({kDs, "radiometry.scale_w_m2"}));
  v.push_back(R("radiometry_scale_negative")
                  .Do(SetJson(kDs, "/radiometry/scale_w_m2", -1.9))
                  .Names({kDs, "radiometry.scale_w_m2"}));
  v.push_back(R("radiometry_saturation_zero")
                  .Do(SetJson(kDs, "/radiometry/saturation_level", 0))
                  .Names({kDs, "radiometry.saturation_level"}));
  v.push_back(R("radiometry_transfer_gamma")
                  .Do(SetJson(kDs, "/radiometry/transfer", "gamma"))
                  .Names({kDs, "radiometry.transfer"}));
  v.push_back(R("radiometry_black_level_high")
                  .Do(SetJson(kDs, "/radiometry/black_level", 0.7))
                  .Names({kDs, "radiometry.black_level"}));
  v.push_back(R("radiometry_black_level_negative")
                  .Do(SetJson(kDs, "/radiometry/black_level", -0.1))
                  .Names({kDs, "radiometry.black_level"}));
  v.push_back(R("radiometry_white_level_low")
                  .Do(SetJson(kDs, "/radiometry/white_level", 0.1))
                  .Names({kDs, "radiometry.white_level"}));
  v.push_back(R("radiometry_white_level_huge")
                  .Do(SetJson(kDs, "/radiometry/white_level", 1e7))
                  .Names({kDs, "radiometry.white_level"}));
  v.push_back(R("radiometry_white_equals_black")
                  .Do(SetJson(kDs, "/radiometry/black_level", 0.5))
                  .Do(SetJson(kDs, "/radiometry/white_level", 0.5))
                  .Names({kDs, "white_level"}));
  // calibration (read by calibrate).
  v.push_back(
      K("calibration_missing").Do(EraseJson(kDs, "/calibration")).Names({kDs, "calibration"}));
  v.push_back(K("calibration_photo_number")
                  .Do(SetJson(kDs, "/calibration/photo", 5))
                  .Names({kDs, "calibration.photo"}));
  v.push_back(K("calibration_photo_empty")
                  .Do(SetJson(kDs, "/calibration/photo", ""))
                  .Names({kDs, "calibration.photo"}));
  v.push_back(K("calibration_photo_dotdot")
                  .Do(SetJson(kDs, "/calibration/photo", "../ds/photos/calib_0.png"))
                  .Names({kDs, "calibration.photo"}));
  v.push_back(K("calibration_photo_absolute")
                  .Do(SetJson(kDs, "/calibration/photo", "/etc/hostname"))
                  .Names({kDs, "calibration.photo"}));
  v.push_back(K("calibration_type_circles")
                  .Do(SetJson(kDs, "/calibration/target/type", "circles"))
                  .Names({kDs, "calibration.target.type"}));
  v.push_back(K("calibration_squares_square")
                  .Do(SetJson(kDs, "/calibration/target/squares", {14, 14}))
                  .Names({kDs, "calibration.target.squares"}));
  v.push_back(K("calibration_squares_two")
                  .Do(SetJson(kDs, "/calibration/target/squares", {2, 13}))
                  .Names({kDs, "calibration.target.squares"}));
  v.push_back(K("calibration_squares_201")
                  .Do(SetJson(kDs, "/calibration/target/squares", {201, 13}))
                  .Names({kDs, "calibration.target.squares"}));
  v.push_back(K("calibration_squares_one_value")
                  .Do(SetJson(kDs, "/calibration/target/squares", {14}))
                  .Names({kDs, "calibration.target.squares"}));
  v.push_back(K("calibration_square_mm_zero")
                  .Do(SetJson(kDs, "/calibration/target/square_mm", 0))
                  .Names({kDs, "calibration.target.square_mm"}));
  v.push_back(K("calibration_square_mm_negative")
                  .Do(SetJson(kDs, "/calibration/target/square_mm", -80))
                  .Names({kDs, "calibration.target.square_mm"}));
  v.push_back(K("calibration_origin_string")
                  .Do(SetJson(kDs, "/calibration/target/origin_mm", {"a", 0}))
                  .Names({kDs, "calibration.target.origin_mm"}));
  v.push_back(K("calibration_origin_nan_string")
                  .Do(SetJson(kDs, "/calibration/target/origin_mm/1", "NaN"))
                  .Names({kDs, "calibration.target.origin_mm"}));
  // photos.
  v.push_back(R("photos_missing").Do(EraseJson(kDs, "/photos")).Names({kDs, "photos"}));
  v.push_back(
      R("photos_not_array").Do(SetJson(kDs, "/photos", json::object())).Names({kDs, "photos"}));
  v.push_back(R("photos_empty").Do(SetJson(kDs, "/photos", json::array())).Names({kDs, "photos"}));
  v.push_back(
      R("photo_i_negative").Do(SetJson(kDs, "/photos/0/i", -1)).Names({kDs, "photos[0].i"}));
  v.push_back(
      R("photo_i_outside_grid").Do(SetJson(kDs, "/photos/0/i", 2)).Names({kDs, "photos[0].i"}));
  v.push_back(
      R("photo_j_outside_grid").Do(SetJson(kDs, "/photos/3/j", 5)).Names({kDs, "photos[3].j"}));
  v.push_back(R("photo_i_string").Do(SetJson(kDs, "/photos/0/i", "0")).Names({kDs, "photos[0].i"}));
  v.push_back(R("photo_i_missing").Do(EraseJson(kDs, "/photos/0/i")).Names({kDs, "photos[0].i"}));
  v.push_back(R("photo_entry_outside_grid")
                  .Do(EditJson(
                      kDs,
                      [](json& j) {
                        j["photos"].push_back(
                            {{"i", 7}, {"j", 0}, {"slide", "p"}, {"file", "photos/pos_0_0_p.png"}});
                      }))
                  .Names({kDs, "photos[8].i"}));
  v.push_back(
      R("photo_slide_x").Do(SetJson(kDs, "/photos/0/slide", "x")).Names({kDs, "photos[0].slide"}));
  v.push_back(R("photo_slide_missing")
                  .Do(EraseJson(kDs, "/photos/0/slide"))
                  .Names({kDs, "photos[0].slide"}));
  v.push_back(R("photo_file_absolute")
                  .Do(SetJson(kDs, "/photos/0/file", "/etc/hostname"))
                  .Names({kDs, "photos[0].file"}));
  v.push_back(R("photo_file_dotdot")
                  .Do(SetJson(kDs, "/photos/0/file", "../ds/photos/pos_0_0_p.png"))
                  .Names({kDs, "photos[0].file"}));
  v.push_back(R("photo_file_inner_dotdot")
                  .Do(SetJson(kDs, "/photos/0/file", "photos/../../ds/photos/pos_0_0_p.png"))
                  .Names({kDs, "photos[0].file"}));
  v.push_back(
      R("photo_file_empty").Do(SetJson(kDs, "/photos/0/file", "")).Names({kDs, "photos[0].file"}));
  v.push_back(
      R("photo_file_number").Do(SetJson(kDs, "/photos/0/file", 42)).Names({kDs, "photos[0].file"}));
  v.push_back(R("photo_exposure_zero")
                  .Do(SetJson(kDs, "/photos/0/exposure", 0))
                  .Names({kDs, "photos[0].exposure"}));
  v.push_back(R("photo_exposure_negative")
                  .Do(SetJson(kDs, "/photos/0/exposure", -1))
                  .Names({kDs, "photos[0].exposure"}));
  v.push_back(R("photo_exposure_string")
                  .Do(SetJson(kDs, "/photos/0/exposure", "bright"))
                  .Names({kDs, "photos[0].exposure"}));
  // The n photo of position (1, 1) is the last entry.
  v.push_back(R("photo_missing_slide").Do(EraseJson(kDs, "/photos/7")).Names({kDs, "photos"}));
  v.push_back(R("photo_duplicate_entry")
                  .Do(EditJson(kDs, [](json& j) { j["photos"].push_back(j["photos"][0]); }))
                  .Names({kDs, "photos"}));
  return v;
}

std::vector<Case> ScreenCalibrationCases() {
  std::vector<Case> v;
  auto R = [](const std::string& name) { return C("screen_" + name).Reconstruct(); };
  v.push_back(R("missing").Do(RemovePath(kScr)).Names({kScr}));
  v.push_back(R("empty").Do(WriteText(kScr, "")).Names({kScr}));
  v.push_back(R("truncated").Do(Truncate(kScr, 0.5)).Names({kScr}));
  v.push_back(R("not_json").Do(WriteText(kScr, Garbage())).Names({kScr}));
  v.push_back(R("nested_100000_arrays").Do(WriteText(kScr, Nested(100000))).Names({kScr}));
  v.push_back(R("file_50mb").Do(Bloat(kScr, 50)).Names({kScr}));
  v.push_back(R("is_a_folder").Do(MakeFolder(kScr)).Names({kScr}));
  v.push_back(R("is_a_fifo").Do(MakeFifo(kScr)).Names({kScr}));
  v.push_back(R("schema_version_99")
                  .Do(SetJson(kScr, "/schema_version", 99))
                  .Names({kScr, "schema_version"}));
  v.push_back(
      R("image_size_zero").Do(SetJson(kScr, "/image_size", {0, 240})).Names({kScr, "image_size"}));
  v.push_back(R("image_size_huge")
                  .Do(SetJson(kScr, "/image_size", {1000000000, 240}))
                  .Names({kScr, "image_size"}));
  v.push_back(R("image_size_one_value")
                  .Do(SetJson(kScr, "/image_size", {320}))
                  .Names({kScr, "image_size"}));
  // Valid on its own, but not the size of the photos.
  v.push_back(R("image_size_not_photos")
                  .Do(SetJson(kScr, "/image_size", {640, 480}))
                  .Names({kScr, "640x480"}));
  v.push_back(R("homography_eight_values")
                  .Do(EraseJson(kScr, "/screen_from_image/8"))
                  .Names({kScr, "screen_from_image"}));
  v.push_back(R("homography_zero")
                  .Do(SetJson(kScr, "/screen_from_image", std::vector<double>(9, 0.0)))
                  .Names({kScr, "screen_from_image"}));
  v.push_back(
      R("homography_singular")
          .Do(SetJson(kScr, "/screen_from_image", {3.13, 0, -1000, 6.26, 0, -2000, 0, 0, 1}))
          .Names({kScr, "screen_from_image"}));
  v.push_back(R("homography_nan_string")
                  .Do(SetJson(kScr, "/screen_from_image/4", "NaN"))
                  .Names({kScr, "screen_from_image"}));
  v.push_back(R("homography_null")
                  .Do(SetJson(kScr, "/screen_from_image/0", nullptr))
                  .Names({kScr, "screen_from_image"}));
  v.push_back(R("homography_1e308")
                  .Do(SetJson(kScr, "/screen_from_image/0", 1e308))
                  .Names({kScr, "screen_from_image"}));
  v.push_back(R("distortion_model_fisheye")
                  .Do(SetJson(kScr, "/distortion/model", "fisheye"))
                  .Names({kScr, "distortion.model"}));
  v.push_back(R("distortion_k1_nan_string")
                  .Do(SetJson(kScr, "/distortion/k1", "NaN"))
                  .Names({kScr, "distortion.k1"}));
  v.push_back(R("distortion_k1_huge")
                  .Do(SetJson(kScr, "/distortion/k1", 1e6))
                  .Names({kScr, "distortion.k1"}));
  v.push_back(R("distortion_k2_missing")
                  .Do(EraseJson(kScr, "/distortion/k2"))
                  .Names({kScr, "distortion.k2"}));
  v.push_back(R("distortion_scale_zero")
                  .Do(SetJson(kScr, "/distortion/scale_px", 0))
                  .Names({kScr, "distortion.scale_px"}));
  v.push_back(R("distortion_scale_negative")
                  .Do(SetJson(kScr, "/distortion/scale_px", -200))
                  .Names({kScr, "distortion.scale_px"}));
  v.push_back(R("distortion_centre_string")
                  .Do(SetJson(kScr, "/distortion/centre_px", {"x", 119.5}))
                  .Names({kScr, "distortion.centre_px"}));
  v.push_back(R("report_rms_negative")
                  .Do(SetJson(kScr, "/report/rms_px", -1))
                  .Names({kScr, "report.rms_px"}));
  v.push_back(R("report_corners_negative")
                  .Do(SetJson(kScr, "/report/corners_used", -5))
                  .Names({kScr, "report.corners_used"}));
  return v;
}

std::vector<Case> PhotoCases() {
  std::vector<Case> v;
  // The bad photo is of position (1, 0); the other positions may be written (a partial slab is
  // valid), that one never.
  const std::string p = "ds/photos/pos_1_0_p.png";
  auto R = [](const std::string& name) {
    return C("photo_" + name)
        .Reconstruct()
        .MayChange("ds/slab/")
        .MustNotExist("ds/slab/pos_1_0.exr");
  };
  v.push_back(R("missing").Do(RemovePath(p)).Names({p}));
  v.push_back(R("empty_file").Do(WriteText(p, "")).Names({p}));
  v.push_back(R("truncated_png").Do(Truncate(p, 0.5)).Names({p}));
  v.push_back(
      R("png_signature_only").Do(WriteText(p, std::string("\x89PNG\r\n\x1a\n", 8))).Names({p}));
  v.push_back(
      R("text_renamed_png").Do(WriteText(p, "this is a text file, not a photo\n")).Names({p}));
  v.push_back(R("is_a_folder").Do(MakeFolder(p)).Names({p}));
  v.push_back(R("is_a_fifo").Do(MakeFifo(p)).Names({p}));
  v.push_back(R("wrong_size").Do(PngResize(p, 160, 120)).Names({p}));
  v.push_back(R("float_tiff").Do(FloatTiff(p)).Names({p}));
  v.push_back(R("png_header_32768").Do(PngHugeHeader(p, 32768, 32768)).Names({p}));
  v.push_back(R("png_header_1x2e9").Do(PngHugeHeader(p, 1, 2000000000)).Names({p}));
  // 8-bit among 16-bit: accepted as exit 2 naming the photo, or exit 0 with a warning naming it.
  v.push_back(R("8bit_among_16bit").Do(PngTo8Bit(p)).Names({p}).WarningOk());
  // --force over a complete slab: the previous slab must stay as it was, byte for byte.
  v.push_back(C("photo_truncated_png_force_keeps_slab")
                  .Reconstruct("--force")
                  .From(Input::kSlab)
                  .Do(Truncate(p, 0.5))
                  .Names({p}));
  v.push_back(C("photo_missing_force_keeps_slab")
                  .Reconstruct("--force")
                  .From(Input::kSlab)
                  .Do(RemovePath(p))
                  .Names({p}));
  v.push_back(C("photo_is_a_fifo_force_keeps_slab")
                  .Reconstruct("--force")
                  .From(Input::kSlab)
                  .Do(MakeFifo(p))
                  .Names({p}));
  // EXR photos (half-float, as acquire writes them by default).
  const std::string e = "ds/photos/pos_1_0_p.exr";
  auto X = [](const std::string& name) {
    return C("photo_exr_" + name)
        .Reconstruct()
        .From(Input::kExrCalibrated)
        .MayChange("ds/slab/")
        .MustNotExist("ds/slab/pos_1_0.exr");
  };
  v.push_back(X("truncated").Do(Truncate(e, 0.5)).Names({e}));
  v.push_back(X("header_only").Do(Truncate(e, 0.02)).Names({e}));
  v.push_back(X("empty_file").Do(WriteText(e, "")).Names({e}));
  v.push_back(
      X("header_32768x32768").Do(ExrHugeHeader(e, {"R", "G", "B"}, 32768, 32768)).Names({e}));
  v.push_back(
      X("nan_values").Do(ExrPoison(e, "G", std::numeric_limits<float>::quiet_NaN())).Names({e}));
  v.push_back(
      X("inf_values").Do(ExrPoison(e, "R", std::numeric_limits<float>::infinity())).Names({e}));
  v.push_back(X("negative_inf_values")
                  .Do(ExrPoison(e, "B", -std::numeric_limits<float>::infinity()))
                  .Names({e}));
  v.push_back(X("no_green_channel").Do(ExrDropChannel(e, "G")).Names({e, "G"}));
  v.push_back(X("wrong_size").Do(ExrResize(e, 160, 120)).Names({e}));
  // The board photo, read by calibrate.
  const std::string b = "ds/photos/calib_0.png";
  auto B = [](const std::string& name) { return C("calib_photo_" + name).Calibrate(); };
  v.push_back(B("missing").Do(RemovePath(b)).Names({b}));
  v.push_back(B("empty_file").Do(WriteText(b, "")).Names({b}));
  v.push_back(B("truncated").Do(Truncate(b, 0.5)).Names({b}));
  v.push_back(B("text_renamed_png").Do(WriteText(b, "not a photo\n")).Names({b}));
  v.push_back(B("is_a_folder").Do(MakeFolder(b)).Names({b}));
  v.push_back(B("is_a_fifo").Do(MakeFifo(b)).Names({b}));
  v.push_back(B("png_header_32768").Do(PngHugeHeader(b, 32768, 32768)).Names({b}));
  v.push_back(B("no_board").Do(CopyPath("ds/photos/pos_0_0_p.png", b)).Names({b}));
  v.push_back(B("tiny_32x24").Do(PngResize(b, 32, 24)).Names({b}));
  // calib/camera.json (lumislab-calibrate camera), which calibrate screen uses when it exists.
  const std::string cam = "ds/calib/camera.json";
  auto Cam = [&](const std::string& name, const json& edits) {
    json camera = {
        {"schema_version", 1},
        {"image_size", {320, 240}},
        {"camera_matrix", {{"fx", 280}, {"fy", 280}, {"cx", 159.5}, {"cy", 119.5}}},
        {"distortion",
         {{"model", "opencv5"}, {"k1", 0}, {"k2", 0}, {"p1", 0}, {"p2", 0}, {"k3", 0}}},
        {"board", {{"type", "chessboard"}, {"inner_corners", {9, 6}}, {"square_mm", 30}}},
        {"report",
         {{"rms_px", 0.1},
          {"opencv_rms_px", 0.1},
          {"views",
           {{{"photo", "v.png"},
             {"used", true},
             {"corners", 54},
             {"rms_px", 0.1},
             {"tilt_deg", 20},
             {"rotation", {0, 0, 0}},
             {"translation_mm", {0, 0, 500}}}}}}}};
    camera.merge_patch(edits);
    return C("calib_camera_" + name)
        .Calibrate()
        .Do(MakeFolder("ds/calib"))
        .Do(WriteText(cam, camera.dump(2) + "\n"));
  };
  // The camera of another photo size: its intrinsics would be wrong for this photo.
  v.push_back(Cam("size_differs", {{"image_size", {640, 480}}}).Names({cam, "image_size"}));
  v.push_back(Cam("size_transposed", {{"image_size", {240, 320}}}).Names({cam, "image_size"}));
  v.push_back(
      Cam("fx_negative", {{"camera_matrix", {{"fx", -280}}}}).Names({cam, "camera_matrix.fx"}));
  v.push_back(Cam("unknown_model", {{"distortion", {{"model", "fisheye"}}}})
                  .Names({cam, "distortion.model"}));
  v.push_back(Cam("not_json", {}).Do(WriteText(cam, "{\"schema_version\": 1,")).Names({cam}));
  return v;
}

std::vector<Case> SceneCases() {
  std::vector<Case> v;
  const std::string& s = kSceneFile;
  auto S = [](const std::string& name) { return C("scene_" + name).Synth(); };
  v.push_back(S("missing").Do(RemovePath(s)).Names({s}));
  v.push_back(S("empty").Do(WriteText(s, "")).Names({s}));
  v.push_back(S("not_json").Do(WriteText(s, "scene: default\n")).Names({s}));
  v.push_back(S("binary_garbage").Do(WriteText(s, Garbage())).Names({s}));
  v.push_back(S("nested_100000_arrays").Do(WriteText(s, Nested(100000))).Names({s}));
  v.push_back(
      S("nested_in_emitters").Do(SetRaw(s, "/luminaire/emitters", Nested(100000))).Names({s}));
  v.push_back(S("file_50mb").Do(Bloat(s, 50)).Names({s}));
  v.push_back(S("is_a_folder").Do(MakeFolder(s)).Names({s}));
  v.push_back(S("is_a_fifo").Do(MakeFifo(s)).Names({s}));
  v.push_back(
      S("schema_version_99").Do(SetJson(s, "/schema_version", 99)).Names({s, "schema_version"}));
  for (const auto& [suffix, value] :
       std::vector<std::pair<std::string, json>>{{"tiny", 1e-9},
                                                 {"zero", 0},
                                                 {"negative", -750},
                                                 {"huge", 1e12},
                                                 {"string", "far"},
                                                 {"nan_string", "NaN"}})
    v.push_back(S("distance_" + suffix)
                    .Do(SetJson(s, "/setup/distance_mm", value))
                    .Names({s, "setup.distance_mm"}));
  v.push_back(S("distance_1e999").Do(SetRaw(s, "/setup/distance_mm", "1e999")).Names({s}));
  for (const auto& [suffix, value] : std::vector<std::pair<std::string, json>>{
           {"zero", 0}, {"negative", -1}, {"1e9", 1000000000}, {"fraction", 2.5}})
    v.push_back(
        S("grid_nu_" + suffix).Do(SetJson(s, "/setup/grid/nu", value)).Names({s, "setup.grid.nu"}));
  v.push_back(S("grid_nv_zero").Do(SetJson(s, "/setup/grid/nv", 0)).Names({s, "setup.grid.nv"}));
  for (const auto& [suffix, value] :
       std::vector<std::pair<std::string, json>>{{"zero", 0}, {"negative", -5}, {"huge", 1e9}})
    v.push_back(S("grid_spacing_" + suffix)
                    .Do(SetJson(s, "/setup/grid/spacing_mm", value))
                    .Names({s, "setup.grid.spacing_mm"}));
  for (const auto& [suffix, value] :
       std::vector<std::pair<std::string, json>>{{"zero", {0, 1200}},
                                                 {"one_value", {1200}},
                                                 {"negative", {1200, -1}},
                                                 {"huge", {1e12, 1200}}})
    v.push_back(S("screen_" + suffix)
                    .Do(SetJson(s, "/setup/screen_mm", value))
                    .Names({s, "setup.screen_mm"}));
  for (const auto& [suffix, value] :
       std::vector<std::pair<std::string, json>>{{"0", 0}, {"9", 9}, {"string", "x"}})
    v.push_back(
        S("k_max_" + suffix).Do(SetJson(s, "/filter/k_max", value)).Names({s, "filter.k_max"}));
  v.push_back(S("emitters_empty")
                  .Do(SetJson(s, "/luminaire/emitters", json::array()))
                  .Names({s, "luminaire.emitters"}));
  v.push_back(S("emitters_missing")
                  .Do(EraseJson(s, "/luminaire/emitters"))
                  .Names({s, "luminaire.emitters"}));
  const std::string em = "luminaire.emitters[0]";
  v.push_back(S("emitter_z_zero")
                  .Do(SetJson(s, "/luminaire/emitters/0/position_mm/2", 0))
                  .Names({s, em + ".position_mm"}));
  v.push_back(S("emitter_z_positive")
                  .Do(SetJson(s, "/luminaire/emitters/0/position_mm/2", 5))
                  .Names({s, em + ".position_mm"}));
  v.push_back(S("emitter_two_coordinates")
                  .Do(SetJson(s, "/luminaire/emitters/0/position_mm", {1, 2}))
                  .Names({s, em + ".position_mm"}));
  v.push_back(S("emitter_far_away")
                  .Do(SetJson(s, "/luminaire/emitters/0/position_mm", {0, 0, -1e12}))
                  .Names({s, em + ".position_mm"}));
  v.push_back(S("intensity_negative")
                  .Do(SetJson(s, "/luminaire/emitters/0/intensity_w_sr/1", -0.9))
                  .Names({s, em + ".intensity_w_sr"}));
  v.push_back(S("intensity_huge")
                  .Do(SetJson(s, "/luminaire/emitters/0/intensity_w_sr/0", 1e308))
                  .Names({s, em + ".intensity_w_sr"}));
  v.push_back(S("intensity_nan_string")
                  .Do(SetJson(s, "/luminaire/emitters/0/intensity_w_sr/2", "NaN"))
                  .Names({s, em + ".intensity_w_sr"}));
  v.push_back(S("intensity_two_values")
                  .Do(SetJson(s, "/luminaire/emitters/0/intensity_w_sr", {1.0, 0.9}))
                  .Names({s, em + ".intensity_w_sr"}));
  v.push_back(S("lobe_negative")
                  .Do(SetJson(s, "/luminaire/emitters/0/lobe_exponent", -1))
                  .Names({s, em + ".lobe_exponent"}));
  v.push_back(S("lobe_huge")
                  .Do(SetJson(s, "/luminaire/emitters/0/lobe_exponent", 1e308))
                  .Names({s, em + ".lobe_exponent"}));
  const std::string cam = "camera";
  v.push_back(
      S("camera_size_tiny").Do(SetJson(s, "/camera/size_px", {8, 6})).Names({s, "camera.size_px"}));
  v.push_back(S("camera_size_huge")
                  .Do(SetJson(s, "/camera/size_px", {100000, 100000}))
                  .Names({s, "camera.size_px"}));
  v.push_back(S("camera_size_one_value")
                  .Do(SetJson(s, "/camera/size_px", {320}))
                  .Names({s, "camera.size_px"}));
  v.push_back(S("camera_size_fraction")
                  .Do(SetJson(s, "/camera/size_px", {320.5, 240}))
                  .Names({s, "camera.size_px"}));
  v.push_back(
      S("camera_focal_zero").Do(SetJson(s, "/camera/focal_px", 0)).Names({s, "camera.focal_px"}));
  v.push_back(S("camera_focal_negative")
                  .Do(SetJson(s, "/camera/focal_px", -280))
                  .Names({s, "camera.focal_px"}));
  v.push_back(S("camera_look_at_position")
                  .Do(SetJson(s, "/camera/look_at_mm", {0, -200, 2400}))
                  .Names({s, "camera.look_at_mm"}));
  v.push_back(S("camera_on_screen_plane")
                  .Do(SetJson(s, "/camera/position_mm", {0, -200, 750}))
                  .Names({s, "camera.position_mm"}));
  v.push_back(S("camera_exposure_zero")
                  .Do(SetJson(s, "/camera/exposure", 0))
                  .Names({s, "camera.exposure"}));
  v.push_back(S("camera_scale_negative")
                  .Do(SetJson(s, "/camera/radiometric_scale_w_m2", -1))
                  .Names({s, "camera.radiometric_scale_w_m2"}));
  v.push_back(S("board_square")
                  .Do(SetJson(s, "/calibration", {{"squares", {14, 14}}}))
                  .Names({s, "calibration"}));
  v.push_back(S("board_two_squares")
                  .Do(SetJson(s, "/calibration", {{"squares", {2, 13}}}))
                  .Names({s, "calibration.squares"}));
  v.push_back(S("board_larger_than_screen")
                  .Do(SetJson(s, "/calibration", {{"square_mm", 500}}))
                  .Names({s, "calibration"}));
  v.push_back(S("board_square_mm_zero")
                  .Do(SetJson(s, "/calibration", {{"square_mm", 0}}))
                  .Names({s, "calibration.square_mm"}));
  // The camera looks 5 m to the side: the board is not in its view.
  v.push_back(
      S("board_out_of_view").Do(SetJson(s, "/camera/look_at_mm", {5000, 0, 750})).Names({s}));
  // Zoomed in on the middle of the board: only part of it is in view.
  v.push_back(S("board_partly_out_of_view").Do(SetJson(s, "/camera/focal_px", 3000)).Names({s}));
  v.push_back(S("effect_unknown")
                  .Do(SetJson(s, "/effects", {{{"type", "lens_flare"}}}))
                  .Names({s, "effects[0].type", "lens_flare"}));
  v.push_back(S("effect_unknown_parameter")
                  .Do(SetJson(s, "/effects", {{{"type", "quantization"}, {"gamma", 2.2}}}))
                  .Names({s, "effects[0]", "gamma"}));
  v.push_back(S("effect_type_missing")
                  .Do(SetJson(s, "/effects", {{{"bit_depth", 16}}}))
                  .Names({s, "effects[0].type"}));
  v.push_back(S("effect_bit_depth_4")
                  .Do(SetJson(s, "/effects", {{{"type", "quantization"}, {"bit_depth", 4}}}))
                  .Names({s, "effects[0].bit_depth"}));
  v.push_back(S("effect_full_well_zero")
                  .Do(SetJson(s, "/effects", {{{"type", "sensor_noise"}, {"full_well_e", 0}}}))
                  .Names({s, "effects[0].full_well_e"}));
  v.push_back(S("effect_read_noise_negative")
                  .Do(SetJson(s, "/effects", {{{"type", "sensor_noise"}, {"read_noise_e", -3}}}))
                  .Names({s, "effects[0].read_noise_e"}));
  v.push_back(S("effect_seed_negative")
                  .Do(SetJson(s, "/effects", {{{"type", "sensor_noise"}, {"seed", -1}}}))
                  .Names({s, "effects[0].seed"}));
  v.push_back(
      S("effects_not_array").Do(SetJson(s, "/effects", "quantization")).Names({s, "effects"}));
  // The camera effects of issue 8: one parameter out of range each, and the once-only ones twice.
  const std::vector<std::tuple<std::string, json, std::string>> ranged = {
      {"vignetting_k1", {{"type", "vignetting"}, {"k1", 2}}, "effects[0].k1"},
      {"screen_gain_amplitude",
       {{"type", "screen_gain"}, {"amplitude", 0.5}},
       "effects[0].amplitude"},
      {"ambient_negative", {{"type", "ambient"}, {"level", -0.1}}, "effects[0].level"},
      {"dark_black_level", {{"type", "dark"}, {"black_level", 0.9}}, "effects[0].black_level"},
      {"brackets_stop", {{"type", "brackets"}, {"stops", {0, 12}}}, "effects[0].stops[1]"},
      {"response_quality", {{"type", "response"}, {"quality", 0}}, "effects[0].quality"},
      {"stage_error_max", {{"type", "stage_error"}, {"max_mm", 50}}, "effects[0].max_mm"},
  };
  for (const auto& [name, effect, field] : ranged)
    v.push_back(
        S("effect_" + name).Do(SetJson(s, "/effects", json::array({effect}))).Names({s, field}));
  v.push_back(S("effect_brackets_twice")
                  .Do(SetJson(s, "/effects",
                              {{{"type", "brackets"}, {"stops", {0}}},
                               {{"type", "brackets"}, {"stops", {1}}}}))
                  .Names({s, "effects[1].type"}));
  // Command line of synth.
  auto A = [](const std::string& name, const std::string& extra) {
    return C("synth_" + name).Synth(extra);
  };
  v.push_back(A("truth_resolution_zero", "--truth-resolution 0").Names({"--truth-resolution"}));
  v.push_back(A("truth_resolution_huge", "--truth-resolution 99999").Names({"--truth-resolution"}));
  v.push_back(A("interval_negative", "--interval -1").Names({"--interval"}));
  v.push_back(A("interval_nan", "--interval nan").Names({"--interval"}));
  v.push_back(A("photo_format_jpeg", "--photo-format jpeg").Names({"--photo-format"}));
  v.push_back(A("threads_negative", "--threads -1").Names({"--threads"}));
  v.push_back(A("threads_abc", "--threads abc").Names({"--threads"}));
  // filter.
  auto F = [](const std::string& name, const std::string& args) {
    return C("filter_" + name).Filter(args);
  };
  v.push_back(F("k_max_0", "--k-max 0").Names({"--k-max"}));
  v.push_back(F("k_max_9", "--k-max 9").Names({"--k-max"}));
  v.push_back(F("k_max_x", "--k-max x").Names({"--k-max"}));
  v.push_back(F("spacing_zero", "--spacing-mm 0").Names({"--spacing-mm"}));
  v.push_back(F("spacing_negative", "--spacing-mm -1").Names({"--spacing-mm"}));
  v.push_back(F("spacing_1e9", "--spacing-mm 1e9").Names({"--spacing-mm"}));
  v.push_back(F("spacing_nan", "--spacing-mm nan").Names({"--spacing-mm"}));
  v.push_back(F("dpi_tiny", "--dpi 1").Names({"--dpi"}));
  v.push_back(F("dpi_huge", "--dpi 1e9").Names({"--dpi"}));
  v.push_back(F("dpi_nan", "--dpi nan").Names({"--dpi"}));
  v.push_back(F("dpi_zero", "--dpi 0").Names({"--dpi"}));
  v.push_back(F("threads_100000", "--threads 100000").Names({"--threads"}));
  return v;
}

std::vector<Case> CommandLineCases() {
  std::vector<Case> v;
  // reconstruct.
  auto R = [](const std::string& name, const std::string& args) {
    return C("reconstruct_" + name).ReconstructArgs("--dataset ds " + args);
  };
  for (const auto& value : std::vector<std::pair<std::string, std::string>>{{"0", "0"},
                                                                            {"negative", "-5"},
                                                                            {"3", "3"},
                                                                            {"99999", "99999"},
                                                                            {"abc", "abc"},
                                                                            {"300x", "300x"}})
    v.push_back(
        R("resolution_" + value.first, "--resolution " + value.second).Names({"--resolution"}));
  for (const auto& value : std::vector<std::pair<std::string, std::string>>{
           {"negative", "-1"}, {"100000", "100000"}, {"abc", "abc"}})
    v.push_back(R("threads_" + value.first, "--resolution 40 --threads " + value.second)
                    .Names({"--threads"}));
  for (const auto& value : std::vector<std::pair<std::string, std::string>>{
           {"negative", "-1"}, {"nan", "nan"}, {"inf", "inf"}})
    v.push_back(
        R("lambda_" + value.first, "--resolution 40 --lambda " + value.second).Names({"--lambda"}));
  v.push_back(R("samples_per_texel_negative", "--resolution 40 --samples-per-texel -1")
                  .Names({"--samples-per-texel"}));
  v.push_back(R("samples_per_texel_huge", "--resolution 40 --samples-per-texel 100000")
                  .Names({"--samples-per-texel"}));
  v.push_back(
      R("poll_zero", "--resolution 40 --watch --poll 0 --idle-timeout 5").Names({"--poll"}));
  v.push_back(
      R("poll_negative", "--resolution 40 --watch --poll -1 --idle-timeout 5").Names({"--poll"}));
  v.push_back(
      R("poll_nan", "--resolution 40 --watch --poll nan --idle-timeout 5").Names({"--poll"}));
  v.push_back(R("idle_timeout_negative", "--resolution 40 --watch --idle-timeout -5")
                  .Names({"--idle-timeout"}));
  v.push_back(C("reconstruct_dataset_not_found")
                  .ReconstructArgs("--dataset nothere --resolution 40")
                  .Names({"nothere/dataset.json"}));
  // An existing slab of another resolution (docs/architecture.md §7.4): refused without --force.
  v.push_back(C("reconstruct_existing_slab_other_resolution")
                  .ReconstructArgs("--dataset ds --resolution 60")
                  .From(Input::kSlab)
                  .Names({"ds/slab"}));
  // calibrate.
  auto K = [](const std::string& name, const std::string& args) {
    return C("calibrate_" + name).Calibrate(args);
  };
  v.push_back(K("threads_negative", "--threads -1").Names({"--threads"}));
  v.push_back(K("threads_100000", "--threads 100000").Names({"--threads"}));
  v.push_back(K("huber_zero", "--huber-px 0").Names({"--huber-px"}));
  v.push_back(K("huber_nan", "--huber-px nan").Names({"--huber-px"}));
  v.push_back(K("distortion_terms_3", "--distortion-terms 3").Names({"--distortion-terms"}));
  v.push_back(
      K("distortion_terms_negative", "--distortion-terms -1").Names({"--distortion-terms"}));
  v.push_back(K("max_rms_negative", "--max-rms-px -1").Names({"--max-rms-px"}));
  v.push_back(K("max_rms_nan", "--max-rms-px nan").Names({"--max-rms-px"}));
  v.push_back(K("max_detection_zero", "--max-detection-px 0").Names({"--max-detection-px"}));
  v.push_back(K("max_detection_negative", "--max-detection-px -5").Names({"--max-detection-px"}));
  v.push_back(
      C("calibrate_dataset_not_found").Calibrate().Do(RemovePath("ds")).Names({"ds/dataset.json"}));
  // preview.
  auto P = [](const std::string& name, const std::string& args) {
    return C("preview_" + name).Preview("--slab ds/slab " + args);
  };
  const std::string plane = "--scene plane --out r.exr ";
  for (const auto& value :
       std::vector<std::pair<std::string, std::string>>{{"junk_suffix", "400x400junk"},
                                                        {"zero", "0x0"},
                                                        {"negative", "-1x5"},
                                                        {"huge", "99999x99999"},
                                                        {"no_height", "10x"},
                                                        {"word", "big"},
                                                        {"8193", "8193x8"}})
    v.push_back(P("size_" + value.first, plane + "--size " + value.second).Names({"--size"}));
  for (const auto& value : std::vector<std::pair<std::string, std::string>>{{"negative", "-5"},
                                                                            {"nan", "nan"},
                                                                            {"1e12", "1e12"},
                                                                            {"inf", "inf"},
                                                                            {"half_mm", "0.5"}})
    v.push_back(
        P("receiver_plane_" + value.first, plane + "--size 32x32 --receiver-plane " + value.second)
            .Names({"--receiver-plane"}));
  for (const auto& value : std::vector<std::pair<std::string, std::string>>{
           {"negative", "-1"}, {"nan", "nan"}, {"1e12", "1e12"}})
    v.push_back(P("extent_" + value.first, plane + "--size 32x32 --extent " + value.second)
                    .Names({"--extent"}));
  // 0 is the documented default of both (docs/method.md §4.4): a control that must succeed.
  v.push_back(P("receiver_plane_0_is_default", plane + "--size 32x32 --receiver-plane 0")
                  .Exit(0)
                  .MayChange("r.exr"));
  v.push_back(
      P("extent_0_is_default", plane + "--size 32x32 --extent 0").Exit(0).MayChange("r.exr"));
  const std::string crypt = "--scene crypt --out r.png --size 32x32 --shadow-size 64 ";
  v.push_back(P("pose_three_values", crypt + "--luminaire-pose 1,2,3").Names({"--luminaire-pose"}));
  v.push_back(P("pose_nan", crypt + "--luminaire-pose nan,0,0,0,0,0").Names({"--luminaire-pose"}));
  v.push_back(
      P("pose_inf_angle", crypt + "--luminaire-pose 0,0,0,0,inf,0").Names({"--luminaire-pose"}));
  v.push_back(
      P("pose_1e12", crypt + "--luminaire-pose 1e12,0,0,0,0,0").Names({"--luminaire-pose"}));
  v.push_back(
      P("pose_seven_values", crypt + "--luminaire-pose 0,0,0,0,0,0,0").Names({"--luminaire-pose"}));
  v.push_back(P("shadow_size_1", "--scene crypt --out r.png --size 32x32 --shadow-size 1")
                  .Names({"--shadow-size"}));
  v.push_back(P("shadow_size_99999", "--scene crypt --out r.png --size 32x32 --shadow-size 99999")
                  .Names({"--shadow-size"}));
  v.push_back(P("shadow_size_abc", "--scene crypt --out r.png --size 32x32 --shadow-size abc")
                  .Names({"--shadow-size"}));
  v.push_back(P("out_bmp", "--scene plane --size 32x32 --out x.bmp").Names({"x.bmp"}));
  v.push_back(P("out_no_extension", "--scene plane --size 32x32 --out image").Names({"image"}));
  v.push_back(P("threads_negative", plane + "--size 32x32 --threads -1").Names({"--threads"}));
  v.push_back(P("threads_100000", plane + "--size 32x32 --threads 100000").Names({"--threads"}));
  v.push_back(P("threads_abc", plane + "--size 32x32 --threads abc").Names({"--threads"}));
  v.push_back(P("poll_zero", plane + "--size 32x32 --watch --poll 0").Names({"--poll"}));
  v.push_back(P("poll_negative", plane + "--size 32x32 --watch --poll -1").Names({"--poll"}));
  v.push_back(P("bench_frames_zero", plane + "--size 32x32 --bench --bench-frames 0")
                  .Names({"--bench-frames"}));
  v.push_back(C("preview_slab_not_found")
                  .Preview("--slab nothere " + plane + "--size 32x32")
                  .Names({"nothere"}));
  v.push_back(P("scene_file_not_found", "--scene nothere.obj --out r.png --size 32x32")
                  .Names({"nothere.obj"}));
  v.push_back(P("scene_file_garbage", "--scene ds/dataset.json --out r.png --size 32x32")
                  .Names({"ds/dataset.json"}));
  return v;
}

std::vector<Case> SlabCases() {
  std::vector<Case> v;
  const std::string& j = kSlabJson;
  auto P = [](const std::string& name) { return C("slab_" + name).Preview(); };
  v.push_back(P("json_missing").Do(RemovePath(j)).Names({j}));
  v.push_back(P("json_empty").Do(WriteText(j, "")).Names({j}));
  v.push_back(P("json_truncated").Do(Truncate(j, 0.5)).Names({j}));
  v.push_back(P("json_garbage").Do(WriteText(j, Garbage())).Names({j}));
  v.push_back(P("json_nested_100000").Do(WriteText(j, Nested(100000))).Names({j}));
  v.push_back(P("json_file_50mb").Do(Bloat(j, 50)).Names({j}));
  v.push_back(P("json_is_a_folder").Do(MakeFolder(j)).Names({j}));
  v.push_back(P("json_is_a_fifo").Do(MakeFifo(j)).Names({j}));
  v.push_back(
      P("schema_version_99").Do(SetJson(j, "/schema_version", 99)).Names({j, "schema_version"}));
  v.push_back(P("resolution_zero").Do(SetJson(j, "/resolution", {0, 40})).Names({j, "resolution"}));
  v.push_back(
      P("resolution_one_value").Do(SetJson(j, "/resolution", {40})).Names({j, "resolution"}));
  v.push_back(
      P("resolution_huge").Do(SetJson(j, "/resolution", {100000, 40})).Names({j, "resolution"}));
  v.push_back(
      P("resolution_not_files").Do(SetJson(j, "/resolution", {60, 60})).Names({"ds/slab/pos_"}));
  v.push_back(P("units_candela").Do(SetJson(j, "/units", "cd")).Names({j, "units"}));
  v.push_back(P("distance_zero").Do(SetJson(j, "/distance_mm", 0)).Names({j, "distance_mm"}));
  v.push_back(
      P("distance_nan_string").Do(SetJson(j, "/distance_mm", "NaN")).Names({j, "distance_mm"}));
  v.push_back(P("grid_nu_zero").Do(SetJson(j, "/grid/nu", 0)).Names({j, "grid.nu"}));
  v.push_back(P("grid_nu_1e9").Do(SetJson(j, "/grid/nu", 1000000000)).Names({j, "grid.nu"}));
  v.push_back(P("window_zero").Do(SetJson(j, "/window_mm", {0, 1200})).Names({j, "window_mm"}));
  v.push_back(P("filter_spacing_mismatch")
                  .Do(SetJson(j, "/filter/spacing_mm", 6))
                  .Names({j, "filter.spacing_mm"}));
  v.push_back(
      P("present_outside_grid").Do(SetJson(j, "/present", {{0, 0}, {5, 5}})).Names({j, "present"}));
  v.push_back(P("present_string").Do(SetJson(j, "/present", "all")).Names({j, "present"}));
  v.push_back(P("present_triplet").Do(SetJson(j, "/present", {{0, 0, 0}})).Names({j, "present"}));
  const std::string e = "ds/slab/pos_1_0.exr";
  v.push_back(P("exr_wrong_size").Do(ExrResize(e, 20, 20)).Names({e}));
  v.push_back(
      P("exr_nan").Do(ExrPoison(e, "R", std::numeric_limits<float>::quiet_NaN())).Names({e}));
  v.push_back(
      P("exr_inf").Do(ExrPoison(e, "G", std::numeric_limits<float>::infinity())).Names({e}));
  v.push_back(P("exr_no_mask").Do(ExrDropChannel(e, "mask")).Names({e, "mask"}));
  v.push_back(P("exr_truncated").Do(Truncate(e, 0.5)).Names({e}));
  v.push_back(P("exr_empty_file").Do(WriteText(e, "")).Names({e}));
  v.push_back(P("exr_text").Do(WriteText(e, "not an EXR\n")).Names({e}));
  v.push_back(P("exr_is_a_folder").Do(MakeFolder(e)).Names({e}));
  v.push_back(P("exr_is_a_fifo").Do(MakeFifo(e)).Names({e}));
  v.push_back(P("exr_header_32768x32768")
                  .Do(ExrHugeHeader(e, {"R", "G", "B", "mask"}, 32768, 32768))
                  .Names({e}));
  v.push_back(P("exr_position_attribute_mismatch")
                  .Do(ExrSetInt(e, "lumislab.i", 0))
                  .Names({e, "lumislab.i"}));
  // ---- Slabs and exports (issue 28, "slab.total_light"): a slab of negative total light (its
  // slides swapped, E = N - P) is refused by every stage that reads it, naming the slab.
  const Mutation negative_slab = [](const std::string& dir) {
    for (const auto& entry : fs::directory_iterator(dir + "/ds/slab"))
      if (entry.path().extension() == ".exr")
        EditExr("ds/slab/" + entry.path().filename().string(), [](ExrImage& image) {
          for (const char* c : {"R", "G", "B"})
            for (float& v : image.channels[c]) v = -v;
        })(dir);
  };
  const std::vector<std::string> negative = {j, "total light"};
  v.push_back(P("negative_light_preview").Do(negative_slab).Names(negative));
  v.push_back(C("slab_negative_light_false_colour")
                  .Preview(kPreview + " --view false-colour")
                  .Do(negative_slab)
                  .Names(negative));
  for (const std::string args :
       {"ies --slab ds --out x.ies --test T1 --lab L --manufacturer M", "ldt --slab ds --out x.ldt",
        "tm25 --slab ds --out x.ray", "polar --slab ds/slab --out x.svg",
        "irradiance --slab ds/slab --distance-mm 1000 --out x.png",
        "report --slab ds --out x.html"})
    v.push_back(C("slab_negative_light_export_" + args.substr(0, args.find(' ')))
                    .Export(args)
                    .Do(negative_slab)
                    .Do(SetJson(kSlabJson, "/units", "lux"))  // ies, ldt: lux slabs only
                    .Names(negative)
                    .MustNotExist(args.substr(args.rfind(' ') + 1)));
  v.push_back(C("slab_negative_light_reconstruct_slides_swapped")
                  .Reconstruct("--force")
                  .Do(EditJson(kDs,
                               [](json& d) {
                                 for (auto& p : d["photos"])
                                   p["slide"] = p["slide"] == "p" ? "n" : "p";
                               }))
                  .Names({"ds/photos/pos_0_0_n", "slides look swapped"})  // slides.sign
                  .MayChange("ds/slab"));
  // ---- end of slabs and exports.
  // --watch on a slab whose EXR is NaN: the same refusal, and no hang.
  v.push_back(C("slab_exr_nan_watch")
                  .Preview(kPreview + " --watch --poll 0.05")
                  .Do(ExrPoison(e, "B", std::numeric_limits<float>::quiet_NaN()))
                  .Names({e}));
  return v;
}

// Refusals that must leave a previous output alone (--force), watchers that must not wait for
// ever on a bad input, output paths, and what every tool's command line must refuse.
std::vector<Case> MoreCases() {
  std::vector<Case> v;
  const std::string e = "ds/photos/pos_1_0_p.png";
  // --force over complete outputs: a refusal leaves them byte-identical.
  v.push_back(C("force_synth_bad_scene_keeps_dataset")
                  .Synth()
                  .Args("synth --scene scene.json --out ds --force")
                  .From(Input::kSlab)
                  .Do(SetJson(kSceneFile, "/setup/distance_mm", -750))
                  .Names({kSceneFile, "setup.distance_mm"}));
  v.push_back(C("force_calibrate_no_board_keeps_calibration")
                  .Calibrate("--force")
                  .From(Input::kCalibrated)
                  .Do(CopyPath("ds/photos/pos_0_0_p.png", "ds/photos/calib_0.png"))
                  .Names({"ds/photos/calib_0.png"}));
  v.push_back(C("force_calibrate_truncated_board_keeps_calibration")
                  .Calibrate("--force")
                  .From(Input::kCalibrated)
                  .Do(Truncate("ds/photos/calib_0.png", 0.5))
                  .Names({"ds/photos/calib_0.png"}));
  v.push_back(C("force_reconstruct_bad_dataset_keeps_slab")
                  .Reconstruct("--force")
                  .From(Input::kSlab)
                  .Do(SetJson(kDs, "/setup/grid/nu", -3))
                  .Names({kDs, "setup.grid.nu"}));
  v.push_back(C("force_reconstruct_bad_calibration_keeps_slab")
                  .Reconstruct("--force")
                  .From(Input::kSlab)
                  .Do(SetJson(kScr, "/screen_from_image", std::vector<double>(9, 0.0)))
                  .Names({kScr, "screen_from_image"}));
  // --watch: a bad input is refused, not waited on (each has an idle timeout as a backstop).
  const std::string watch = "--dataset ds --resolution 40 --watch --poll 0.05 --idle-timeout 5";
  v.push_back(
      C("watch_reconstruct_dataset_fifo").ReconstructArgs(watch).Do(MakeFifo(kDs)).Names({kDs}));
  v.push_back(C("watch_reconstruct_photo_fifo")
                  .ReconstructArgs(watch)
                  .Do(MakeFifo(e))
                  .Names({e})
                  .MayChange("ds/slab/")
                  .MustNotExist("ds/slab/pos_1_0.exr"));
  v.push_back(C("watch_reconstruct_truncated_photo")
                  .ReconstructArgs(watch)
                  .Do(Truncate(e, 0.5))
                  .Names({e})
                  .MayChange("ds/slab/")
                  .MustNotExist("ds/slab/pos_1_0.exr"));
  v.push_back(C("watch_reconstruct_screen_json_garbage")
                  .ReconstructArgs(watch)
                  .Do(WriteText(kScr, Garbage()))
                  .Names({kScr}));
  v.push_back(C("watch_preview_slab_json_fifo")
                  .Preview(kPreview + " --watch --poll 0.05")
                  .Do(MakeFifo(kSlabJson))
                  .Names({kSlabJson}));
  v.push_back(C("watch_preview_slab_json_garbage")
                  .Preview(kPreview + " --watch --poll 0.05")
                  .Do(WriteText(kSlabJson, Garbage()))
                  .Names({kSlabJson}));
  // Text that is not UTF-8 inside a JSON string.
  v.push_back(C("dataset_invalid_utf8")
                  .Reconstruct()
                  .Do([](const std::string& dir) {
                    std::string text = ReadBinaryFile(dir + "/" + kDs);
                    const size_t at = text.find("photos/pos_0_0_p.png");
                    text.replace(at, 6, std::string("ph\xff\xfe\xc3s", 6));
                    WriteBinaryFile(dir + "/" + kDs, text);
                  })
                  .Names({kDs}));
  // A dataset "folder" that is a file.
  v.push_back(C("reconstruct_dataset_is_a_file")
                  .ReconstructArgs("--dataset ds/dataset.json --resolution 40")
                  .Names({"ds/dataset.json"}));
  v.push_back(C("calibrate_dataset_is_a_file")
                  .Calibrate()
                  .Args("screen --dataset ds/dataset.json")
                  .Names({"ds/dataset.json"}));
  // Scene meshes for the preview (docs/method.md §4.4: a face naming a vertex the file lacks, or
  // a non-finite vertex, is exit 2).
  v.push_back(C("preview_mesh_face_out_of_range")
                  .Preview("--slab ds/slab --scene bad.obj --out r.png --size 32x32")
                  .Do(WriteText("bad.obj", "v 0 0 0\nv 1000 0 0\nv 0 1000 0\nf 1 2 7\n"))
                  .Names({"bad.obj"}));
  v.push_back(C("preview_mesh_nan_vertex")
                  .Preview("--slab ds/slab --scene bad.obj --out r.png --size 32x32")
                  .Do(WriteText("bad.obj", "v nan 0 0\nv 1000 0 0\nv 0 1000 0\nf 1 2 3\n"))
                  .Names({"bad.obj"}));
  v.push_back(C("preview_mesh_empty")
                  .Preview("--slab ds/slab --scene bad.obj --out r.png --size 32x32")
                  .Do(WriteText("bad.obj", ""))
                  .Names({"bad.obj"}));
  // An output folder that does not exist: an I/O error (exit 3) naming the output.
  v.push_back(C("preview_out_folder_missing")
                  .Preview("--slab ds/slab --scene plane --size 32x32 --out nodir/r.exr")
                  .Exit(3)
                  .Names({"nodir/r.exr"}));
  // An output onto a special file or a link (docs/architecture.md §7.5): refused, exit 2, the
  // FIFO, the link and its target left as they were.
  v.push_back(C("preview_out_is_a_fifo")
                  .Preview()
                  .Do(MakeFifo("r.exr"))
                  .Names({"r.exr", "not a regular file"}));
  v.push_back(C("preview_out_is_a_symlink")
                  .Preview()
                  .Do(WriteText("target.exr", "not an image"))
                  .Do(MakeSymlink("r.exr", "target.exr"))
                  .Names({"r.exr", "symbolic link"}));
  v.push_back(C("preview_out_is_a_dangling_symlink")
                  .Preview()
                  .Do(MakeSymlink("r.exr", "nowhere/r.exr"))
                  .Names({"r.exr", "symbolic link"}));
  const std::string plan = "--aperture-mm 40,40 --depth-mm 20 --json plan.json";
  v.push_back(C("plan_json_onto_a_fifo")
                  .Plan(plan)
                  .Do(MakeFifo("plan.json"))
                  .Names({"plan.json", "not a regular file"}));
  v.push_back(C("plan_json_onto_a_symlink")
                  .Plan(plan)
                  .Do(WriteText("target.json", "{}"))
                  .Do(MakeSymlink("plan.json", "target.json"))
                  .Names({"plan.json", "symbolic link"}));
  // Unknown options and missing required ones (CLI11, exit 2, naming the option).
  v.push_back(C("cli_synth_unknown_option").Synth("--bogus 1").Names({"--bogus"}));
  v.push_back(C("cli_synth_scene_missing").Synth().Args("synth --out out").Names({"--scene"}));
  v.push_back(C("cli_filter_out_missing").Filter("").Args("filter --k-max 1").Names({"--out"}));
  v.push_back(C("cli_acquire_unknown_subcommand")
                  .Synth()
                  .Args("shoot --scene scene.json --out out")
                  .Names({"shoot"}));
  v.push_back(C("cli_calibrate_unknown_option").Calibrate("--bogus").Names({"--bogus"}));
  v.push_back(C("cli_calibrate_dataset_missing").Calibrate().Args("screen").Names({"--dataset"}));
  v.push_back(C("cli_reconstruct_unknown_option").Reconstruct("--bogus").Names({"--bogus"}));
  v.push_back(
      C("cli_reconstruct_dataset_missing").ReconstructArgs("--resolution 40").Names({"--dataset"}));
  v.push_back(C("cli_preview_unknown_option").Preview(kPreview + " --bogus").Names({"--bogus"}));
  v.push_back(C("cli_preview_slab_missing").Preview("--scene plane --out r.exr").Names({"--slab"}));
  v.push_back(C("cli_preview_no_output").Preview("--slab ds/slab --scene plane").Names({"--out"}));

  // ---- issue 28: the photos of a capture (reconstruct/capture_checks.h, acquire/import.cc):
  // photos that are each well-formed but do not add up as one capture. (A bracket with its
  // exposures exchanged has no case here: the masters have one photo per slide; it is
  // consistency_capture_test's BracketWithItsExposuresExchangedIsRefused.)
  // The slides swapped in dataset.json at every position: every position's light is negative.
  v.push_back(C("consistency_slides_swapped_everywhere")
                  .Reconstruct()
                  .Do(EditJson(kDs,
                               [](json& d) {
                                 for (auto& e : d["photos"])
                                   e["slide"] = e["slide"] == "p" ? "n" : "p";
                               }))
                  .Names({"ds/photos/pos_", "slides.sign"})
                  .MayChange("ds/slab/")
                  .MayChange("ds/checks.json"));
  // One photo taken with the camera turned to portrait (240 x 320 among 320 x 240).
  v.push_back(C("consistency_photo_turned_portrait")
                  .Reconstruct()
                  .Do(PngResize(e, 240, 320))
                  .Names({e, "image size"})
                  .MayChange("ds/slab/")
                  .MayChange("ds/checks.json")
                  .MustNotExist("ds/slab/pos_1_0.exr"));
  // A camera folder (synth --camera-folder: TIFFs with EXIF times, one a second) whose third
  // and fourth photos were given each other's names: import --order name is refused
  // (order.names_and_times), nothing written.
  v.push_back(
      C("consistency_import_by_name_times_backwards")
          .Synth()
          .Args("import --photos cam/camera --setup cam/setup.json --out imp --order name")
          .Do([](const std::string& dir) {
            const CommandResult r = RunToolIn(
                dir, "lumislab-acquire",
                "synth --scene scene.json --out cam --camera-folder --truth-resolution 20", 120);
            if (r.exit_code != 0) throw std::runtime_error(r.output);
            const std::string c = dir + "/cam/camera/";
            fs::rename(c + "IMG_0003.TIF", c + "swap.TIF");
            fs::rename(c + "IMG_0004.TIF", c + "IMG_0003.TIF");
            fs::rename(c + "swap.TIF", c + "IMG_0004.TIF");
          })
          .Names({"cam/camera/IMG_0004.TIF", "EXIF DateTimeOriginal", "order.names_and_times"})
          .MustNotExist("imp/dataset.json"));
  // ---- end of the photos of a capture
  return v;
}

// lumislab-calibrate dark, response, flat and scale, and the calib/ files they write as
// reconstruct (and the later steps) read them. Frames are tiny (8x6) where no calib/screen.json
// fixes their size (Input::kDataset), the photos' 320x240 otherwise.
std::vector<Case> RadiometricCases() {
  std::vector<Case> v;
  const std::string dark = "dark --dataset ds --frames f0.png f1.png";
  auto D = [&](const std::string& name, const std::string& args = "") {
    return C("dark_" + name)
        .Radiometric(args.empty() ? dark : args, Input::kDataset)
        .Do(WriteFrame("f0.png", 8, 6, 16, 0.01))
        .Do(WriteFrame("f1.png", 8, 6, 16, 0.01));
  };
  v.push_back(D("frame_not_an_image").Do(WriteText("f1.png", Garbage())).Names({"f1.png"}));
  v.push_back(D("frame_missing", "dark --dataset ds --frames f0.png nope.png").Names({"nope.png"}));
  v.push_back(D("frame_is_a_folder").Do(MakeFolder("f1.png")).Names({"f1.png"}));
  v.push_back(D("frames_mixed_sizes")
                  .Do(WriteFrame("f1.png", 10, 6, 16, 0.01))
                  .Names({"f1.png", "image size"}));
  v.push_back(D("frames_mixed_bit_depths")
                  .Do(WriteFrame("f1.png", 8, 6, 8, 0.01))
                  .Names({"f1.png", "bit depth"}));
  // calib/screen.json fixes the camera's size: 8x6 frames are of another camera.
  v.push_back(D("frame_not_the_camera_size")
                  .From(Input::kCalibrated)
                  .Names({"f0.png", "image size", "ds/calib/screen.json"}));
  v.push_back(D("exposures_count", dark + " --exposures 1").Names({"--exposures"}));
  v.push_back(D("exposure_nan", dark + " --exposures 1,nan").Names({"--exposures"}));
  v.push_back(D("exposure_negative", dark + " --exposures 1,-2").Names({"--exposures"}));
  v.push_back(D("hot_threshold_zero", dark + " --hot-threshold 0").Names({"--hot-threshold"}));
  v.push_back(D("no_frames", "dark --dataset ds --frames").Names({"--frames"}));
  // The response curve the frames are decoded through is read first.
  v.push_back(D("response_json_nan")
                  .Do(WriteCalibration("response"))
                  .Do(SetJson("ds/calib/response.json", "/linear_of_code/G/100", "NaN"))
                  .Names({"ds/calib/response.json", "linear_of_code.G"}));

  const std::string response = "response --dataset ds --frames f0.png f1.png --exposures 1,4";
  auto R = [&](const std::string& name, const std::string& args = "") {
    return C("response_" + name)
        .Radiometric(args.empty() ? response : args, Input::kDataset)
        .Do(WriteFrame("f0.png", 8, 6, 8))
        .Do(WriteFrame("f1.png", 8, 6, 8));
  };
  v.push_back(R("one_frame", "response --dataset ds --frames f0.png --exposures 1")
                  .Names({"--frames", "at least 2"}));
  // Neither EXIF (the frames have none) nor --exposures gives an exposure.
  v.push_back(R("no_exposure", "response --dataset ds --frames f0.png f1.png")
                  .Names({"f0.png", "exposure"}));
  v.push_back(R("one_exposure", "response --dataset ds --frames f0.png f1.png --exposures 2,2")
                  .Names({"f0.png", "exposure"}));
  // Uniform frames: no pixel changes over the series, no sample for the curve.
  v.push_back(R("uniform_frames")
                  .Do(WriteFrame("f0.png", 8, 6, 8, 0.3))
                  .Do(WriteFrame("f1.png", 8, 6, 8, 0.3))
                  .Names({"f0.png", "frames", "response.samples"})
                  .MayChange("ds/checks.json"));
  v.push_back(R("frame_not_an_image").Do(WriteText("f1.png", Garbage())).Names({"f1.png"}));
  v.push_back(
      R("frames_mixed_sizes").Do(WriteFrame("f1.png", 8, 7, 8)).Names({"f1.png", "image size"}));
  v.push_back(R("samples_too_few", response + " --samples 5").Names({"--samples"}));
  v.push_back(R("lambda_nan", response + " --lambda nan").Names({"--lambda"}));

  const std::string flat = "flat --dataset ds --frames f0.png";
  auto F = [&](const std::string& name, const std::string& args = "") {
    return C("flat_" + name)
        .Radiometric(args.empty() ? flat : args)
        .Do(WriteFrame("f0.png", 320, 240, 16, 0.5));
  };
  v.push_back(F("frame_clipped")
                  .Do(WriteFrame("f0.png", 320, 240, 16, 1.0))
                  .Names({"f0.png", "pixel data", "flat.clipped"})
                  .MayChange("ds/checks.json"));
  // Refused by the check flat.has_signal, recorded in ds/checks.json (issue 28).
  v.push_back(F("frame_black")
                  .Do(WriteFrame("f0.png", 320, 240, 16, 0.0))
                  .Names({"f0.png", "pixel data"})
                  .MayChange("ds/checks.json"));
  v.push_back(F("frame_not_the_camera_size")
                  .Do(WriteFrame("f0.png", 8, 6, 16, 0.5))
                  .Names({"f0.png", "image size"}));
  v.push_back(F("frame_truncated").Do(Truncate("f0.png", 0.3)).Names({"f0.png"}));
  v.push_back(F("no_screen_calibration").From(Input::kDataset).Names({"ds/calib/screen.json"}));
  v.push_back(F("smooth_negative", flat + " --smooth-px -1").Names({"--smooth-px"}));
  // The dark map the frames are corrected with is read first.
  v.push_back(F("dark_exr_nan")
                  .Do(WriteCalibration("dark"))
                  .Do(ExrPoison("ds/calib/dark.exr", "G", std::numeric_limits<float>::quiet_NaN()))
                  .Names({"ds/calib/dark.exr", "pixel data"}));

  const std::string reading = "scale --dataset ds --position 0,0 --point-mm 0,0";
  auto S = [&](const std::string& name, const std::string& args) {
    return C("scale_" + name).Radiometric(args);
  };
  v.push_back(S("point_off_screen",
                "scale --dataset ds --position 0,0 --point-mm 5000,0 "
                "--reading-p 1 --reading-n 0.5")
                  .Names({"command line", "point_mm"}));
  v.push_back(S("position_outside_grid",
                "scale --dataset ds --position 2,0 --point-mm 0,0 "
                "--reading-p 1 --reading-n 0.5")
                  .Names({"command line", "position"}));
  v.push_back(S("reading_n_negative", reading + " --reading-p 1 --reading-n -0.5")
                  .Names({"command line", "reading_n"}));
  v.push_back(S("reading_p_below_n", reading + " --reading-p 1 --reading-n 2")
                  .Names({"command line", "reading_p"}));
  v.push_back(
      S("reading_p_nan", reading + " --reading-p nan --reading-n 0.5").Names({"--reading-p"}));
  v.push_back(S("reading_missing", reading + " --reading-p 1").Names({"--reference"}));
  v.push_back(S("unit_bogus", reading + " --reading-p 1 --reading-n 0.5 --unit cd")
                  .Names({"--unit", "unit"}));
  v.push_back(S("no_screen_calibration", reading + " --reading-p 1 --reading-n 0.5")
                  .From(Input::kDataset)
                  .Names({"ds/calib/screen.json"}));
  // Slide n's photo under slide p's name: Y+ = Y-, no scale can come of the readings.
  v.push_back(S("no_contrast", reading + " --reading-p 1 --reading-n 0.5")
                  .Do(CopyPath("ds/photos/pos_0_0_n.png", "ds/photos/pos_0_0_p.png"))
                  .Names({"command line", "point_mm", "scale.point_lit"})
                  .MayChange("ds/checks.json"));
  const std::string ref = "scale --dataset ds --reference ref.json";
  const json valid_ref = {{"position", {0, 0}},
                          {"point_mm", {0, 0}},
                          {"reading_p", 1.0},
                          {"reading_n", 0.5},
                          {"unit", "W/m2"}};
  auto Ref = [&](const std::string& name) {
    return S("reference_" + name, ref).Do(WriteText("ref.json", valid_ref.dump()));
  };
  v.push_back(Ref("nan").Do(SetRaw("ref.json", "/reading_p", "NaN")).Names({"ref.json"}));
  v.push_back(Ref("reading_string")
                  .Do(SetJson("ref.json", "/reading_n", "0.5"))
                  .Names({"ref.json", "reading_n"}));
  v.push_back(
      Ref("reading_1e999").Do(SetRaw("ref.json", "/reading_p", "1e999")).Names({"ref.json"}));
  v.push_back(
      Ref("point_missing").Do(EraseJson("ref.json", "/point_mm")).Names({"ref.json", "point_mm"}));
  v.push_back(Ref("position_three_values")
                  .Do(SetJson("ref.json", "/position", {0, 0, 0}))
                  .Names({"ref.json", "position"}));
  v.push_back(Ref("position_negative")
                  .Do(SetJson("ref.json", "/position", {-1, 0}))
                  .Names({"ref.json", "position"}));
  v.push_back(
      Ref("unit_bogus").Do(SetJson("ref.json", "/unit", "cd/m2")).Names({"ref.json", "unit"}));
  v.push_back(Ref("missing").Do(RemovePath("ref.json")).Names({"ref.json"}));

  // ---- Calibration consistency (issue 28, calibrate/radiometric/calibration_checks.h): frames
  // that are well-formed but cannot be what the step reads. Each failure is recorded in
  // ds/checks.json before the exit.
  // An 8-bit 320x240 frame of a gradient scene at `gain` (a bracket of it).
  const auto bracket = [](const std::string& file, double gain) -> Mutation {
    return [=](const std::string& dir) {
      cv::Mat image(240, 320, CV_8UC3);
      for (int y = 0; y < 240; ++y)
        for (int x = 0; x < 320; ++x)
          for (int c = 0; c < 3; ++c)
            image.at<cv::Vec3b>(y, x)[c] =
                uchar(std::min(255.0, std::round(255 * gain * (0.05 + 0.6 * x / 320.0))));
      WriteImage(dir + "/" + file, image);
    };
  };
  // --exposures in another order than --frames: the brighter frame stated the shorter exposure.
  v.push_back(C("consistency_response_exposures_swapped")
                  .Radiometric("response --dataset ds --frames f0.png f1.png --exposures 1,4")
                  .Do(bracket("f0.png", 1))
                  .Do(bracket("f1.png", 0.25))
                  .Names({"f1.png", "exposure: stated 4", "f0.png", "response.exposure_order"})
                  .MayChange("ds/checks.json"));
  // A slide photo given as a dark frame: light in a pattern.
  v.push_back(C("consistency_dark_frame_is_a_slide_photo")
                  .Radiometric("dark --dataset ds --frames ds/photos/pos_0_0_p.png")
                  .Names({"ds/photos/pos_0_0_p.png", "dark.is_dark"})
                  .MayChange("ds/checks.json"));
  // An all-white frame given as a dark frame: even, but at full scale.
  v.push_back(C("consistency_dark_frame_all_white")
                  .Radiometric("dark --dataset ds --frames f0.png")
                  .Do(WriteFrame("f0.png", 320, 240, 16, 0.9))
                  .Names({"f0.png", "dark level", "dark.is_dark"})
                  .MayChange("ds/checks.json"));
  // A dark frame given as a flat: no light on the screen.
  v.push_back(C("consistency_flat_frame_is_dark")
                  .Radiometric("flat --dataset ds --frames f0.png")
                  .Do(WriteFrame("f0.png", 320, 240, 16, 0.002))
                  .Names({"f0.png", "pixel data", "flat.has_signal"})
                  .MayChange("ds/checks.json"));
  // ---- end of calibration consistency

  // The calib/ files as reconstruct reads them (every one is loaded before the first position).
  auto Cal = [&](const std::string& kind, const std::string& name) {
    return C("calib_" + kind + "_" + name).Reconstruct().Do(WriteCalibration(kind));
  };
  const std::string rj = "ds/calib/response.json", dj = "ds/calib/dark.json",
                    de = "ds/calib/dark.exr", fj = "ds/calib/flat.json", fe = "ds/calib/flat.exr",
                    sj = "ds/calib/scale.json";
  v.push_back(Cal("response", "schema_version_2")
                  .Do(SetJson(rj, "/schema_version", 2))
                  .Names({rj, "schema_version"}));
  v.push_back(Cal("response", "nan_string")
                  .Do(SetJson(rj, "/linear_of_code/R/7", "NaN"))
                  .Names({rj, "linear_of_code.R"}));
  v.push_back(Cal("response", "nan_raw").Do(SetRaw(rj, "/linear_of_code/B/9", "NaN")).Names({rj}));
  v.push_back(Cal("response", "decreasing")
                  .Do(SetJson(rj, "/linear_of_code/G/128", 0.9))
                  .Names({rj, "linear_of_code.G"}));
  v.push_back(Cal("response", "code_255_not_1")
                  .Do(SetJson(rj, "/linear_of_code/R/255", 0.999999))
                  .Names({rj, "linear_of_code.R"}));
  v.push_back(Cal("response", "255_values")
                  .Do(EraseJson(rj, "/linear_of_code/B/0"))
                  .Names({rj, "linear_of_code.B"}));
  v.push_back(Cal("response", "channel_missing")
                  .Do(EraseJson(rj, "/linear_of_code/G"))
                  .Names({rj, "linear_of_code.G"}));
  v.push_back(Cal("dark", "schema_version_2")
                  .Do(SetJson(dj, "/schema_version", 2))
                  .Names({dj, "schema_version"}));
  v.push_back(Cal("dark", "model_bogus").Do(SetJson(dj, "/model", "linear")).Names({dj, "model"}));
  v.push_back(Cal("dark", "image_size_nan").Do(SetRaw(dj, "/image_size/0", "NaN")).Names({dj}));
  v.push_back(Cal("dark", "image_size_huge")
                  .Do(SetJson(dj, "/image_size", {1000000, 1000000}))
                  .Names({dj, "image_size"}));
  v.push_back(Cal("dark", "map_in_other_folder")
                  .Do(SetJson(dj, "/map", "../photos/pos_0_0_p.png"))
                  .Names({dj, "map"}));
  v.push_back(Cal("dark", "map_is_the_folder").Do(SetJson(dj, "/map", "..")).Names({dj, "map"}));
  // The map is not the size the JSON says.
  v.push_back(Cal("dark", "exr_wrong_size").Do(ExrResize(de, 160, 120)).Names({de, "size"}));
  // JSON and map agree, but on another camera's size than the photos'.
  v.push_back(Cal("dark", "map_of_another_camera")
                  .Do(ExrResize(de, 160, 120))
                  .Do(SetJson(dj, "/image_size", {160, 120}))
                  .Names({"ds/photos/", "image size", dj}));
  v.push_back(Cal("dark", "exr_nan")
                  .Do(ExrPoison(de, "R", std::numeric_limits<float>::quiet_NaN()))
                  .Names({de, "pixel data"}));
  v.push_back(Cal("dark", "exr_huge_value").Do(ExrPoison(de, "B", 1e6f)).Names({de, "pixel data"}));
  v.push_back(Cal("dark", "exr_no_hot_channel").Do(ExrDropChannel(de, "hot")).Names({de, "hot"}));
  v.push_back(Cal("dark", "current_channels_missing")
                  .Do(SetJson(dj, "/model", "offset+current"))
                  .Names({de, "current.R"}));
  v.push_back(Cal("dark", "exr_missing").Do(RemovePath(de)).Names({de}));
  v.push_back(Cal("dark", "exr_truncated").Do(Truncate(de, 0.5)).Names({de}));
  v.push_back(Cal("flat", "exr_zero_gain").Do(ExrPoison(fe, "G", 0.f)).Names({fe, "pixel data"}));
  v.push_back(Cal("flat", "exr_inf")
                  .Do(ExrPoison(fe, "R", std::numeric_limits<float>::infinity()))
                  .Names({fe, "pixel data"}));
  v.push_back(Cal("flat", "image_size_one_value")
                  .Do(SetJson(fj, "/image_size", {320}))
                  .Names({fj, "image_size"}));
  v.push_back(Cal("flat", "exr_huge_header")
                  .Do(ExrHugeHeader(fe, {"R", "G", "B"}, 1 << 20, 1 << 20))
                  .Names({fe}));
  v.push_back(Cal("scale", "negative").Do(SetJson(sj, "/scale", -10)).Names({sj, "scale"}));
  v.push_back(Cal("scale", "nan_string").Do(SetJson(sj, "/scale", "NaN")).Names({sj, "scale"}));
  v.push_back(Cal("scale", "units_bogus").Do(SetJson(sj, "/units", "cd")).Names({sj, "units"}));
  v.push_back(Cal("scale", "schema_version_missing")
                  .Do(EraseJson(sj, "/schema_version"))
                  .Names({sj, "schema_version"}));
  return v;
}

// lumislab-export (docs/architecture.md §7.8) and the files of the lighting industry it reads and
// writes (docs/formats.md §17), and the scene's measured emitters (`distribution`, docs/formats.md
// §10), which read the same IES / EULUMDAT files. Every refusal names the file (or the option) and
// the field, and writes nothing at --out.
std::vector<Case> PhotometryCases() {
  std::vector<Case> v;
  // info on a bad file: IES, EULUMDAT (anything not IES nor TM-25) and TM-25.
  auto I = [](const std::string& name, const std::string& file) {
    return C("export_info_" + name).Export("info " + file + " --json");
  };
  v.push_back(I("missing", "nothere.ies").Names({"nothere.ies"}));
  v.push_back(I("empty", "bad.ies").Do(WriteText("bad.ies", "")).Names({"bad.ies"}));
  v.push_back(I("is_a_folder", "bad.ies").Do(MakeFolder("bad.ies")).Names({"bad.ies"}));
  v.push_back(
      I("binary_garbage", "bad.ies").Do(WriteText("bad.ies", Garbage())).Names({"bad.ies"}));
  v.push_back(I("ies_truncated", "bad.ies")
                  .Do(RealIes("bad.ies", "", "", 0.8))
                  .Names({"bad.ies", "vertical x 1 horizontal angles need"}));
  v.push_back(I("ies_cut_before_tilt", "bad.ies")
                  .Do(RealIes("bad.ies", "", "", 0.3))
                  .Names({"bad.ies", "TILT="}));
  v.push_back(I("ies_nan_candela", "bad.ies")
                  .Do(RealIes("bad.ies", " 102 90", " nan 90"))
                  .Names({"bad.ies", "candela value 21 of horizontal angle 1"}));
  v.push_back(I("ies_huge_candela", "bad.ies")
                  .Do(RealIes("bad.ies", " 102 90", " 1e999 90"))
                  .Names({"bad.ies", "candela value 21"}));
  v.push_back(I("ies_negative_candela", "bad.ies")
                  .Do(RealIes("bad.ies", " 102 90", " -102 90"))
                  .Names({"bad.ies", "intensity at C 0, gamma 50"}));
  v.push_back(I("ies_counts_huge", "bad.ies")
                  .Do(RealIes("bad.ies", "24 -1 1 37 1", "24 -1 1 100000 100000"))
                  .Names({"bad.ies", "100000 vertical x 100000 horizontal"}));
  v.push_back(I("ies_counts_over_limit", "bad.ies")
                  .Do(RealIes("bad.ies", "24 -1 1 37 1", "24 -1 1 1e12 1"))
                  .Names({"bad.ies", "number of vertical angles"}));
  v.push_back(I("ies_angles_out_of_order", "bad.ies")
                  .Do(RealIes("bad.ies", "0 2.5 5 7.5", "0 5 2.5 7.5"))
                  .Names({"bad.ies", "vertical angle 3"}));
  v.push_back(I("ies_tilt_file", "bad.ies")
                  .Do(RealIes("bad.ies", "TILT=NONE", "TILT=lamp.tlt"))
                  .Names({"bad.ies", "TILT=lamp.tlt"}));
  v.push_back(I("ies_type_b", "bad.ies")
                  .Do(RealIes("bad.ies", "37 1 1 1 -0.45", "37 1 2 1 -0.45"))
                  .Names({"bad.ies", "photometric type B"}));
  v.push_back(I("ldt_isym_9", "bad.ldt").Do(Ldt("bad.ldt", {{3, "9"}})).Names({"bad.ldt", "Isym"}));
  v.push_back(
      I("ldt_lamp_flux_zero", "bad.ldt").Do(Ldt("bad.ldt", {{29, "0"}})).Names({"bad.ldt", "26c"}));
  v.push_back(I("ldt_nan_intensity", "bad.ldt")
                  .Do(Ldt("bad.ldt", {{48, "nan"}}))
                  .Names({"bad.ldt", "intensity 2 of C plane 0"}));
  v.push_back(I("ldt_truncated", "bad.ldt")
                  .Do(Ldt("bad.ldt"))
                  .Do(Truncate("bad.ldt", 0.9))
                  .Names({"bad.ldt", "truncated"}));
  v.push_back(I("tm25_ray_count_too_high", "bad.ray")
                  .Do(Tm25("bad.ray", 5, 3))
                  .Names({"bad.ray", "number of rays", "the header says 5 rays"}));
  v.push_back(I("tm25_ray_count_huge", "bad.ray")
                  .Do(Tm25("bad.ray", uint64_t(1) << 62, 3))
                  .Names({"bad.ray", "number of rays"}));
  v.push_back(I("tm25_partial_ray", "bad.ray")
                  .Do(Tm25("bad.ray", 3, 3))
                  .Do(Truncate("bad.ray", 0.9995))
                  .Names({"bad.ray", "number of rays", "a partial one"}));
  v.push_back(I("tm25_nan_ray", "bad.ray")
                  .Do(Tm25("bad.ray", 3, 3, 1))
                  .Names({"bad.ray", "ray 1, value 1", "finite"}));
  v.push_back(I("tm25_version", "bad.ray")
                  .Do(Tm25("bad.ray", 3, 3, -1, 2014))
                  .Names({"bad.ray", "version"}));
  v.push_back(I("tm25_header_only", "bad.ray")
                  .Do(Tm25("bad.ray", 3, 3))
                  .Do(Truncate("bad.ray", 0.5))
                  .Names({"bad.ray", "truncated"}));
  // ies / ldt / tm25 from the slab: bad flags, a bad slab, an output that cannot be written.
  const std::string keywords = " --test T1 --lab L --manufacturer M";
  auto F = [&](const std::string& format, const std::string& name, const std::string& flags) {
    const std::string out = "x." + format;
    return C("export_" + format + "_" + name)
        .Export(format + " --slab ds --out " + out + (format == "ies" ? keywords : "") + " " +
                flags)
        .MustNotExist(out);
  };
  for (const std::string format : {"ies", "ldt"}) {
    v.push_back(F(format, "c_step_negative", "--c-step -5").Names({"--c-step"}));
    v.push_back(F(format, "c_step_zero", "--c-step 0").Names({"--c-step"}));
    v.push_back(F(format, "c_step_not_dividing", "--c-step 7").Names({"--c-step", "divides"}));
    v.push_back(F(format, "c_step_nan", "--c-step nan").Names({"--c-step"}));
    v.push_back(F(format, "gamma_step_above_90", "--gamma-step 100").Names({"--gamma-step"}));
    v.push_back(F(format, "c_angles_decreasing", "--c-angles 0,90,45")
                    .Names({"--c-angles", "horizontal angle 3"}));
    v.push_back(F(format, "gamma_angles_above_180", "--gamma-angles 0,90,200")
                    .Names({"--gamma-angles", "vertical angle 3"}));
    v.push_back(F(format, "samples_zero", "--samples 0").Names({"--samples"}));
    v.push_back(F(format, "opening_two_values", "--opening-mm 10,20").Names({"--opening-mm"}));
    v.push_back(F(format, "opening_nan", "--opening-mm nan,20,0").Names({"--opening-mm"}));
    // 324 million directions: refused before any work, naming the option and the bound.
    v.push_back(F(format, "grid_0_01_degrees", "--c-step 0.01 --gamma-step 0.01")
                    .Names({"--c-step", "at most 721"}));
    v.push_back(F(format, "gamma_step_0_01", "--gamma-step 0.01").Names({"--gamma-step", "361"}));
    v.push_back(F(format, "c_step_tiny", "--c-step 1e-9").Names({"--c-step"}));
  }
  v.push_back(F("ies", "no_test_keyword", "")
                  .Args("ies --slab ds --out x.ies --lab L --manufacturer M")
                  .Names({"x.ies", "[TEST]"}));
  v.push_back(
      F("ies", "metadata_missing", "--metadata meta.json").Names({"meta.json", "not found"}));
  v.push_back(F("ies", "metadata_not_json", "--metadata meta.json")
                  .Do(WriteText("meta.json", "{\"test\": "))
                  .Names({"meta.json", "not valid JSON"}));
  v.push_back(F("ies", "metadata_unknown_member", "--metadata meta.json")
                  .Do(WriteText("meta.json", "{\"schema_version\": 1, \"colour\": \"red\"}"))
                  .Names({"meta.json", "colour"}));
  v.push_back(
      F("ies", "metadata_keyword_lower_case", "--metadata meta.json")
          .Do(WriteText("meta.json", "{\"schema_version\": 1, \"keywords\": {\"bad\": \"x\"}}"))
          .Names({"meta.json", "keywords.bad"}));
  v.push_back(F("ies", "slab_missing", "")
                  .Args("ies --slab nowhere --out x.ies" + keywords)
                  .Names({"nowhere", "no slab.json"}));
  v.push_back(F("ies", "slab_partial", "")
                  .Do(SetJson(kSlabJson, "/present", {{0, 0}}))
                  .Do(SetJson(kSlabJson, "/units", "lux"))
                  .Names({kSlabJson, "present"}));
  v.push_back(
      F("ldt", "slab_exr_nan", "")
          .Do(ExrPoison("ds/slab/pos_1_0.exr", "R", std::numeric_limits<float>::quiet_NaN()))
          .Do(SetJson(kSlabJson, "/units", "lux"))
          .Names({"ds/slab/pos_1_0.exr"}));
  // Issue 29: IES and EULUMDAT hold candela, from a slab in lux only (this one is W/m^2), naming
  // how to calibrate; a grid the screen did not wholly see is refused without --allow-partial;
  // an existing output is exit 2 unless --force, the file left as it was.
  for (const std::string format : {"ies", "ldt"})
    v.push_back(
        F(format, "slab_not_lux", "")
            .Names({kSlabJson, "units", "expected lux", "lumislab-calibrate scale", "got W/m^2"}));
  v.push_back(F("ies", "grid_partly_unseen", "")
                  .Do(SetJson(kSlabJson, "/units", "lux"))
                  .Names({"x.ies", "did not see every direction", "--allow-partial"}));
  v.push_back(F("tm25", "rays_partly_unseen", "--rays 10")
                  .Names({"x.tm25", "rays would miss light", "--allow-partial"}));
  v.push_back(C("export_ies_out_exists")
                  .Export("ies --slab ds --out x.ies" + keywords)
                  .Do(WriteText("x.ies", "an older file\n"))
                  .Names({"x.ies", "exists", "--force"}));
  v.push_back(C("export_ies_out_folder_missing")
                  .Export("ies --slab ds --out nodir/x.ies" + keywords)
                  .Exit(3)
                  .Names({"nodir/x.ies", "cannot"}));
  // An output onto a special file or a link (docs/architecture.md §7.5), with and without
  // --force: exit 2 before the slab is read, the FIFO, the link and its target unchanged.
  for (const std::string force : {"", " --force"}) {
    const std::string tag = force.empty() ? "" : "_force";
    v.push_back(C("export_ies_out_is_a_fifo" + tag)
                    .Export("ies --slab ds --out x.ies" + keywords + force)
                    .Do(MakeFifo("x.ies"))
                    .Names({"x.ies", "not a regular file"}));
    v.push_back(C("export_ies_out_is_a_symlink" + tag)
                    .Export("ies --slab ds --out x.ies" + keywords + force)
                    .Do(WriteText("target.ies", "IESNA:LM-63-2019\n"))
                    .Do(MakeSymlink("x.ies", "target.ies"))
                    .Names({"x.ies", "symbolic link", "target's path"}));
  }
  v.push_back(C("export_ies_out_is_a_dangling_symlink")
                  .Export("ies --slab ds --out x.ies" + keywords)
                  .Do(MakeSymlink("x.ies", "nowhere.ies"))
                  .Names({"x.ies", "symbolic link"}));
  v.push_back(C("export_ldt_out_is_a_fifo")
                  .Export("ldt --slab ds --out x.ldt --force")
                  .Do(MakeFifo("x.ldt"))
                  .Names({"x.ldt", "not a regular file"}));
  v.push_back(C("export_tm25_out_is_a_symlink")
                  .Export("tm25 --slab ds --out x.ray --rays 10 --force")
                  .Do(WriteText("target.ray", "rays"))
                  .Do(MakeSymlink("x.ray", "target.ray"))
                  .Names({"x.ray", "symbolic link"}));
  v.push_back(C("export_polar_out_is_a_fifo")
                  .Export("polar --slab ds/slab --out p.svg")
                  .Do(MakeFifo("p.svg"))
                  .Names({"p.svg", "not a regular file"}));
  v.push_back(C("export_irradiance_out_is_a_symlink")
                  .Export("irradiance --slab ds/slab --distance-mm 1000 --out i.png")
                  .Do(WriteText("target.png", "not a picture"))
                  .Do(MakeSymlink("i.png", "target.png"))
                  .Names({"i.png", "symbolic link"}));
  v.push_back(C("export_ldt_out_is_a_folder")
                  .Export("ldt --slab ds --out x.ldt --force")
                  .Do(MakeFolder("x.ldt"))
                  .Exit(3)
                  .Names({"x.ldt", "cannot"}));
  auto T = [](const std::string& name, const std::string& flags) {
    return C("export_tm25_" + name)
        .Export("tm25 --slab ds --out x.ray " + flags)
        .MustNotExist("x.ray");
  };
  v.push_back(T("rays_zero", "--rays 0").Names({"--rays"}));
  v.push_back(T("rays_negative", "--rays -10").Names({"--rays"}));
  v.push_back(T("rays_above_limit", "--rays 1000000000").Names({"--rays"}));
  v.push_back(T("rays_text", "--rays many").Names({"--rays"}));
  v.push_back(T("seed_negative", "--seed -1").Names({"--seed", "expected an integer >= 0"}));
  v.push_back(T("slab_partial", "")
                  .Do(SetJson(kSlabJson, "/present", {{0, 0}}))
                  .Names({kSlabJson, "present"}));
  v.push_back(C("export_tm25_out_folder_missing")
                  .Export("tm25 --slab ds --out nodir/x.ray --rays 10")
                  .Exit(3)
                  .Names({"nodir/x.ray", "cannot"}));
  // irradiance and polar (docs/method.md §4.9).
  auto P = [](const std::string& cmd, const std::string& name, const std::string& flags,
              const std::string& out) {
    return C("export_" + cmd + "_" + name)
        .Export(cmd + " --slab ds/slab --out " + out + " " + flags)
        .MustNotExist(out);
  };
  v.push_back(
      P("irradiance", "distance_zero", "--distance-mm 0", "i.png").Names({"--distance-mm"}));
  v.push_back(
      P("irradiance", "distance_nan", "--distance-mm nan", "i.png").Names({"--distance-mm"}));
  v.push_back(P("irradiance", "extent_negative", "--distance-mm 1000 --extent-mm -5", "i.png")
                  .Names({"--extent-mm"}));
  v.push_back(
      P("irradiance", "size_huge", "--distance-mm 1000 --size 100000", "i.png").Names({"--size"}));
  v.push_back(
      P("irradiance", "range_bad", "--distance-mm 1000 --range 5,1", "i.png").Names({"--range"}));
  v.push_back(P("irradiance", "range_reversed", "--distance-mm 1000 --range 5:1", "i.png")
                  .Names({"--range"}));
  v.push_back(P("irradiance", "out_bmp", "--distance-mm 1000", "i.bmp").Names({"i.bmp", "--out"}));
  v.push_back(P("polar", "gamma_step_zero", "--gamma-step 0", "p.svg").Names({"--gamma-step"}));
  v.push_back(P("polar", "size_10", "--size 10", "p.svg").Names({"--size"}));
  v.push_back(P("polar", "out_txt", "", "p.txt").Names({"p.txt", "--out"}));
  v.push_back(P("polar", "slab_partial", "", "p.svg")
                  .Do(SetJson(kSlabJson, "/present", {{0, 0}}))
                  .Names({kSlabJson, "present"}));
  v.push_back(P("irradiance", "slab_partial", "--distance-mm 1000", "i.png")
                  .Do(SetJson(kSlabJson, "/present", {{0, 0}, {1, 1}}))
                  .Names({kSlabJson, "present"}));
  v.push_back(C("export_irradiance_out_folder_missing")
                  .Export("irradiance --slab ds/slab --distance-mm 1000 --out nodir/i.png")
                  .Exit(3)
                  .Names({"nodir/i.png", "cannot"}));
  // report (docs/method.md §4.10): the same refusals, nothing written.
  v.push_back(P("report", "out_txt", "", "r.txt").Names({"r.txt", "--out"}));
  v.push_back(P("report", "pdf_txt", "--pdf r.txt", "r.html").Names({"r.txt", "--pdf"}));
  v.push_back(P("report", "c_step_7", "--c-step 7", "r.html").Names({"--c-step", "divid"}));
  v.push_back(P("report", "gamma_step_zero", "--gamma-step 0", "r.html").Names({"--gamma-step"}));
  v.push_back(
      P("report", "distances_zero", "--distances-mm 0", "r.html").Names({"--distances-mm"}));
  v.push_back(
      P("report", "input_watts_nan", "--input-watts nan", "r.html").Names({"--input-watts"}));
  v.push_back(P("report", "slab_partial", "", "r.html")
                  .Do(SetJson(kSlabJson, "/present", {{0, 0}}))
                  .Names({kSlabJson, "present"}));
  v.push_back(C("export_report_out_folder_missing")
                  .Export("report --slab ds/slab --out nodir/r.html")
                  .Exit(3)
                  .Names({"nodir/r.html", "cannot"}));
  v.push_back(C("cli_export_unknown_subcommand").Export("pdf --slab ds").Names({"pdf"}));
  v.push_back(C("cli_export_unknown_option").Export("info x.ies --bogus").Names({"--bogus"}));
  v.push_back(C("cli_export_no_subcommand").Export("").Names({"subcommand"}));
  // The scene's measured emitters: the same readers behind lumislab-acquire synth.
  auto S = [](const std::string& name) { return C("scene_distribution_" + name).Synth(); };
  v.push_back(S("missing_file").Do(SceneDistribution("nothere.ies")).Names({"nothere.ies"}));
  v.push_back(S("truncated_ies")
                  .Do(SceneDistribution("lamp.ies"))
                  .Do(RealIes("lamp.ies", "", "", 0.8))
                  .Names({"lamp.ies", "vertical x 1 horizontal angles need"}));
  v.push_back(S("nan_candela")
                  .Do(SceneDistribution("lamp.ies"))
                  .Do(RealIes("lamp.ies", " 102 90", " nan 90"))
                  .Names({"lamp.ies", "candela value 21"}));
  v.push_back(S("all_zero")
                  .Do(SceneDistribution("lamp.ldt"))
                  .Do(Ldt("lamp.ldt", {{47, "0"}, {48, "0"}}))
                  .Names({"lamp.ldt", "no light"}));
  v.push_back(S("ldt_isym_9")
                  .Do(SceneDistribution("lamp.ldt"))
                  .Do(Ldt("lamp.ldt", {{3, "9"}}))
                  .Names({"lamp.ldt", "Isym"}));
  v.push_back(S("tm25_file")
                  .Do(SceneDistribution("lamp.ray"))
                  .Do(Tm25("lamp.ray", 3, 3))
                  .Names({"lamp.ray"}));
  v.push_back(S("is_a_folder")
                  .Do(SceneDistribution("lamp.ies"))
                  .Do(MakeFolder("lamp.ies"))
                  .Names({"lamp.ies"}));
  v.push_back(S("and_lobe")
                  .Do(SceneDistribution("lamp.ies"))
                  .Do(RealIes("lamp.ies"))
                  .Do(SetJson(kSceneFile, "/luminaire/emitters/0/lobe_exponent", 4))
                  .Names({kSceneFile, "luminaire.emitters[0]"}));
  v.push_back(S("rotation_huge")
                  .Do(SceneDistribution("lamp.ies", {{"rotation_deg", {0, 1e9, 0}}}))
                  .Do(RealIes("lamp.ies"))
                  .Names({kSceneFile, "rotation_deg"}));
  v.push_back(S("rotation_two_values")
                  .Do(SceneDistribution("lamp.ies", {{"rotation_deg", {0, 90}}}))
                  .Do(RealIes("lamp.ies"))
                  .Names({kSceneFile, "rotation_deg"}));
  v.push_back(S("unknown_member")
                  .Do(SceneDistribution("lamp.ies", {{"scale", 2}}))
                  .Do(RealIes("lamp.ies"))
                  .Names({kSceneFile, "distribution.scale"}));
  v.push_back(S("file_not_a_string")
                  .Do(SetJson(kSceneFile, "/luminaire/emitters/0/distribution", {{"file", 7}}))
                  .Do(EraseJson(kSceneFile, "/luminaire/emitters/0/lobe_exponent"))
                  .Names({kSceneFile, "distribution.file"}));
  return v;
}

// lumislab-acquire capture: setups and devices it cannot work with, refused before any device
// moves and before the dataset folder is made (docs/formats.md §3, "Capturing with lumislab").
// The devices that need an emulator to answer (a silent stage, a camera not found, an exposure
// time the camera lacks) are tested in tests/e2e/capture_test.cc.
std::vector<Case> CaptureCases() {
  std::vector<Case> v;
  const std::string lab =
      R"({"stage": {"origin_mm": [150, 150], "travel_mm": {"X": [0, 300], "Y": [0, 300]}},
          "camera": {"brackets": 1, "shutter_s": [0.5], "board_shutter_s": 0.1}})";
  auto K = [&](const std::string& name, const std::string& stage, const std::string& camera) {
    return C("capture_" + name)
        .Args("capture --setup ds/dataset.json --stage " + stage + " --camera " + camera +
              " --out cap")
        .From(Input::kDataset)
        .Do(SetRaw(kDs, "/lab", lab))
        .MustNotExist("cap");
  };
  auto tool = [](C c) {
    Case k = c;
    k.tool = "lumislab-acquire";
    return k;
  };
  v.push_back(tool(C("capture_setup_without_lab")
                       .Args("capture --setup ds/dataset.json --stage manual --camera folder:ds "
                             "--out cap")
                       .From(Input::kDataset)
                       .MustNotExist("cap")
                       .Names({kDs, "lab"})));
  v.push_back(tool(K("unknown_stage_scheme", "usb:/dev/ttyUSB0", "folder:ds")
                       .Names({"--stage", "usb:/dev/ttyUSB0"})));
  v.push_back(
      tool(K("unknown_camera_scheme", "manual", "webcam:0").Names({"--camera", "webcam:0"})));
  v.push_back(
      tool(K("bad_baud", "grbl:ds/ttyUSB0?baud=12", "folder:ds").Names({"--stage", "baud"})));
  v.push_back(tool(K("stage_port_not_a_tty", "grbl:ds/dataset.json", "folder:ds")
                       .Names({"grbl:ds/dataset.json", "tty"})));
  v.push_back(tool(K("stage_port_missing", "grbl:ds/ttyUSB9", "folder:ds").Names({"ds/ttyUSB9"})));
  v.push_back(tool(K("stage_program_missing", "command:ds/mover", "folder:ds")
                       .Names({"command:ds/mover", "not an executable"})));
  v.push_back(tool(K("camera_folder_missing", "manual", "folder:ds/tether")
                       .Names({"folder:ds/tether", "not found"})));
  v.push_back(tool(K("grid_beyond_soft_limits", "manual", "folder:ds")
                       .Do(SetRaw(kDs, "/lab/stage/travel_mm/X", "[0, 151]"))
                       .Names({kDs, "lab.stage.travel_mm.X"})));
  v.push_back(tool(K("axis_without_travel", "manual", "folder:ds")
                       .Do(SetRaw(kDs, "/lab/stage/travel_mm", R"({"X": [0, 300]})"))
                       .Names({kDs, "lab.stage.travel_mm.Y"})));
  v.push_back(tool(K("brackets_zero", "manual", "folder:ds")
                       .Do(SetRaw(kDs, "/lab/camera/brackets", "0"))
                       .Names({kDs, "lab.camera.brackets"})));
  v.push_back(tool(K("slide_axis_is_a_grid_axis", "manual", "folder:ds")
                       .Do(SetRaw(kDs, "/lab/slides", R"({"axis": "X", "p_mm": 0, "n_mm": 50})"))
                       .Names({kDs, "lab.slides.axis"})));
  // A camera whose exposure times lumislab cannot set, without the times given.
  v.push_back(tool(K("folder_camera_without_times", "command:/bin/true", "folder:ds")
                       .Do(SetRaw(kDs, "/lab/camera", R"({"brackets": 1})"))
                       .Names({kDs, "lab.camera.shutter_s"})));
  v.push_back(
      tool(K("bad_order", "manual", "folder:ds")
               .Args("capture --setup ds/dataset.json --stage manual --camera folder:ds --out "
                     "cap --order random")
               .Names({"--order", "random"})));
  // capture --orientations (formats.md §19, "Capturing orientations in the lab"): the plan against
  // the lab's rotation axis, refused before a device is opened or the luminaire folder made.
  const std::string plan = R"({"schema_version": 1, "coverage": "sphere", "orientations": [
      {"name": "o00", "dataset": "o00", "rotation_deg": [0, 0, 0], "centre_mm": [0, 0, 0],
       "mount": 0, "axis_deg": 0},
      {"name": "o01", "dataset": "o01", "rotation_deg": [ROTATION], "centre_mm": [0, 0, 0],
       "mount": 0, "axis_deg": ANGLE}]})";
  auto O = [&](const std::string& name, const std::string& rotation, const std::string& angle) {
    std::string text = plan;
    text.replace(text.find("ROTATION"), 8, rotation);
    text.replace(text.find("ANGLE"), 5, angle);
    return C("capture_orientations_" + name)
        .Args(
            "capture --setup ds/dataset.json --stage manual --camera folder:ds --out lum "
            "--orientations plan.json")
        .From(Input::kDataset)
        .Do(SetRaw(kDs, "/lab", lab))
        .Do(SetRaw(kDs, "/lab/stage/travel_mm/A", "[-180, 180]"))
        .Do(SetRaw(kDs, "/lab/rotation_axis", R"({"stage_axis": "A", "about": "y"})"))
        .Do(WriteText("plan.json", text))
        .MustNotExist("lum");
  };
  v.push_back(tool(O("turned_about_another_axis", "90, 0, 0", "90")
                       .Names({"plan.json", "orientations[1].rotation_deg", "about y"})));
  v.push_back(tool(O("beyond_the_axis_travel", "0, 270, 0", "270")
                       .Names({"plan.json", "orientations[1].axis_deg", "[-180, 180]"})));
  v.push_back(
      tool(O("axis_of_the_grid", "0, 90, 0", "90")
               .Do(SetRaw(kDs, "/lab/rotation_axis", R"({"stage_axis": "X", "about": "y"})"))
               .Names({kDs, "lab.rotation_axis.stage_axis"})));
  return v;
}

std::vector<Case> AllCases() {
  std::vector<Case> all;
  for (auto part :
       {DatasetCases(), ScreenCalibrationCases(), PhotoCases(), SceneCases(), CommandLineCases(),
        SlabCases(), MoreCases(), RadiometricCases(), PhotometryCases(), CaptureCases()})
    all.insert(all.end(), part.begin(), part.end());
  return all;
}

// ------------------------------------------------------------------------------------------
// The check.

bool Allowed(const std::string& path, const std::vector<std::string>& prefixes) {
  for (const auto& p : prefixes)
    if (path.compare(0, p.size(), p) == 0 || (p.back() == '/' && path + "/" == p)) return true;
  return false;
}

const char* kCrashMarkers[] = {"terminate called", "Aborted",        "Segmentation fault",
                               "core dumped",      "std::bad_alloc", "Assertion",
                               "what():"};

class Catalogue : public ::testing::TestWithParam<Case> {
 protected:
  void TearDown() override {
    if (!dir_.empty() && !std::getenv("LUMISLAB_KEEP_CASES")) fs::remove_all(dir_);
  }
  std::string dir_;
};

TEST_P(Catalogue, Refuses) {
  const Case& c = GetParam();
  if (!fs::exists(std::string(LUMISLAB_BIN_DIR) + "/" + c.tool))
    GTEST_SKIP() << c.tool << " is not built (LUMISLAB_BUILD_PREVIEW=OFF?)";
  if (!testing::InSanitizerSample(c.name, kSanitizerSampleEvery))
    GTEST_SKIP() << "sanitized build: runs 1 case in " << kSanitizerSampleEvery
                 << " (the Release build runs them all)";
  std::string error;
  const std::string master = Masters::Get(c.input, &error);
  ASSERT_TRUE(error.empty()) << "making the valid input failed:\n" << error;
  dir_ = testing::FreshDir("catalogue_" + c.name + "_" + std::to_string(getpid()));
  testing::WriteFile(dir_ + "/scene.json", ValidScene(true));
  if (!master.empty()) {
    fs::copy(master, dir_ + "/ds", fs::copy_options::recursive);
    if (c.input == Input::kDataset) fs::remove_all(dir_ + "/ds/calib");
    if (c.input != Input::kSlab) fs::remove_all(dir_ + "/ds/slab");
  }
  for (const auto& m : c.mutations) ASSERT_NO_THROW(m(dir_)) << "mutation failed";
  const TreeSnapshot before = SnapshotTree(dir_);

  const CommandResult r = RunToolIn(dir_, c.tool, c.args, kTimeoutS, kMemoryLimitKb);
  std::vector<std::string> problems;

  // Exit code (124: it hung; >= 128: a signal).
  const bool warned = c.warning_ok && r.exit_code == 0;
  if (warned) {
    if (r.output.find("warning") == std::string::npos)
      problems.push_back("exit 0 without a warning");
  } else if (r.exit_code != c.exit_code) {
    problems.push_back("exit code " + std::to_string(r.exit_code) + ", expected " +
                       std::to_string(c.exit_code) +
                       (r.exit_code == 124 ? " (timed out: a hang)" : "") +
                       (r.exit_code > 128 ? " (killed by a signal: a crash)" : ""));
  }
  // The tool's answer, shown for passing cases too (ctest -V, or the test binary run directly).
  std::printf("$ %s %s\n  -> exit %d\n%s", c.tool.c_str(), c.args.c_str(), r.exit_code,
              r.output.c_str());
  if (c.warning_ok) RecordProperty("outcome", warned ? "exit 0 with a warning" : "refused");
  for (const char* marker : kCrashMarkers)
    if (r.output.find(marker) != std::string::npos)
      problems.push_back(std::string("crash marker \"") + marker + "\" in the output");
  // One line names the file and the field (for a warning: the line that says it).
  if (!c.mentions.empty()) {
    bool found = false;
    std::istringstream lines(r.output);
    for (std::string line; std::getline(lines, line) && !found;) {
      if (warned && line.find("warning") == std::string::npos) continue;
      found = std::all_of(c.mentions.begin(), c.mentions.end(),
                          [&](const std::string& m) { return line.find(m) != std::string::npos; });
    }
    std::string wanted;
    for (const auto& m : c.mentions) wanted += " \"" + m + "\"";
    if (!found) problems.push_back("no output line names all of" + wanted);
  }
  // Nothing changed but what the case allows; no temporary file anywhere.
  const TreeSnapshot after = SnapshotTree(dir_);
  // (checks.json is the stages' report of what they checked, a refusal included: not an output.)
  for (const auto& d : testing::DiffSnapshots(before, after)) {
    const std::string path = d.substr(0, d.find(": "));
    if (!Allowed(path, c.may_change) && fs::path(path).filename() != "checks.json")
      problems.push_back("changed: " + d);
  }
  for (const auto& t : testing::TemporaryPaths(after))
    problems.push_back("temporary file left: " + t);
  for (const auto& path : c.must_not_exist)
    if (after.count(path)) problems.push_back("written although its input is bad: " + path);

  std::string report;
  for (const auto& p : problems) report += "  - " + p + "\n";
  EXPECT_TRUE(problems.empty()) << c.name << ":\n"
                                << report << "$ (cd " << dir_ << " && " << c.tool << " " << c.args
                                << ")\n  -> exit " << r.exit_code << "\n"
                                << r.output;
}

// The table covers the five tools, each with cases of its own; prints the counts.
TEST(CatalogueTable, CoversTheFiveTools) {
  std::map<std::string, int> by_tool;
  const std::vector<Case> all = AllCases();
  for (const Case& c : all) ++by_tool[c.tool];
  for (const auto& [tool, n] : by_tool) std::printf("%s: %d cases\n", tool.c_str(), n);
  EXPECT_GE(all.size(), 100u);
  for (const char* tool : {"lumislab-acquire", "lumislab-calibrate", "lumislab-reconstruct",
                           "lumislab-preview", "lumislab-export"})
    EXPECT_GE(by_tool[tool], 10) << tool;
}

INSTANTIATE_TEST_SUITE_P(Cli, Catalogue, ::testing::ValuesIn(AllCases()),
                         [](const ::testing::TestParamInfo<Case>& param) {
                           return param.param.name;
                         });

}  // namespace
}  // namespace lumislab
