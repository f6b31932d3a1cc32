// Writes the seed corpus of every fuzz target (fuzz/corpus/<target>/) with lumislab's own
// writers: small valid files of each kind. The committed corpus was made with
//   build-fuzz/fuzz/lumislab_fuzz_make_corpus fuzz/corpus
// (the mesh seeds are hand-written: fuzz/corpus/fuzz_mesh_*, and so are the manifests and scale
// references of fuzz_radiometric_calibration, which no lumislab writer makes (a lab writes them;
// the reference is truth/reference.json's form); fuzz_camera_calibration's seed is
// lumislab-calibrate camera's output on tests/data/chessboard-opencv-left, photo folder
// stripped). Rerun it when a file format changes.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "core/atomic_file.h"
#include "core/dataset.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "core/screen_calibration.h"
#include "core/slab.h"
#include "lib/photo/photo_io.h"
#include "lib/photo/radiometric_calibration.h"
#include "lib/synthetic/scene.h"

namespace fs = std::filesystem;
using namespace lumislab;

namespace {

std::string root;

std::string Dir(const std::string& target) {
  const std::string d = root + "/" + target;
  fs::create_directories(d);
  return d;
}

void Put(const std::string& target, const std::string& name, const std::string& text) {
  WriteTextAtomically(Dir(target) + "/" + name, text);
}

// The writers take a folder and a fixed file name: write in a scratch folder, move into place.
void Take(const std::string& from, const std::string& target, const std::string& name) {
  fs::rename(from, Dir(target) + "/" + name);
}

const char* kSmallScene = R"({
  "schema_version": 1,
  "setup": { "distance_mm": 400, "grid": {"nu": 3, "nv": 2, "spacing_mm": 4},
             "screen_mm": [800, 600] },
  "filter": { "k_max": 2 },
  "luminaire": { "emitters": [
    {"position_mm": [0.5, -1, -15], "intensity_w_sr": [2.0, 1.5, 1.0], "lobe_exponent": 4} ] },
  "camera": { "size_px": [640, 480], "focal_px": 600, "position_mm": [50, -200, 1500],
              "look_at_mm": [0, 0, 400], "exposure": 0.5, "radiometric_scale_w_m2": 12.5 },
  "calibration": { "squares": [9, 7], "square_mm": 60 },
  "effects": [ {"type": "sensor_noise", "full_well_e": 15000, "read_noise_e": 2.5, "seed": 7},
               {"type": "quantization", "bit_depth": 12} ]
}
)";

ImageF Gradient(int w, int h, int channels) {
  ImageF im(w, h, channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c)
        im.at(x, y, c) = float(0.05 + 0.9 * (x + 2 * y + 3 * c) / (w + 2 * h + 3 * channels));
  return im;
}

// Every camera effect of issue 8 in one scene, in the order a camera meets them.
const char* kCameraEffectsScene = R"({
  "schema_version": 1,
  "setup": { "distance_mm": 400, "grid": {"nu": 2, "nv": 2, "spacing_mm": 4},
             "screen_mm": [800, 600] },
  "luminaire": { "emitters": [
    {"position_mm": [0.5, -1, -15], "intensity_w_sr": [2.0, 1.5, 1.0], "lobe_exponent": 4} ] },
  "camera": { "size_px": [640, 480], "focal_px": 600, "position_mm": [50, -200, 1500],
              "look_at_mm": [0, 0, 400] },
  "calibration": { "squares": [9, 7], "square_mm": 60 },
  "effects": [ {"type": "stage_error", "max_mm": 0.3, "seed": 1},
               {"type": "screen_gain", "amplitude": 0.1, "blobs": 3, "size_mm": 200, "seed": 2},
               {"type": "ambient", "level": 0.02},
               {"type": "vignetting", "k1": -0.1, "k2": 0.02, "cos4": true},
               {"type": "dark", "black_level": 0.02, "dark_current": 0.01, "hot_fraction": 0.001,
                "hot_current": 0.5, "seed": 3},
               {"type": "sensor_noise", "seed": 4},
               {"type": "brackets", "stops": [-2, 0, 2]},
               {"type": "response", "curve": "gamma", "gamma": 2.2, "shoulder": 0.5,
                "quality": 90} ]
}
)";

