#include "acquire/photo_store.h"

#include <cctype>
#include <cstdio>
#include <ctime>
#include <filesystem>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json.h"
#include "core/slab.h"
#include "lib/photo/camera_write.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

// The RGGB mosaic of a photo: row 0 R G R G ..., row 1 G B G B ...; each pixel the sensor code
// of its channel.
cv::Mat RggbMosaic(const ImageF& rgb, const RawEffect& raw) {
  cv::Mat mosaic(rgb.height, rgb.width, CV_16UC1);
  for (int y = 0; y < rgb.height; ++y)
    for (int x = 0; x < rgb.width; ++x) {
      const int c = (y % 2 == 0) ? (x % 2 == 0 ? 0 : 1) : (x % 2 == 0 ? 1 : 2);
      mosaic.at<uint16_t>(y, x) = uint16_t(raw.Code(rgb.at(x, y, c)));
    }
  return mosaic;
}

// "2026:01:01 00:00:00" plus `seconds`, as EXIF writes a time (UTC calendar).
std::string ExifTime(long long seconds) {
  constexpr std::time_t kStart = 1767225600;  // 2026-01-01 00:00:00 UTC
  const std::time_t t = kStart + std::time_t(seconds);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y:%m:%d %H:%M:%S", &tm);
  return text;
}

}  // namespace

PhotoExif SynthExif(double exposure, int photo_index) {
  PhotoExif exif;
  exif.make = "Lumislab";
  exif.model = "Synthetic camera";
  exif.lens_model = "Synthetic pinhole";
  exif.f_number = kSynthFNumber;
  exif.iso = kSynthIso;
  exif.exposure_time = exposure * kBaseExposureTimeS;
  exif.date_time = ExifTime(photo_index);
  return exif;
}

void StoreSlidePhoto(const SynthScene& scene, const PhotoStore& store, const std::string& path,
                     const ImageF& photo, double exposure, int photo_index) {
  if (const RawEffect* raw = scene.Raw()) {
    DngInfo info;
    info.black_level = raw->black_level();
    info.white_level = raw->white_level();
    info.exif = SynthExif(exposure, photo_index);
    WriteDng(path, RggbMosaic(photo, *raw), info);
  } else if (!store.camera_folder) {
    WritePhoto(path, photo, store.encoding, store.jpeg_quality);
  } else if (store.encoding == PhotoEncoding::kCurve8Jpeg) {
    WriteJpeg(path, PhotoCodes(photo, store.encoding), store.jpeg_quality,
              SynthExif(exposure, photo_index));
  } else {  // linear: 16-bit codes, as the quantization effect's PNG (exact for its levels)
    WriteTiff(path, PhotoCodes(photo, PhotoEncoding::kLinear16Png),
              SynthExif(exposure, photo_index));
  }
}

std::string StoreName(const SynthScene& scene, const PhotoStore& store) {
  if (scene.Raw()) return std::to_string(scene.Raw()->bit_depth()) + "-bit DNG mosaic";
  if (store.encoding == PhotoEncoding::kCurve8Jpeg) return "8-bit JPEG";
  if (store.camera_folder) return "16-bit TIFF";
  if (store.encoding == PhotoEncoding::kLinear16Png) return "16-bit PNG";
  return store.encoding == PhotoEncoding::kHalfExr ? "half-float EXR" : "float EXR";
}

std::string StoredExtension(const SynthScene& scene, const PhotoStore& store) {
  if (!store.camera_folder || scene.Raw()) return scene.PhotoExtension();
  return scene.Response() ? "jpg" : "tif";
}

std::vector<PhotoEntry> CameraFolderPhotoList(const SynthScene& scene) {
  PhotoStore camera;
  camera.camera_folder = true;
  std::string ext = StoredExtension(scene, camera);
  for (char& c : ext) c = char(std::toupper((unsigned char)c));
  std::vector<PhotoEntry> list = PhotoList(scene);
  for (size_t k = 0; k < list.size(); ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "IMG_%04zu.", k + 1);
    list[k].file = std::string(kCameraFolder) + "/" + name + ext;
  }
  return list;
}

void WriteSetupFile(const Dataset& dataset, const std::string& path) {
  nlohmann::json setup = dataset.ToJson();
  setup.erase("photos");
  setup.erase("synthetic");
  setup.erase("photo_folder");
  setup["schema_version"] = 2;
  setup["radiometry"] = nlohmann::json::object();
  setup["calibration"]["photo"] = kCameraBoardPhoto;
  WriteJsonAtomically(path, setup);
}

bool CameraFolderComplete(const SynthScene& scene, const std::string& dir) {
  if (!fs::exists(dir + "/setup.json")) return false;
  if (!fs::exists(dir + "/" + kCameraFolder + "/" + kCameraBoardPhoto)) return false;
  for (const PhotoEntry& e : CameraFolderPhotoList(scene))
    if (!fs::exists(dir + "/" + e.file)) return false;
  try {
    return fs::exists(dir + "/truth/camera.json") && SlabInfo::Load(dir + "/truth").Complete();
  } catch (const Error&) {
    return false;
  }
}

}  // namespace lumislab
