// The radiometric corrections the one decoder applies (docs/method.md §3.5, docs/formats.md §13 -
// §15): the dark level subtracted before the exposure division, hot pixels read as their
// neighbours' mean, the flat gain divided out, the calibrated response curve for 8-bit photos; and
// the calibration files' round trips and checks.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "core/json.h"
#include "lib/photo/photo_io.h"
#include "lib/photo/photo_write.h"
#include "lib/photo/radiometric_calibration.h"
#include "photo_test_util.h"

namespace lumislab {
namespace {

using testing::ScratchDir;
using testing::ThrowsBadInputNaming;

constexpr int kW = 8, kH = 6;

float Value(int x, int y, int c) { return 0.1f + 0.05f * x + 0.02f * y + 0.01f * c; }

std::shared_ptr<PhotoCorrections> Corrections() {
  auto dark = std::make_shared<DarkMap>();
  dark->file = "calib/dark.json";
  dark->offset = ImageF(kW, kH, 3, 0.01f);
  dark->current = ImageF(kW, kH, 3, 0.005f);
  dark->hot.assign(kW * kH, 0);
  dark->hot[2 * kW + 3] = 1;  // pixel (3, 2)
  dark->hot_count = 1;
  auto flat = std::make_shared<FlatMap>();
  flat->file = "calib/flat.json";
  flat->gain = ImageF(kW, kH, 3, 1.f);
  for (int x = 0; x < kW; ++x)
    for (int c = 0; c < 3; ++c) flat->gain.at(x, 1, c) = 0.8f;  // row 1
  auto c = std::make_shared<PhotoCorrections>();
  c->dark = dark;
  c->flat = flat;
  return c;
}

TEST(Corrections, DarkThenExposureThenFlatAndHotPixelsReadAsTheirNeighbours) {
  const std::string dir = ScratchDir();
  ImageF image(kW, kH, 3);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = Value(x, y, c);
  WritePhoto(dir + "/p.exr", image, PhotoEncoding::kFloatExr);
  PhotoSpec spec;
  spec.black_level = 0.02;
  spec.white_level = 1.02;
  spec.exposure = 2;
  spec.corrections = Corrections();
  const Photo photo = DecodePhoto(dir + "/p.exr", spec);
  EXPECT_TRUE(photo.PixelCorrections());
  const LinearReader reader(photo);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      float v[3];
      bool clipped[3];
      reader.Read(y, x, v, clipped);
      for (int c = 0; c < 3; ++c) {
        auto expected = [c](int xx, int yy) {
          return ((Value(xx, yy, c) - 0.02) - 0.01 - 0.005 * 2) / 2 / (yy == 1 ? 0.8 : 1.0);
        };
        // The hot pixel (3, 2) reads as the mean of its 8 neighbours' corrected values.
        double want = 0;
        if (x == 3 && y == 2) {
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
              if (dx || dy) want += expected(x + dx, y + dy) / 8;
        } else {
          want = expected(x, y);
        }
        EXPECT_NEAR(v[c], want, 1e-6) << x << "," << y;
        EXPECT_FALSE(clipped[c]) << x << "," << y;
      }
    }
  // A hot pixel whose neighbours are all hot has nothing to read: clipped. One beside a clipped
  // neighbour is clipped in that channel.
  {
    auto all_hot = Corrections();
    auto dark = std::make_shared<DarkMap>(*all_hot->dark);
    dark->hot.assign(kW * kH, 1);
    all_hot->dark = dark;
    PhotoSpec hot_spec = spec;
    hot_spec.corrections = all_hot;
    const Photo hot_photo = DecodePhoto(dir + "/p.exr", hot_spec);
    float v[3];
    bool clipped[3];
    LinearReader(hot_photo).Read(2, 3, v, clipped);
    EXPECT_TRUE(clipped[0] && clipped[1] && clipped[2]);
    PhotoSpec low_saturation = spec;
    low_saturation.saturation_level = Value(4, 3, 0) - 1e-4;  // (4, 3) and beyond clip
    const Photo clipping = DecodePhoto(dir + "/p.exr", low_saturation);
    LinearReader(clipping).Read(2, 3, v, clipped);
    EXPECT_TRUE(clipped[0]);
  }
  // Maps of another size than the photo: exit 2 naming the photo and the map.
  auto other = Corrections();
  auto small_flat = std::make_shared<FlatMap>();
  small_flat->file = "calib/flat.json";
  small_flat->gain = ImageF(4, 4, 3, 1.f);
  other->flat = small_flat;
  spec.corrections = other;
  std::string message;
  EXPECT_TRUE(
      ThrowsBadInputNaming([&] { DecodePhoto(dir + "/p.exr", spec); }, dir + "/p.exr", &message));
  EXPECT_NE(message.find("calib/flat.json"), std::string::npos) << message;
}

TEST(Corrections, ResponseCurveLinearisesEightBitPhotosOnly) {
  const std::string dir = ScratchDir();
  ImageF image(kW, kH, 3, 0.5f);
  WritePhoto(dir + "/p8.png", image, PhotoEncoding::kSrgb8Png);
  WritePhoto(dir + "/p16.png", image, PhotoEncoding::kLinear16Png);
  auto response = std::make_shared<ResponseCurve>();
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 256; ++k) response->linear_of_code[c][k] = (k + 1) / 256.f * (c + 1) / 3;
  auto corrections = std::make_shared<PhotoCorrections>();
  corrections->response = response;
  PhotoSpec spec;
  spec.corrections = corrections;
  const Photo p8 = DecodePhoto(dir + "/p8.png", spec);
  EXPECT_EQ(p8.transfer, Transfer::kResponse);
  EXPECT_FALSE(p8.PixelCorrections());
  const int code = p8.pixels.at<cv::Vec3b>(0, 0)[1];  // sRGB of 0.5: 188
  float v[3];
  bool clipped[3];
  LinearReader(p8).Read(0, 0, v, clipped);
  for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(v[c], (code + 1) / 256.f * (c + 1) / 3);
  const Photo p16 = DecodePhoto(dir + "/p16.png", spec);
  EXPECT_EQ(p16.transfer, Transfer::kLinear);
}

