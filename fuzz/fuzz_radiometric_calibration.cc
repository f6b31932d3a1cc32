// The radiometric calibration files and the import manifest, one target for six readers (each
// target costs CI a build and 15 s). The first byte picks the reader (its value modulo 6, so
// the seeds start with '0' ... '5'); the rest is the file:
//   '0'  calib/dark.json      lib/photo LoadDarkMap      <tmp>/in/dark.json
//   '1'  calib/response.json  lib/photo LoadResponseCurve <tmp>/in/response.json
//   '2'  calib/flat.json      lib/photo LoadFlatMap      <tmp>/in/flat.json
//   '3'  calib/scale.json     lib/photo LoadRadiometricScale <tmp>/in/scale.json
//   '4'  captures.csv         acquire/capture_list.h ManifestPhotos (import's --manifest)
//   '5'  reference.json       calibrate/scale_calibrator.h LoadScaleReference + Check against a
//                             3 x 2 grid on an 800 x 600 mm screen (calibrate scale --reference)
// The JSON readers of dark and flat also read the EXR map the JSON names: <tmp>/in/dark.exr and
// flat.exr are small valid maps (4 x 3, written once), so the fuzzer explores the JSON. An
// accepted dark map, response curve or flat field is applied the way the decoder does to a 4 x 3
// photo (every pixel through LinearReader, values finite), and every accepted calibration file
// must survive Save + Load.
#include <cmath>
#include <memory>

#include "acquire/capture_list.h"
#include "calibrate/scale_calibrator.h"
#include "core/exr_io.h"
#include "fuzz/fuzz_util.h"
#include "lib/photo/photo_io.h"
#include "lib/photo/photo_write.h"
#include "lib/photo/radiometric_calibration.h"

using namespace lumislab;

namespace {

constexpr int kW = 4, kH = 3;  // the maps' and the photos' size

ImageF Ramp(int channels, float base) {
  ImageF im(kW, kH, channels);
  for (size_t k = 0; k < im.data.size(); ++k) im.data[k] = base + 0.01f * float(k % 7);
  return im;
}

// The fixed files beside the fuzzed JSON: the maps it may name and the photos the corrections
// are applied to (16-bit linear PNG, and 8-bit for the response curve).
struct Fixture {
  std::string in, out, photo16, photo8;
  Fixture() : in(fuzz::SubDir("in")), out(fuzz::SubDir("out")) {
    ImageF dark = Ramp(7, 0.f);  // R G B hot current.R current.G current.B
    dark.data[3] = 1.f;          // pixel 0 is hot
    WriteExr(in + "/dark.exr", dark, {"R", "G", "B", "hot", "current.R", "current.G", "current.B"});
    WriteExr(in + "/flat.exr", Ramp(3, 0.9f), {"R", "G", "B"});
    photo16 = in + "/photo16.png";
    photo8 = in + "/photo8.png";
    WritePhoto(photo16, Ramp(3, 0.3f), PhotoEncoding::kLinear16Png);
    WritePhoto(photo8, Ramp(3, 0.3f), PhotoEncoding::kSrgb8Png);
  }
};

// Decodes `photo` with the corrections and reads every pixel: the values must be finite.
void Apply(const std::string& photo, std::shared_ptr<PhotoCorrections> corrections,
           double exposure) {
  PhotoSpec spec;
  spec.exposure = exposure;
  spec.corrections = std::move(corrections);
  const Photo p = DecodePhoto(photo, spec);
  const LinearReader reader(p);
  for (int y = 0; y < p.pixels.rows; ++y)
    for (int x = 0; x < p.pixels.cols; ++x) {
      float v[3];
      bool clipped[3];
      reader.Read(y, x, v, clipped);
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(v[c]))
          fuzz::Finding("a corrected pixel value is not finite: " + photo + " (" +
                        std::to_string(x) + ", " + std::to_string(y) + ")");
    }
}

// Save + Load of what a reader accepted must give it back.
template <typename T, typename Save, typename Load>
T RoundTrip(const T& value, const std::string& path, Save save, Load load, const char* what) {
  save(path, value, nlohmann::json::object());
  try {
    return load(path);
  } catch (const Error& e) {
    fuzz::Finding(std::string(what) + ": Load refuses what Save wrote: " + e.what());
  }
}

