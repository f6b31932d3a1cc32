#include "lib/photometry/colour.h"

#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <limits>

#include "core/error.h"
#include "core/json.h"

namespace lumislab {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kC2 = 1.4388e-2;             // m K, second radiation constant (CIE 15:2004)
constexpr double kMaxLuminousEfficacy = 683;  // lm/W at 555 nm (540 THz)
// The CCT search range, in mired (1e6 / K): 1000 K - 25000 K.
constexpr double kMinMired = 40, kMaxMired = 1000;

Spectrum FromTable(const double* table) {
  Spectrum s;
  for (int k = 0; k < kSpectralSamples; ++k) s[k] = table[k];
  return s;
}

Eigen::Vector2d PlanckianUv(double mired) { return XyToUv1960(PlanckianXy(1e6 / mired)); }

// The Planckian locus in CIE 1960 (u, v) every mired of [kMinMired, kMaxMired].
const std::vector<Eigen::Vector2d>& LocusTable() {
  static const std::vector<Eigen::Vector2d> table = [] {
    std::vector<Eigen::Vector2d> t;
    for (double m = kMinMired; m <= kMaxMired; m += 1) t.push_back(PlanckianUv(m));
    return t;
  }();
  return table;
}

}  // namespace

const Eigen::Matrix<double, kSpectralSamples, 3>& Cmf1931() {
  static const Eigen::Matrix<double, kSpectralSamples, 3> cmf = [] {
    Eigen::Matrix<double, kSpectralSamples, 3> m;
    for (int k = 0; k < kSpectralSamples; ++k)
      for (int c = 0; c < 3; ++c) m(k, c) = kCmf1931[k][c];
    return m;
  }();
  return cmf;
}

Spectrum Blackbody(double kelvin) {
  Spectrum s;
  for (int k = 0; k < kSpectralSamples; ++k) {
    const double lambda_m = WavelengthNm(k) * 1e-9;
    // c1 / lambda^5 / (exp(c2 / (lambda T)) - 1); c1 drops out with the normalisation.
    s[k] = 1.0 / (std::pow(lambda_m, 5) * std::expm1(kC2 / (lambda_m * kelvin)));
  }
  return s / s.maxCoeff();
}

Spectrum IlluminantD50() { return FromTable(kD50); }
Spectrum IlluminantD65() { return FromTable(kD65); }
std::optional<Spectrum> IlluminantByName(const std::string& name) {
  if (name == "D50") return IlluminantD50();
  if (name == "D65") return IlluminantD65();
  return std::nullopt;
}

Spectrum ColorCheckerReflectance(int k) { return FromTable(kColorCheckerOhta[k]); }
const char* ColorCheckerPatchName(int k) { return kColorCheckerNames[k]; }

Eigen::Vector3d SpectrumToXyz(const Spectrum& s) {
  return kSpectralStepNm * (Cmf1931().transpose() * s);
}

double LuminousEfficacy(const Spectrum& s) {
  const double total = s.sum();
  if (!(total > 0)) return kNaN;
  return kMaxLuminousEfficacy * Cmf1931().col(1).dot(s) / total;
}

Eigen::Vector2d XyzToXy(const Eigen::Vector3d& xyz) {
  const double sum = xyz.sum();
  if (!(sum > 0)) return {kNaN, kNaN};
  return {xyz.x() / sum, xyz.y() / sum};
}

Eigen::Vector2d XyToUv1960(const Eigen::Vector2d& xy) {
  const double d = -2 * xy.x() + 12 * xy.y() + 3;
  return {4 * xy.x() / d, 6 * xy.y() / d};
}

Eigen::Vector2d PlanckianXy(double kelvin) { return XyzToXy(SpectrumToXyz(Blackbody(kelvin))); }

