#include "calibrate/radiometric/scale_calibrator.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <vector>

#include "core/error.h"
#include "core/json.h"
#include "lib/photo/photo_io.h"

namespace lumislab {

std::string CanonicalUnit(const std::string& unit, const std::string& where) {
  if (unit == "W/m2" || unit == "W/m^2") return "W/m^2";
  if (unit == "lux") return "lux";
  throw InputError(where, "unit", "W/m2 (a radiometer) or lux (a lux meter)", unit);
}

void ScaleReference::Check(const Dataset& dataset) const {
  if (i < 0 || j < 0 || i >= dataset.grid.nu || j >= dataset.grid.nv)
    throw InputError(source, "position", "a grid position of dataset.json",
                     std::to_string(i) + "," + std::to_string(j));
  if (!(std::abs(point_mm.x()) <= 0.5 * dataset.screen_w_mm &&
        std::abs(point_mm.y()) <= 0.5 * dataset.screen_h_mm))
    throw InputError(source, "point_mm", "a lab point on the screen",
                     std::to_string(point_mm.x()) + "," + std::to_string(point_mm.y()));
  if (!(std::isfinite(reading_p) && reading_p > 0))
    throw InputError(source, "reading_p", "a finite reading > 0", std::to_string(reading_p));
  if (!(std::isfinite(reading_n) && reading_n >= 0))
    throw InputError(source, "reading_n", "a finite reading >= 0", std::to_string(reading_n));
  if (!(reading_p > reading_n))
    throw InputError(source, "reading_p",
                     "a reading above reading_n (a point where T+ passes more light than T-)",
                     std::to_string(reading_p) + " vs " + std::to_string(reading_n));
}

ScaleReference LoadScaleReference(const std::string& path) {
  const JsonDocument doc = JsonDocument::Load(path);
  const JsonView root = doc.root();
  ScaleReference r;
  r.source = path;
  const JsonView position = root["position"];
  r.i = position[0].Int();
  r.j = position[1].Int();
  if (position.Size() != 2) position.Fail("[i, j]");
  const std::vector<double> xy = root["point_mm"].Numbers(2);
  r.point_mm = {xy[0], xy[1]};
  r.reading_p = root["reading_p"].Number();
  r.reading_n = root["reading_n"].Number();
  r.unit = CanonicalUnit(root["unit"].String(), path);
  return r;
}

namespace {

struct SlideValue {
  double rgb[3] = {0, 0, 0};
  double exposure_sum = 0;
  int photos = 0;
};

// Adds the value of one photo (per unit exposure) at the exact (sub-pixel) position of the
// reference point: a quadratic surface a + b x + c y + d x^2 + e x y + f y^2 least-squares
// fitted to the pixels within r of it, per channel, evaluated there (a). The fit keeps the
// light's slope and curvature across the neighbourhood from biasing the value (a plain mean
// over a peak reads low) while averaging the pixels' noise and a JPEG's compression error.
// Nothing when a pixel in the neighbourhood is clipped. Returns the photo's value (RGB, per unit
// exposure), or nothing.
std::optional<Eigen::Vector3d> AddPhoto(const Photo& photo, const Eigen::Vector2d& at, int r,
                                        SlideValue* out) {
  const LinearReader reader(photo);
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 3> atb = Eigen::Matrix<double, 6, 3>::Zero();
  const int x0 = int(std::round(at.x())), y0 = int(std::round(at.y()));
  const int reach = r + 1;
  for (int y = y0 - reach; y <= y0 + reach; ++y)
    for (int x = x0 - reach; x <= x0 + reach; ++x) {
      const double dx = x - at.x(), dy = y - at.y();
      if (dx * dx + dy * dy > double(r) * r + 0.5) continue;
      float v[3];
      bool clipped[3];
      reader.Read(y, x, v, clipped);
      if (clipped[0] || clipped[1] || clipped[2]) return std::nullopt;
      Eigen::Matrix<double, 6, 1> row;
      row << 1, dx, dy, dx * dx, dx * dy, dy * dy;
      ata += row * row.transpose();
      for (int c = 0; c < 3; ++c) atb.col(c) += row * double(v[c]);
    }
  const Eigen::Matrix<double, 6, 3> coefficients = ata.ldlt().solve(atb);
  const double e = photo.spec.exposure;
  for (int c = 0; c < 3; ++c) out->rgb[c] += coefficients(0, c) * e;
  out->exposure_sum += e;
  ++out->photos;
  return Eigen::Vector3d(coefficients(0, 0), coefficients(0, 1), coefficients(0, 2));
}

// The brightest light in a photo (per unit exposure): the 99.9th percentile of its luminance, so
// that a few hot or glinting pixels do not count. Rec. 709's (LinearGray): a level against the
// sensor's full scale for the exposure checks, not a photometric quantity.
double PeakLuminance(const Photo& photo) {
  const cv::Mat gray = LinearGray(photo);
  std::vector<float> v(gray.begin<float>(), gray.end<float>());
  const size_t k = std::min(v.size() - 1, size_t(0.999 * double(v.size())));
  std::nth_element(v.begin(), v.begin() + long(k), v.end());
  return v[k];
}

}  // namespace

RadiometricScale CalibrateScale(const Dataset& dataset, const ScreenCalibration& screen,
                                const ScaleReference& reference,
                                const std::shared_ptr<const PhotoCorrections>& corrections,
                                const ScaleOptions& options, nlohmann::json* report,
                                CheckLog* checks) {
  reference.Check(dataset);
  // The one channel the reading is matched to: the slab's (SlabInfo::channel_weights).
  const Eigen::Vector3d& weights = options.channel_weights;
  auto luminance = [&](const double rgb[3]) {
    return weights.x() * rgb[0] + weights.y() * rgb[1] + weights.z() * rgb[2];
  };
  const Eigen::Vector2d pixel = screen.ImageFromScreen(reference.point_mm);
  const int r = options.radius_px;
  if (!(pixel.x() - r - 2 >= 0 && pixel.y() - r - 2 >= 0 &&
        pixel.x() + r + 2 < screen.image_width && pixel.y() + r + 2 < screen.image_height))
    throw InputError(reference.source, "point_mm",
                     "a point seen in the photos (calib/screen.json maps it to pixel " +
                         std::to_string(pixel.x()) + ", " + std::to_string(pixel.y()) + ")",
                     "a point outside the photo");
  SlideValue slides[2];
  // Each photo's value at the point (luminance per unit exposure) and level (at its exposure,
  // fraction of full scale); the T+ photos' peak (the least exposed photo's): the checks of
  // calibration_checks.h, scale.*.
  nlohmann::json bracket_values[2] = {nlohmann::json::array(), nlohmann::json::array()};
  double peak_p = 0, peak_exposure = 0;
  bool srgb = false;  // codes linearised through the sRGB curve (report, and a note in the log)
  for (const PhotoEntry& e : dataset.PhotosOf(reference.i, reference.j)) {
    PhotoSpec spec = PhotoSpecOf(dataset, e);
    spec.corrections = corrections;
    const Photo photo = DecodePhoto(dataset.PhotoPath(e.file), spec);
    srgb = srgb || (photo.transfer == Transfer::kSrgb && photo.CodeBits() < 32);
    if (photo.pixels.cols != screen.image_width || photo.pixels.rows != screen.image_height)
      throw InputError(photo.path, "image size",
                       std::to_string(screen.image_width) + "x" +
                           std::to_string(screen.image_height) + " as calib/screen.json",
                       std::to_string(photo.pixels.cols) + "x" + std::to_string(photo.pixels.rows));
    const int s = e.positive ? 0 : 1;
    if (const auto v = AddPhoto(photo, pixel, r, &slides[s])) {
      const double y[3] = {v->x(), v->y(), v->z()};
      // The photo as dataset.json names it: a dataset folder's name need not be UTF-8 (JSON
      // must), and the report stays valid when the folder moves.
      bracket_values[s].push_back({{"file", e.file},
                                   {"value", luminance(y)},
                                   {"level", luminance(y) * photo.spec.exposure}});
    }
    if (e.positive && (peak_exposure == 0 || photo.spec.exposure < peak_exposure))
      peak_exposure = photo.spec.exposure, peak_p = PeakLuminance(photo);
  }
  double value[2];
  for (int s = 0; s < 2; ++s) {
    if (slides[s].photos == 0)
      throw InputError(
          dataset.Path("dataset.json"),
          "photos of position " + std::to_string(reference.i) + "," + std::to_string(reference.j),
          std::string("a photo of slide ") + (s == 0 ? "p" : "n") +
              " unclipped around the reference point",
          "every one clipped (or no photo)");
    for (double& c : slides[s].rgb) c /= slides[s].exposure_sum;
    value[s] = luminance(slides[s].rgb);
  }
  const double difference = value[0] - value[1];
  // The reference reads more light through T+ (ScaleReference::Check); photos that do not are
  // of other slides, or the point is where the filter passes none (recorded as scale.point_lit,
  // the same question as its threshold on the signal's size).
  if (!(difference > 1e-6 * std::max(std::abs(value[0]), 1e-12)) || !std::isfinite(difference)) {
    const Error error =
        InputError(reference.source, "point_mm",
                   "a point where the photos through T+ are brighter than through T-",
                   "Y+ " + std::to_string(value[0]) + ", Y- " + std::to_string(value[1]));
    if (checks)
      checks->Fail("scale.point_lit", error.what(),
                   {{"y_plus", value[0]}, {"y_minus", value[1]}, {"signal", difference}});
    throw error;
  }
  RadiometricScale scale;
  scale.scale = (reference.reading_p - reference.reading_n) / difference;
  scale.units = reference.unit;
  scale.channel_weights = weights;
  scale.from_colour = options.channel_weights_from_colour;
  if (!(scale.scale >= 1e-12 && scale.scale <= 1e12))
    throw InputError(reference.source, "reading_p", "readings giving a scale in [1e-12, 1e12]",
                     std::to_string(scale.scale));
  nlohmann::json& j = *report;
  j["photos_through_srgb_curve"] = srgb;
  // A reading file in the dataset folder by its path there: the folder's name need not be UTF-8
  // (JSON must be), and the report stays valid when the folder moves.
  const std::filesystem::path relative =
      std::filesystem::path(reference.source).lexically_relative(dataset.dir);
  j["reference"] =
      !relative.empty() && *relative.begin() != ".." ? relative.string() : reference.source;
  j["position"] = {reference.i, reference.j};
  j["point_mm"] = {reference.point_mm.x(), reference.point_mm.y()};
  j["pixel"] = {pixel.x(), pixel.y()};
  j["fit_radius_px"] = r;
  j["reading_p"] = reference.reading_p;
  j["reading_n"] = reference.reading_n;
  j["value_p"] = value[0];
  j["value_n"] = value[1];
  j["photos_used"] = {slides[0].photos, slides[1].photos};
  j["peak_value_p"] = peak_p;
  j["bracket_values_p"] = bracket_values[0];
  j["bracket_values_n"] = bracket_values[1];
  // A lux meter's scale is K (lm/W, the source's spectrum: unknown here) times a radiometer's:
  // only a W/m2 reading is compared with dataset.json's (scale.matches_dataset).
  if (dataset.radiometric_scale && reference.unit != "lux")
    j["dataset_scale_w_m2"] = *dataset.radiometric_scale;
  j["corrections_applied"] = {{"dark", corrections && corrections->dark != nullptr},
                              {"response", corrections && corrections->response != nullptr},
                              {"flat", corrections && corrections->flat != nullptr}};
  return scale;
}

}  // namespace lumislab
