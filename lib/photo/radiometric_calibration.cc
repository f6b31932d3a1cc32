#include "lib/photo/radiometric_calibration.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>

#include "core/error.h"
#include "core/exr_io.h"
#include "core/json.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

const char* kRgb[3] = {"R", "G", "B"};

std::string Beside(const std::string& json_path, const std::string& file) {
  return (fs::path(json_path).parent_path() / file).string();
}

// The map of a calibration JSON and the JSON are one result, written in two files; the JSON's
// rename is the commit. The map is written first under a name of its own content
// (<stem>-<16 hex digits of the FNV-1a hash of its channel names and values>.exr), so that until
// the JSON is renamed into place the previous JSON still names the previous map, intact: an
// interrupted recalibration (--force) leaves the old pair, never a new map under an old JSON.
// Once the JSON is in place, the maps of the stem that it does not name (the previous one, and
// those of interrupted runs) are removed. Returns the map's file name.
std::string WriteMapBeside(const std::string& json_path, const ImageF& map,
                           const std::vector<std::string>& names) {
  uint64_t hash = 1469598103934665603ull;
  auto mix = [&hash](const void* data, size_t bytes) {
    for (size_t k = 0; k < bytes; ++k) {
      hash ^= static_cast<const unsigned char*>(data)[k];
      hash *= 1099511628211ull;
    }
  };
  for (const std::string& n : names) mix(n.c_str(), n.size() + 1);
  mix(&map.width, sizeof map.width);
  mix(&map.height, sizeof map.height);
  mix(map.data.data(), map.data.size() * sizeof(float));
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  const std::string file = fs::path(json_path).stem().string() + "-" + hex + ".exr";
  WriteExr(Beside(json_path, file), map, names, {}, {false, ExrCompression::kPiz});
  return file;
}

// After the JSON is in place: removes <stem>.exr and <stem>-<hex>.exr beside it other than `keep`.
void RemoveOtherMaps(const std::string& json_path, const std::string& keep) {
  const std::string stem = fs::path(json_path).stem().string();
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(fs::path(json_path).parent_path(), ec)) {
    const std::string name = e.path().filename().string();
    const bool plain = name == stem + ".exr";
    const bool hashed =
        name.size() == stem.size() + 21 && name.rfind(stem + "-", 0) == 0 &&
        name.compare(name.size() - 4, 4, ".exr") == 0 &&
        name.find_first_not_of("0123456789abcdef", stem.size() + 1) == name.size() - 4;
    if ((plain || hashed) && name != keep) fs::remove(e.path(), ec);
  }
}

// The map file a calibration JSON names: a plain file name beside it (no folders; "." and ".."
// name the folders themselves, a NUL byte would end the name early).
std::string MapFileOf(const JsonView& root) {
  const JsonView map = root["map"];
  const std::string name = map.String();
  if (name.empty() || name == "." || name == ".." ||
      name.find_first_of(std::string("/\\\0", 3)) != std::string::npos)
    map.Fail("a file name beside the JSON (no folder)");
  return name;
}

// Reads the map's channels and checks its size against image_size and its values.
ImageF ReadMap(const JsonView& root, const std::string& json_path,
               const std::vector<std::string>& channels, double lo, double hi) {
  const int w = root["image_size"][0].IntIn(1, 65536);
  const int h = root["image_size"][1].IntIn(1, 65536);
  const std::string path = Beside(json_path, MapFileOf(root));
  ImageF image = ReadExr(path, channels);
  if (image.width != w || image.height != h)
    throw InputError(
        path, "size",
        std::to_string(w) + "x" + std::to_string(h) + " (" + json_path + " image_size)",
        std::to_string(image.width) + "x" + std::to_string(image.height));
  for (float v : image.data)
    if (!(v >= lo && v <= hi))
      throw InputError(path, "pixel data",
                       "finite values in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]",
                       std::to_string(v));
  return image;
}