void Dark(const Fixture& f) {
  const DarkMap map = LoadDarkMap(f.in + "/dark.json");
  auto c = std::make_shared<PhotoCorrections>();
  c->dark = std::make_shared<DarkMap>(map);
  Apply(f.photo16, c, 2.0);
  const DarkMap back = RoundTrip(map, f.out + "/dark.json", SaveDarkMap, LoadDarkMap, "dark.json");
  if (back.hot_count != map.hot_count || back.offset.data != map.offset.data ||
      back.current.data != map.current.data)
    fuzz::Finding("dark.json: Save + Load changed the map");
}

void Response(const Fixture& f) {
  const ResponseCurve curve = LoadResponseCurve(f.in + "/response.json");
  auto c = std::make_shared<PhotoCorrections>();
  c->response = std::make_shared<ResponseCurve>(curve);
  Apply(f.photo8, c, 1.0);
  const ResponseCurve back = RoundTrip(curve, f.out + "/response.json", SaveResponseCurve,
                                       LoadResponseCurve, "response.json");
  if (back.linear_of_code != curve.linear_of_code)
    fuzz::Finding("response.json: Save + Load changed the curve");
}

void Flat(const Fixture& f) {
  const FlatMap map = LoadFlatMap(f.in + "/flat.json");
  auto c = std::make_shared<PhotoCorrections>();
  c->flat = std::make_shared<FlatMap>(map);
  Apply(f.photo16, c, 0.5);
  const FlatMap back = RoundTrip(map, f.out + "/flat.json", SaveFlatMap, LoadFlatMap, "flat.json");
  if (back.gain.data != map.gain.data) fuzz::Finding("flat.json: Save + Load changed the map");
}

void Scale(const Fixture& f) {
  const RadiometricScale s = LoadRadiometricScale(f.in + "/scale.json");
  const RadiometricScale back =
      RoundTrip(s, f.out + "/scale.json", SaveRadiometricScale, LoadRadiometricScale, "scale.json");
  if (back.scale != s.scale || back.units != s.units)
    fuzz::Finding("scale.json: Save + Load changed the scale");
}

void Manifest(const Fixture& f) {
  for (const NamedPhoto& n : ManifestPhotos(f.in + "/captures.csv"))
    if (n.i < 0 || n.j < 0 || n.file.empty() ||
        (n.exposure && !(std::isfinite(*n.exposure) && *n.exposure > 0)))
      fuzz::Finding("captures.csv: accepted a row without a position, file or valid exposure (" +
                    n.where + ")");
}

void Reference(const Fixture& f) {
  static const Dataset dataset = [] {
    Dataset d;
    d.grid.nu = 3;
    d.grid.nv = 2;
    d.grid.spacing_mm = 5;
    d.screen_w_mm = 800;
    d.screen_h_mm = 600;
    return d;
  }();
  const ScaleReference r = LoadScaleReference(f.in + "/reference.json");
  r.Check(dataset);
  if (!(std::isfinite(r.reading_p) && std::isfinite(r.reading_n) && r.reading_p > r.reading_n &&
        r.point_mm.allFinite()))
    fuzz::Finding("reference.json: Check accepted a reading or point that is not finite");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const Fixture fixture;
  if (size == 0) return 0;
  static const char* kFiles[6] = {"dark.json",  "response.json", "flat.json",
                                  "scale.json", "captures.csv",  "reference.json"};
  const int kind = data[0] % 6;
  fuzz::WriteFile(fixture.in + "/" + kFiles[kind], data + 1, size - 1);
  FUZZ_BEGIN
  switch (kind) {
    case 0:
      Dark(fixture);
      break;
    case 1:
      Response(fixture);
      break;
    case 2:
      Flat(fixture);
      break;
    case 3:
      Scale(fixture);
      break;
    case 4:
      Manifest(fixture);
      break;
    default:
      Reference(fixture);
      break;
  }
  FUZZ_END
}
