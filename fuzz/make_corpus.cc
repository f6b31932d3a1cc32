// Writes the seed corpus of every fuzz target (fuzz/corpus/<target>/) with lumislab's own
// writers: small valid files of each kind. The committed corpus was made with
//   build-fuzz/fuzz/lumislab_fuzz_make_corpus fuzz/corpus
// (the mesh seeds are hand-written: fuzz/corpus/fuzz_mesh_*, and so are the manifests and scale
// references of fuzz_radiometric_calibration, which no lumislab writer makes (a lab writes them;
// the reference is truth/reference.json's form); fuzz_camera_calibration's seed is
// lumislab-calibrate camera's output on tests/data/chessboard-opencv-left, photo folder
// stripped). Rerun it when a file format changes.
#include <tiffio.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/dataset.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "core/screen_calibration.h"
#include "core/slab.h"
#include "lib/photo/photo_write.h"
#include "lib/photo/radiometric_calibration.h"
#include "lib/photometry/eulumdat.h"
#include "lib/photometry/ies.h"
#include "lib/photometry/tm25.h"
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

// A 16-bit RGB TIFF in a layout lumislab's writer does not make (libtiff directly): tiled or
// strips of 2 rows, planar (one plane per sample) or contiguous, compressed: the decoder's other
// read paths (lib/photo/image_codecs.cc).
void LayoutTiff(const std::string& path, bool tiled, bool planar, uint16_t compression) {
  TIFF* tif = TIFFOpen(path.c_str(), "wb");  // big-endian: the samples are swapped on reading
  if (!tif) throw IoError(path, "cannot create the file");
  const uint32_t w = 20, h = 6, tile = 16;
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, w);
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, h);
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, 16);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 3);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_RGB);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, planar ? PLANARCONFIG_SEPARATE : PLANARCONFIG_CONTIG);
  TIFFSetField(tif, TIFFTAG_COMPRESSION, compression);
  const int stride = planar ? 1 : 3;
  auto value = [](uint32_t x, uint32_t y, int s) {
    return uint16_t(x * 3000 + y * 700 + s * 9000);
  };
  if (tiled) {
    TIFFSetField(tif, TIFFTAG_TILEWIDTH, tile);
    TIFFSetField(tif, TIFFTAG_TILELENGTH, tile);
    std::vector<uint16_t> buf(size_t(tile) * tile * stride, 0);
    for (int p = 0; p < (planar ? 3 : 1); ++p)
      for (uint32_t tx = 0; tx < w; tx += tile) {
        for (uint32_t y = 0; y < tile; ++y)
          for (uint32_t x = 0; x < tile; ++x)
            for (int s = 0; s < stride; ++s)
              buf[(size_t(y) * tile + x) * stride + s] = value(tx + x, y, planar ? p : s);
        TIFFWriteEncodedTile(tif, TIFFComputeTile(tif, tx, 0, 0, uint16_t(p)), buf.data(),
                             tmsize_t(buf.size() * 2));
      }
  } else {
    TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, 2);
    std::vector<uint16_t> row(size_t(w) * stride);
    for (int p = 0; p < (planar ? 3 : 1); ++p)
      for (uint32_t y = 0; y < h; ++y) {
        for (uint32_t x = 0; x < w; ++x)
          for (int s = 0; s < stride; ++s)
            row[size_t(x) * stride + s] = value(x, y, planar ? p : s);
        TIFFWriteScanline(tif, row.data(), y, uint16_t(p));
      }
  }
  TIFFClose(tif);
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
  WritePhoto(d + "/curve8.jpg", rgb, PhotoEncoding::kCurve8Jpeg, 90);
  LayoutTiff(d + "/tiled_planar_deflate16.tif", true, true, COMPRESSION_ADOBE_DEFLATE);
  LayoutTiff(d + "/strips_lzw16.tif", false, false, COMPRESSION_LZW);
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

// --- the lighting industry's files (lib/photometry): small grids, a few rays