ImageF Channels(const ImageF& image, int first, int count) {
  ImageF out(image.width, image.height, count);
  for (size_t p = 0; p < size_t(image.width) * image.height; ++p)
    for (int c = 0; c < count; ++c)
      out.data[p * count + c] = image.data[p * image.channels + first + c];
  return out;
}

nlohmann::json Header(const std::string& kind, int width, int height) {
  nlohmann::json j;
  j["schema_version"] = kRadiometricCalibrationSchemaVersion;
  j["kind"] = kind;
  if (width > 0) j["image_size"] = {width, height};
  return j;
}

}  // namespace

DarkMap LoadDarkMap(const std::string& json_path) {
  const JsonDocument doc = JsonDocument::Load(json_path);
  doc.CheckSchemaVersion(kRadiometricCalibrationSchemaVersion);
  const JsonView root = doc.root();
  const std::string model = root["model"].OneOf({"constant", "offset+current"});
  std::vector<std::string> names = {"R", "G", "B", "hot"};
  if (model == "offset+current")
    for (const char* c : kRgb) names.push_back(std::string("current.") + c);
  // Dark levels are small parts of full scale; a negative offset comes from a black level set
  // too high in dataset.json and is kept (it is subtracted all the same).
  const ImageF all = ReadMap(root, json_path, names, -1, 100);
  DarkMap map;
  map.file = json_path;
  map.offset = Channels(all, 0, 3);
  if (model == "offset+current") map.current = Channels(all, 4, 3);
  map.hot.resize(size_t(all.width) * all.height);
  for (size_t p = 0; p < map.hot.size(); ++p) {
    map.hot[p] = all.data[p * all.channels + 3] > 0.5f;
    map.hot_count += map.hot[p];
  }
  return map;
}

void SaveDarkMap(const std::string& json_path, const DarkMap& map, const nlohmann::json& report) {
  const int w = map.offset.width, h = map.offset.height;
  const bool current = !map.current.empty();
  std::vector<std::string> names = {"R", "G", "B", "hot"};
  if (current)
    for (const char* c : kRgb) names.push_back(std::string("current.") + c);
  ImageF all(w, h, int(names.size()));
  for (size_t p = 0; p < size_t(w) * h; ++p) {
    float* o = &all.data[p * all.channels];
    for (int c = 0; c < 3; ++c) o[c] = map.offset.data[p * 3 + c];
    o[3] = map.hot[p] ? 1.f : 0.f;
    if (current)
      for (int c = 0; c < 3; ++c) o[4 + c] = map.current.data[p * 3 + c];
  }
  const std::string exr = WriteMapBeside(json_path, all, names);
  nlohmann::json j = Header("dark", w, h);
  j["map"] = exr;
  j["model"] = current ? "offset+current" : "constant";
  j["units"] = "decoder linear units before the exposure division; current per unit exposure";
  j["report"] = report;
  WriteJsonAtomically(json_path, j);
  RemoveOtherMaps(json_path, exr);
}

ResponseCurve LoadResponseCurve(const std::string& json_path) {
  const JsonDocument doc = JsonDocument::Load(json_path);
  doc.CheckSchemaVersion(kRadiometricCalibrationSchemaVersion);
  const JsonView curves = doc.root()["linear_of_code"];
  ResponseCurve curve;
  curve.file = json_path;
  for (int c = 0; c < 3; ++c) {
    const JsonView list = curves[kRgb[c]];
    const std::vector<double> values = list.Numbers(256);
    std::array<float, 256>& out = curve.linear_of_code[c];
    for (int k = 0; k < 256; ++k) {
      // Increasing as the decoder uses it: in single precision (two values closer than a float
      // apart, e.g. 0.99999999999 and 1, would become one code value).
      out[k] = float(values[k]);
      if (!(values[k] >= 0 && values[k] <= 1) || (k > 0 && !(out[k] > out[k - 1])))
        list[size_t(k)].Fail("a value in [0, 1] above that of code " + std::to_string(k - 1) +
                             " (as a 32-bit float)");
    }
    if (values[255] != 1) list[255].Fail("1 (the curve is normalised at code 255)");
  }
  return curve;
}