Cct CctFromXy(const Eigen::Vector2d& xy) {
  if (!xy.allFinite()) return {kNaN, kNaN};
  const Eigen::Vector2d uv = XyToUv1960(xy);
  const std::vector<Eigen::Vector2d>& table = LocusTable();
  size_t best = 0;
  for (size_t k = 1; k < table.size(); ++k)
    if ((table[k] - uv).squaredNorm() < (table[best] - uv).squaredNorm()) best = k;
  // Golden-section search for the nearest point within a mired of the nearest table entry (the
  // distance is unimodal there: the locus curves slowly on the scale of a mired).
  auto distance = [&](double mired) { return (PlanckianUv(mired) - uv).squaredNorm(); };
  double lo = std::max(kMinMired, kMinMired + best - 1.0);
  double hi = std::min(kMaxMired, kMinMired + best + 1.0);
  const double g = 0.5 * (std::sqrt(5.0) - 1);
  double a = hi - g * (hi - lo), b = lo + g * (hi - lo);
  double fa = distance(a), fb = distance(b);
  for (int it = 0; it < 40; ++it) {
    if (fa < fb) {
      hi = b, b = a, fb = fa;
      a = hi - g * (hi - lo), fa = distance(a);
    } else {
      lo = a, a = b, fa = fb;
      b = lo + g * (hi - lo), fb = distance(b);
    }
  }
  const double mired = 0.5 * (lo + hi);
  Cct cct;
  cct.kelvin = 1e6 / mired;
  // Duv: + above the locus (towards green, larger v), the CIE / ANSI C78.377 sign.
  const Eigen::Vector2d on_locus = PlanckianUv(mired);
  cct.duv = std::copysign((uv - on_locus).norm(), uv.y() - on_locus.y());
  if (mired <= kMinMired + 1e-6 || mired >= kMaxMired - 1e-6) cct.kelvin = kNaN;
  if (!(std::abs(cct.duv) <= kCctMaxAbsDuv)) cct.kelvin = kNaN;  // no CCT this far off the locus
  return cct;
}

Eigen::Vector3d XyzToLab(const Eigen::Vector3d& xyz, const Eigen::Vector3d& white_xyz) {
  auto f = [](double t) {
    constexpr double d = 6.0 / 29;
    return t > d * d * d ? std::cbrt(t) : t / (3 * d * d) + 4.0 / 29;
  };
  const double fx = f(xyz.x() / white_xyz.x()), fy = f(xyz.y() / white_xyz.y()),
               fz = f(xyz.z() / white_xyz.z());
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

double DeltaE76(const Eigen::Vector3d& lab1, const Eigen::Vector3d& lab2) {
  return (lab1 - lab2).norm();
}

Eigen::Vector3d ColourCalibration::LuminanceWeights() const {
  const Eigen::Vector3d y = rgb_to_xyz.row(1).transpose();
  return y / y.sum();
}

ColourCalibration ColourCalibration::Load(const std::string& path) {
  const JsonDocument doc = JsonDocument::Load(path);
  doc.CheckSchemaVersion(kColourSchemaVersion);
  const JsonView root = doc.root();
  ColourCalibration c;
  c.file = path;
  const JsonView m = root["rgb_to_xyz"];
  if (m.Size() != 3) m.Fail("3 rows [X, Y, Z] of 3 numbers");
  for (size_t r = 0; r < 3; ++r) {
    const std::vector<double> row = m[r].Numbers(3);
    for (int col = 0; col < 3; ++col) c.rgb_to_xyz(int(r), col) = row[col];
  }
  // A matrix that maps every positive RGB to zero luminance or an undefined chromaticity is no
  // calibration (hand-edited or corrupt).
  const Eigen::Matrix3d& a = c.rgb_to_xyz;
  const double scale = a.row(0).norm() * a.row(1).norm() * a.row(2).norm();
  if (!(a.row(1).sum() > 0) || !(std::abs(a.determinant()) > 1e-9 * scale))
    m.Fail("an invertible matrix whose Y row sums to > 0");
  c.chart = root["chart"].String();
  c.illuminant = root["illuminant"].String();
  c.photo = root.StringOr("photo", "");
  const JsonView residual = root["residual_delta_e"];
  c.mean_delta_e = residual["mean"].NumberIn(0, 1e6);
  c.max_delta_e = residual["max"].NumberIn(0, 1e6);
  return c;
}

std::optional<ColourCalibration> ColourCalibration::LoadFor(const std::string& dataset_dir) {
  const std::string path = (std::filesystem::path(dataset_dir) / "calib" / "colour.json").string();
  if (!std::filesystem::exists(path)) return std::nullopt;
  return Load(path);
}

LightColour ColourOfRgb(const ColourCalibration& calibration, const Eigen::Vector3d& rgb) {
  LightColour c;
  c.xyz = calibration.Xyz(rgb);
  c.xy = XyzToXy(c.xyz);
  c.cct = CctFromXy(c.xy);
  return c;
}

}  // namespace lumislab