void Scenes() {
  Put("fuzz_scene", "default.json", DefaultSceneJson());
  Put("fuzz_scene", "small_effects.json", kSmallScene);
  Put("fuzz_scene", "camera_effects.json", kCameraEffectsScene);
  Put("fuzz_scene", "minimal.json", R"({"schema_version": 1,
 "setup": {"distance_mm": 750, "grid": {"nu": 1, "nv": 1, "spacing_mm": 5}, "screen_mm": [1200, 1200]},
 "luminaire": {"emitters": [{"position_mm": [0, 0, -10], "intensity_w_sr": [1, 1, 1], "lobe_exponent": 0}]},
 "camera": {"size_px": [1600, 1200], "focal_px": 1300, "position_mm": [0, 0, 2400], "look_at_mm": [0, 0, 750]}}
)");
}

Dataset SmallDataset() {
  const SynthScene scene = ParseScene(kSmallScene, "small");
  Dataset ds = DatasetSkeleton(scene);
  ds.photos = PhotoList(scene);
  return ds;
}

void Datasets(const std::string& scratch) {
  Dataset ds = SmallDataset();
  ds.Save(scratch);
  Take(scratch + "/dataset.json", "fuzz_dataset", "small.json");
  // A real capture: radiometric scale, sRGB camera output with black and white level, and two
  // exposures per slide (an HDR bracket).
  ds.synthetic = false;
  ds.radiometric_scale = 3.5;
  ds.photo_transfer = "srgb";
  ds.black_level = 0.02;
  ds.white_level = 0.98;
  ds.saturation_level = 0.97;
  const auto photos = ds.photos;
  ds.photos.clear();
  for (PhotoEntry e : photos) {
    e.file = "photos/" + PhotoFileName(e.i, e.j, e.positive, "png", "e1");
    e.exposure = 1;
    ds.photos.push_back(e);
    e.file = "photos/" + PhotoFileName(e.i, e.j, e.positive, "png", "e4");
    e.exposure = 4;
    ds.photos.push_back(e);
  }
  ds.Save(scratch);
  Take(scratch + "/dataset.json", "fuzz_dataset", "bracketed_srgb.json");
  // One position, linear transfer.
  Dataset one = SmallDataset();
  one.grid.nu = one.grid.nv = 1;
  one.photos = {{0, 0, true, "photos/pos_0_0_p.exr", 1.0},
                {0, 0, false, "photos/pos_0_0_n.exr", 1.0}};
  one.photo_transfer = "linear";
  one.Save(scratch);
  Take(scratch + "/dataset.json", "fuzz_dataset", "one_position.json");
}

void Slabs(const std::string& scratch) {
  SlabInfo info = SlabInfo::FromDataset(SmallDataset(), 64);
  info.Save(scratch);
  Take(scratch + "/slab.json", "fuzz_slab_info", "empty.json");
  info.MarkPresent(0, 0);
  info.MarkPresent(2, 1);
  info.Save(scratch);
  Take(scratch + "/slab.json", "fuzz_slab_info", "partial.json");
  for (int j = 0; j < info.grid.nv; ++j)
    for (int i = 0; i < info.grid.nu; ++i) info.MarkPresent(i, j);
  info.units = "relative";
  info.Save(scratch);
  Take(scratch + "/slab.json", "fuzz_slab_info", "complete_relative.json");
}