void SaveResponseCurve(const std::string& json_path, const ResponseCurve& curve,
                       const nlohmann::json& report) {
  nlohmann::json j = Header("response", 0, 0);
  j["bit_depth"] = 8;
  for (int c = 0; c < 3; ++c) {
    nlohmann::json list = nlohmann::json::array();
    for (float v : curve.linear_of_code[c]) list.push_back(v);
    j["linear_of_code"][kRgb[c]] = list;
  }
  j["report"] = report;
  WriteJsonAtomically(json_path, j);
}

FlatMap LoadFlatMap(const std::string& json_path) {
  const JsonDocument doc = JsonDocument::Load(json_path);
  doc.CheckSchemaVersion(kRadiometricCalibrationSchemaVersion);
  FlatMap map;
  map.file = json_path;
  // A gain below 1e-3 of the mean would amplify the pixel's noise a thousandfold: refused.
  map.gain = ReadMap(doc.root(), json_path, {"R", "G", "B"}, 1e-3, 1e3);
  return map;
}

void SaveFlatMap(const std::string& json_path, const FlatMap& map, const nlohmann::json& report) {
  const std::string exr = WriteMapBeside(json_path, map.gain, {"R", "G", "B"});
  nlohmann::json j = Header("flat", map.gain.width, map.gain.height);
  j["map"] = exr;
  j["report"] = report;
  WriteJsonAtomically(json_path, j);
  RemoveOtherMaps(json_path, exr);
}

RadiometricScale LoadRadiometricScale(const std::string& json_path) {
  const JsonDocument doc = JsonDocument::Load(json_path);
  doc.CheckSchemaVersion(kScaleSchemaVersion);
  RadiometricScale scale;
  scale.file = json_path;
  scale.scale = doc.root()["scale"].NumberIn(1e-12, 1e12);
  scale.units = doc.root()["units"].OneOf({"W/m^2", "lux"});
  if (doc.root().Has("channel_weights")) {
    const JsonView weights = doc.root()["channel_weights"];
    const std::vector<double> w = weights["rgb"].Numbers(3);
    scale.channel_weights = {w[0], w[1], w[2]};
    if (!(std::abs(scale.channel_weights.sum() - 1) < 1e-6 && scale.channel_weights.maxCoeff() > 0))
      weights["rgb"].Fail("3 weights summing to 1, one of them > 0");
    scale.from_colour = weights["from"].OneOf({"rec709", "colour"}) == "colour";
  }
  return scale;
}

void SaveRadiometricScale(const std::string& json_path, const RadiometricScale& scale,
                          const nlohmann::json& report) {
  nlohmann::json j = Header("scale", 0, 0);
  if (scale.from_colour) j["schema_version"] = kScaleSchemaVersion;
  j["scale"] = scale.scale;
  j["units"] = scale.units;
  const Eigen::Vector3d& w = scale.channel_weights;
  j["channel_weights"] = {{"rgb", {w.x(), w.y(), w.z()}},
                          {"from", scale.from_colour ? "colour" : "rec709"}};
  j["meaning"] = "irradiance (units) per unit of corrected linear pixel value at exposure 1";
  j["report"] = report;
  WriteJsonAtomically(json_path, j);
}

PhotoCorrections LoadPhotoCorrections(const std::string& calib_dir, CorrectionSet which) {
  PhotoCorrections c;
  const std::string dark = calib_dir + "/dark.json", response = calib_dir + "/response.json",
                    flat = calib_dir + "/flat.json";
  if (which.dark && fs::exists(dark)) c.dark = std::make_shared<DarkMap>(LoadDarkMap(dark));
  if (which.response && fs::exists(response))
    c.response = std::make_shared<ResponseCurve>(LoadResponseCurve(response));
  if (which.flat && fs::exists(flat)) c.flat = std::make_shared<FlatMap>(LoadFlatMap(flat));
  return c;
}

}  // namespace lumislab