TEST(Corrections, CalibrationFilesRoundTripAndAreChecked) {
  const std::string dir = ScratchDir();
  const auto c = Corrections();
  SaveDarkMap(dir + "/dark.json", *c->dark, {{"hot_pixels", 1}});
  const DarkMap dark = LoadDarkMap(dir + "/dark.json");
  EXPECT_EQ(dark.hot_count, 1);
  EXPECT_EQ(dark.offset.data, c->dark->offset.data);
  EXPECT_EQ(dark.current.data, c->dark->current.data);
  SaveFlatMap(dir + "/flat.json", *c->flat, {});
  EXPECT_EQ(LoadFlatMap(dir + "/flat.json").gain.data, c->flat->gain.data);
  // The JSON and its map are one result: the map is written first under a name of its content,
  // the JSON's rename commits the pair, and only then are the stem's other maps removed. A
  // rewrite that stops before the JSON (here: a stray map of another content, as an interrupted
  // --force leaves) keeps the previous pair readable; the next rewrite removes the stray map
  // and the previous one.
  const std::string first = JsonDocument::Load(dir + "/flat.json").root()["map"].String();
  EXPECT_EQ(first.rfind("flat-", 0), 0u) << first;
  WriteTextAtomically(dir + "/flat-0123456789abcdef.exr", "interrupted");
  WriteTextAtomically(dir + "/flat.exr", "an older lumislab's map");
  EXPECT_EQ(LoadFlatMap(dir + "/flat.json").gain.data, c->flat->gain.data);
  FlatMap other = *c->flat;
  other.gain.data[0] *= 1.5f;
  SaveFlatMap(dir + "/flat.json", other, {});
  const std::string second = JsonDocument::Load(dir + "/flat.json").root()["map"].String();
  EXPECT_NE(second, first);
  EXPECT_EQ(LoadFlatMap(dir + "/flat.json").gain.data, other.gain.data);
  std::vector<std::string> maps;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".exr" && e.path().filename().string().rfind("flat", 0) == 0)
      maps.push_back(e.path().filename().string());
  EXPECT_EQ(maps, std::vector<std::string>{second});
  EXPECT_TRUE(std::filesystem::exists(
      dir + "/" + JsonDocument::Load(dir + "/dark.json").root()["map"].String()));
  ResponseCurve curve;
  for (int ch = 0; ch < 3; ++ch)
    for (int k = 0; k < 256; ++k) curve.linear_of_code[ch][k] = (k + 1) / 256.f;
  SaveResponseCurve(dir + "/response.json", curve, {});
  EXPECT_EQ(LoadResponseCurve(dir + "/response.json").linear_of_code, curve.linear_of_code);
  // A curve that is not increasing, a scale of 0: exit 2 naming the file and the field.
  nlohmann::json j = JsonDocument::Load(dir + "/response.json").raw();
  j["linear_of_code"]["G"][100] = 0.1;
  WriteJsonAtomically(dir + "/response.json", j);
  std::string message;
  EXPECT_TRUE(ThrowsBadInputNaming([&] { LoadResponseCurve(dir + "/response.json"); },
                                   dir + "/response.json", &message));
  EXPECT_NE(message.find("linear_of_code.G[100]"), std::string::npos) << message;
  // fuzz_radiometric_calibration: values increasing as doubles but equal as the floats the
  // decoder keeps (code 254 at 1 - 1e-11 is 1.0f, as code 255) were accepted, and the saved
  // curve was then refused.
  j["linear_of_code"]["G"][100] = j["linear_of_code"]["G"][99].get<double>() + 0.5 / 256;
  j["linear_of_code"]["R"][254] = 0.99999999999;
  WriteJsonAtomically(dir + "/response.json", j);
  EXPECT_TRUE(ThrowsBadInputNaming([&] { LoadResponseCurve(dir + "/response.json"); },
                                   dir + "/response.json", &message));
  EXPECT_NE(message.find("linear_of_code.R[255]"), std::string::npos) << message;
  SaveRadiometricScale(dir + "/scale.json", {"", 2.5, "lux"}, {});
  EXPECT_EQ(LoadRadiometricScale(dir + "/scale.json").units, "lux");
  j = JsonDocument::Load(dir + "/scale.json").raw();
  j["scale"] = 0;
  WriteJsonAtomically(dir + "/scale.json", j);
  EXPECT_TRUE(ThrowsBadInputNaming([&] { LoadRadiometricScale(dir + "/scale.json"); },
                                   dir + "/scale.json", &message));
  EXPECT_NE(message.find("scale"), std::string::npos) << message;
}

}  // namespace
}  // namespace lumislab