// A lobe of 100 cd * cos(gamma)^2 (0 beyond 90 degrees), brighter towards C 0, on the grid.
IntensityDistribution SmallDistribution(std::vector<double> c, std::vector<double> gamma) {
  IntensityDistribution d;
  d.c_deg = std::move(c);
  d.gamma_deg = std::move(gamma);
  for (double ci : d.c_deg)
    for (double g : d.gamma_deg) {
      const double cg = std::cos(g * M_PI / 180);
      d.values.push_back(cg > 0 ? 100 * cg * cg * (1.2 + 0.2 * std::cos(ci * M_PI / 180)) : 0);
    }
  d.opening = {-60, -60, 0};
  d.input_watts = 8.5;
  d.keywords = {{"TEST", "fuzz seed"},
                {"TESTLAB", "lumislab"},
                {"ISSUEDATE", "2026-12-02"},
                {"MANUFAC", "lumislab"},
                {"LUMCAT", "L-1"},
                {"LUMINAIRE", "a small lobe"},
                {"MORE_TEXT", "line one\nline two"}};
  return d;
}

// A 1995 file with TILT=INCLUDE, a ballast-lamp factor and numbers split over lines (the reader
// takes every edition; the writer writes only 2019).
const char* kIes1995Tilt = R"(IESNA:LM-63-1995
[TEST] 1995 seed
[MANUFAC] lumislab
[MORE] continued
TILT=INCLUDE
1
3
0 45 90
1.0 0.9 0.7
2 1000 0.5 3 2 1 1 0.3 0.3 0.05
1.0 0.95 12
0 45 90
0 90
100 80 10
120,90,5
)";

// A 1986 file: free text lines before TILT=NONE, feet, one C plane.
const char* kIes1986 = R"(a luminaire of 1986
measured long ago
TILT=NONE
1 500 1 3 1 1 1 0 0 0
1 1 10
0 60 90
0
200 50 0
)";

// EULUMDAT with decimal commas, two lamp sets and several numbers on a line (Isym 1).
const char* kLdtCommas = R"(lumislab
1
1
1
0
3
45
seed
commas
L-2
commas.ldt
2026
100
0
50
80
0
0
0
0
0
100
85,5
1,0
0
2
1
LED
1200,5
3000K
80
15,5
1
LED
600
4000K
90
7
0,5 0,5 0,5 0,5 0,5 0,5 0,5 0,5 0,5 0,5
0
0 45 90
300,5 120 0
)";