void Calibrations(const std::string& scratch) {
  ScreenCalibration c;
  c.image_width = 1600;
  c.image_height = 1200;
  c.screen_from_image << 0.82, 0.03, -650.0, -0.01, 0.85, -510.0, 1e-6, 2e-5, 1.0;
  c.k1 = -0.021;
  c.k2 = 0.0034;
  c.centre_px = {799.5, 599.5};
  c.scale_px = 1000;
  c.rms_px = 0.08;
  c.rms_mm = 0.06;
  c.corners_used = 182;
  c.photo = "photos/calib_0.png";
  c.Save(scratch + "/screen.json");
  Take(scratch + "/screen.json", "fuzz_screen_calibration", "distorted.json");
  ScreenCalibration plain;
  plain.image_width = 640;
  plain.image_height = 480;
  plain.screen_from_image << 2, 0, -640, 0, 2, -480, 0, 0, 1;
  plain.centre_px = {319.5, 239.5};
  plain.scale_px = 400;
  plain.Save(scratch + "/screen.json");
  Take(scratch + "/screen.json", "fuzz_screen_calibration", "plain.json");
  // The screen's pose under a camera calibrated from many views (distortion model "opencv5").
  ScreenCalibration posed = plain;
  CameraModel camera;
  camera.image_width = 640;
  camera.image_height = 480;
  camera.fx = 650, camera.fy = 651, camera.cx = 328, camera.cy = 234;
  camera.k1 = -0.25, camera.k2 = 0.05, camera.p1 = 0.001, camera.p2 = -0.0008;
  posed.camera = camera;
  posed.camera_file = "calib/camera.json";
  posed.method = "camera+pose";
  posed.Save(scratch + "/screen.json");
  Take(scratch + "/screen.json", "fuzz_screen_calibration", "camera_pose.json");
}

void Photos() {
  const std::string d = Dir("fuzz_photo");
  const ImageF rgb = Gradient(8, 6, 3), gray = Gradient(8, 6, 1);
  WritePhoto(d + "/linear16.png", rgb, PhotoEncoding::kLinear16Png);
  WritePhoto(d + "/srgb8.png", rgb, PhotoEncoding::kSrgb8Png);
  WritePhoto(d + "/gray16.png", gray, PhotoEncoding::kLinear16Png);
  WritePhoto(d + "/half_rle.exr", rgb, PhotoEncoding::kHalfExr);
  WritePhoto(d + "/float.exr", rgb, PhotoEncoding::kFloatExr);
  WritePhoto(d + "/float_piz.exr", rgb, PhotoEncoding::kFloatExrPiz);
  cv::Mat bgra(6, 8, CV_8UC4), g8(6, 8, CV_8UC1);
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 8; ++x) {
      bgra.at<cv::Vec4b>(y, x) = cv::Vec4b(uchar(30 * x), uchar(40 * y), uchar(x * y), 255);
      g8.at<uchar>(y, x) = uchar(20 * x + 10 * y);
    }
  WriteImageFile(d + "/bgra8.png", bgra);
  WriteImageFile(d + "/gray8.jpg", g8);
  WriteImageFile(d + "/bgra8.tif", bgra);
}

void SlabPositions(const std::string& scratch) {
  SlabInfo info;
  info.distance_mm = 500;
  info.grid = {1, 1, 5.0};
  info.layout = {100.0, 75.0, 8, 6};
  SlabPosition p;
  p.irradiance = Gradient(8, 6, 3);
  p.mask = ImageF(8, 6, 1, 1.f);
  p.mask.at(0, 0, 0) = 0;
  p.irradiance.at(0, 0, 0) = p.irradiance.at(0, 0, 1) = p.irradiance.at(0, 0, 2) = 0;
  WriteSlabPosition(scratch, info, p);
  Take(SlabPositionPath(scratch, 0, 0), "fuzz_slab_position", "written.exr");
  // Without lumislab attributes, in the other compressions and as half.
  ImageF rgbm(8, 6, 4);
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 8; ++x) {
      for (int c = 0; c < 3; ++c) rgbm.at(x, y, c) = p.irradiance.at(x, y, c);
      rgbm.at(x, y, 3) = p.mask.at(x, y, 0);
    }
  const std::string d = Dir("fuzz_slab_position");
  ExrOptions rle{true, ExrCompression::kRle}, piz{false, ExrCompression::kPiz};
  WriteExr(d + "/half_rle.exr", rgbm, {"R", "G", "B", "mask"}, {}, rle);
  WriteExr(d + "/float_piz.exr", rgbm, {"R", "G", "B", "mask"}, {}, piz);
}

// fuzz_radiometric_calibration: the first byte picks the reader ('0' dark.json, '1'
// response.json, '2' flat.json, '3' scale.json, '4' captures.csv, '5' reference.json), the rest
// is the file. The maps are 4 x 3, the size of the target's fixed dark.exr and flat.exr.
void RadiometricCalibrations(const std::string& scratch) {
  const std::string t = "fuzz_radiometric_calibration";
  // The dark and flat JSON name their map by its content (dark-<hash>.exr); the target provides
  // dark.exr and flat.exr beside the JSON, so the seeds name those.
  auto take = [&](char kind, const std::string& written, const std::string& name) {
    nlohmann::json j = nlohmann::json::parse(ReadTextFile(written));
    if (j.contains("map")) j["map"] = j["kind"].get<std::string>() + ".exr";
    Put(t, name, std::string(1, kind) + j.dump(2) + "\n");
  };
  const nlohmann::json report = {{"frames", nlohmann::json::array()}};
  DarkMap dark;
  dark.offset = Gradient(4, 3, 3);
  dark.hot.assign(12, 0);
  dark.hot[5] = 1;
  dark.hot_count = 1;
  SaveDarkMap(scratch + "/dark.json", dark, report);
  take('0', scratch + "/dark.json", "dark_constant.json");
  dark.current = Gradient(4, 3, 3);
  SaveDarkMap(scratch + "/dark.json", dark, report);
  take('0', scratch + "/dark.json", "dark_offset_current.json");
  ResponseCurve curve;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 256; ++k)
      curve.linear_of_code[c][k] =
          float(std::pow(k / 255.0, 2.2 + 0.1 * c) + 1e-4 * k) / float(1 + 1e-4 * 255);
  for (auto& channel : curve.linear_of_code) channel[255] = 1;
  SaveResponseCurve(scratch + "/response.json", curve, report);
  take('1', scratch + "/response.json", "response_gamma.json");
  FlatMap flat;
  flat.gain = Gradient(4, 3, 3);
  for (float& g : flat.gain.data) g += 0.5f;
  SaveFlatMap(scratch + "/flat.json", flat, report);
  take('2', scratch + "/flat.json", "flat.json");
  SaveRadiometricScale(scratch + "/scale.json", {"", 12.5, "W/m^2"}, report);
  take('3', scratch + "/scale.json", "scale_w_m2.json");
  SaveRadiometricScale(scratch + "/scale.json", {"", 3.4e4, "lux"}, report);
  take('3', scratch + "/scale.json", "scale_lux.json");
  Put(t, "captures.csv",
      "4i,j,slide,file,exposure\n0,0,p,IMG_0001.JPG,0.25\n0,0,p,IMG_0002.JPG,1\n"
      "0,0,n,IMG_0003.JPG,0.25\n0,0,n,IMG_0004.JPG,1\n# a comment\n1,0,+,IMG_0005.JPG,\n"
      "1,0,minus,IMG_0006.JPG\n");
  Put(t, "captures_no_header.csv", "40,0,pos,a.dng,1e-2\n0,0,neg,b.dng,1e-2\n");
  Put(t, "reference.json",
      "5{\"schema_version\": 1, \"position\": [1, 0], \"point_mm\": [12.5, -30], "
      "\"unit\": \"W/m2\", \"reading_p\": 0.42, \"reading_n\": 0.11}\n");
  Put(t, "reference_lux.json",
      "5{\"position\": [2, 1], \"point_mm\": [-399, 299], \"unit\": \"lux\", "
      "\"reading_p\": 1200, \"reading_n\": 0}\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <corpus folder>\n", argv[0]);
    return 2;
  }
  return RunMain("fuzz-make-corpus", [&] {
    root = argv[1];
    const std::string scratch = root + "/.scratch";
    fs::create_directories(scratch);
    Scenes();
    Datasets(scratch);
    Slabs(scratch);
    Calibrations(scratch);
    Photos();
    SlabPositions(scratch);
    RadiometricCalibrations(scratch);
    fs::remove_all(scratch);
    return 0;
  });
}