void Photometry(const std::string& scratch) {
  // IES: the writer's form of each symmetry, a radiometric one, and the older editions
  // (the real files of tests/data/ies/ are copied into fuzz/corpus/fuzz_ies/ by hand).
  const std::vector<double> gamma = {0, 30, 60, 90, 135, 180};
  Put("fuzz_ies", "written_axial.ies", FormatIes(SmallDistribution({0}, gamma), {}, "seed"));
  Put("fuzz_ies", "written_quadrant.ies",
      FormatIes(SmallDistribution({0, 45, 90}, {0, 45, 90}), {}, "seed"));
  IntensityDistribution radiometric = SmallDistribution({0, 90, 180, 270, 360}, gamma);
  radiometric.photometric = false;
  Put("fuzz_ies", "written_radiometric.ies", FormatIes(radiometric, {}, "seed"));
  Put("fuzz_ies", "edition_1995_tilt_include.ies", kIes1995Tilt);
  Put("fuzz_ies", "edition_1986.ies", kIes1986);
  // EULUMDAT: Isym 1, 2, 3, 4 and 0, and a hand-written one.
  const std::vector<std::pair<std::string, std::vector<double>>> planes = {
      {"isym1_axial", {0}},
      {"isym2_c0_c180", {0, 90, 180}},
      {"isym3_c90_c270", {90, 180, 270}},
      {"isym4_quadrant", {0, 45, 90}},
      {"isym0_none", {0, 90, 180, 270}}};
  for (const auto& [name, c] : planes)
    Put("fuzz_eulumdat", name + ".ldt",
        FormatEulumdat(SmallDistribution(c, {0, 45, 90, 180}), name + ".ldt"));
  Put("fuzz_eulumdat", "commas_two_lamp_sets.ldt", kLdtCommas);
  // TM-25: three rays with luminous flux, two with radiant flux and unknown header totals, and
  // the latter with every optional part (spectral table, extra column, text block) patched in.
  Tm25RaySet set;
  set.luminous_flux_lm = 3;
  set.radiant_flux_w = std::nan("");
  set.date_time = "2026-12-02T06:00:00Z";
  set.name = "seed";
  set.manufacturer = "lumislab";
  set.rays = {
      {0, 0, 0, 0, 0, 1, 1}, {1.5f, -2, 0, 0.6f, 0, 0.8f, 1.5f}, {-3, 4, 0, 0, -0.6f, 0.8f, 0.5f}};
  WriteTm25(set, scratch + "/rays.ray");
  Take(scratch + "/rays.ray", "fuzz_tm25", "luminous_3_rays.ray");
  set.photometric = false;
  set.luminous_flux_lm = std::nan("");
  set.radiant_flux_w = 0.02;
  set.rays.resize(2);
  WriteTm25(set, scratch + "/rays.ray");
  const std::string radiant = ReadTextFile(scratch + "/rays.ray");
  Take(scratch + "/rays.ray", "fuzz_tm25", "radiant_2_rays.ray");
  // Offsets of the header fields (docs/formats.md §17): 76 spectral tables, 80 additional
  // items, 84 text block bytes, 256 the flags (radiant, wavelength, luminous, Stokes,
  // tristimulus, spectrum index from 264), 36288 the end of the fixed header.
  std::string all = radiant.substr(0, kTm25FixedHeaderBytes);
  auto put_int = [&](size_t at, int32_t v) { std::memcpy(&all[at], &v, 4); };
  auto append = [&](const void* p, size_t n) { all.append(static_cast<const char*>(p), n); };
  put_int(76, 1);                                                   // one spectral table
  put_int(80, 1);                                                   // one additional ray item
  put_int(84, 32);                                                  // a 32-byte text block
  for (size_t at : {264, 268, 272, 276, 280, 284}) put_int(at, 1);  // every optional column
  const int32_t pairs = 3;
  const float table[6] = {450, 0.2f, 550, 1, 650, 0.4f};
  append(&pairs, 4);
  append(table, sizeof table);
  all.append(32 - (4 + sizeof table) % 32, '\0');  // the tables padded to 32 bytes
  std::string column(512, '\0');
  column.replace(0, 5, "extra");
  all += column;
  all += std::string("a text block of 32 bytes........", 32);
  // position 3, direction 3, radiant, wavelength, luminous, Stokes 3, tristimulus 2, spectrum
  // index, the extra item: 16 values per ray.
  const float rays[2][16] = {{0, 0, 0, 0, 0, 1, 0.01f, 550, 6.8f, 1, 0, 0, 0.3f, 0.3f, 0, 7},
                             {1, 2, 0, 0, 0.6f, 0.8f, 0.01f, 600, 5.0f, 1, 0, 0, 0.4f, 0.3f, 0, 8}};
  append(rays, sizeof rays);
  Put("fuzz_tm25", "every_optional_part.ray", all);
  // info: one file of each format (the detection is what it adds).
  Put("fuzz_photometry_info", "edition_1986.ies", kIes1986);
  Put("fuzz_photometry_info", "isym4_quadrant.ldt",
      FormatEulumdat(SmallDistribution({0, 45, 90}, {0, 45, 90, 180}), "seed.ldt"));
  Put("fuzz_photometry_info", "radiant_2_rays.ray", radiant);
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
    Photometry(scratch);
    fs::remove_all(scratch);
    return 0;
  });
}
