#include "calibrate/orientations/registration.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "calibrate/ceres_options.h"
#include "calibrate/orientations/overlap_cost.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/log.h"
#include "core/luminaire_set.h"

namespace lumislab {
namespace {

constexpr double kDegPerRad = 180.0 / kPi;
// A pair is compared when at least this many sample directions lie in its overlap.
constexpr int kMinPairSamples = 20;
// A direction of the corrections' space is unconstrained when its curvature is below this
// fraction of the largest, or when turning kFreeSigmaDeg about it changes the overlaps'
// intensities by less than their residual RMS after the fit, i.e. when the residual, were it
// all systematic, could move it by more than kFreeSigmaDeg: the curvature then comes from the
// far fields' own errors (a rotationally symmetric overlap still has some), not from the
// luminaire. No small sigma is reported for what the overlaps do not fix.
constexpr double kFreeCurvatureRatio = 1e-12;
// Sample selection and fit repeat until a round changes no correction by more than this (deg),
// in at most kMaxRounds rounds.
constexpr double kRoundChangeDeg = 0.005;
constexpr int kMaxRounds = 6;
// The residuals are not independent: what remains after the fit is the slabs' far-field error,
// which varies over tens of degrees (a ripple of period about h / z in tan(theta), docs/results.md
// §13). Residuals within one cell of this size count as one measurement for the sigmas: the
// covariance is scaled by (residuals / cells), cells = sum over pairs of overlap_sr / cell.
constexpr double kCorrelationDeg = 15.0;
constexpr double kFreeSigmaDeg = 10.0;
// The gain profile is fitted when at least this many pairs are compared. Across one overlap it
// is seen only as the ratio g(theta_a) / g(theta_b) over one band of directions, which trades
// off against a tilt of the luminaire's lobes there (and, fitted to the slabs' other errors,
// would make a rotation the luminaire's symmetry leaves free look constrained); three pairs
// see each capture angle against several others.
constexpr int kMinGainProfilePairs = 3;

// One orientation's far field as Ceres reads it.
struct Sampler {
  const RegistrationInput* input;
  std::unique_ptr<ceres::Grid2D<double, 1>> grid;
  std::unique_ptr<FarFieldInterpolator> interpolator;
  double At(const Eigen::Vector3d& w_capture) const {
    double col = 0, row = 0, value = 0;
    input->far_field.GridCoordinates(w_capture.data(), &col, &row);
    interpolator->Evaluate(row, col, &value);
    return value;
  }
};

struct PairSamples {
  int a = 0, b = 0;
  double overlap_sr = 0;
  std::vector<Eigen::Vector3d> directions;  // luminaire frame
  double scale = 0;                         // mean of (I_a + I_b) / 2 where selected
  double theta_max_deg = 0;  // the largest angle from either capture axis among the directions
};

Eigen::Matrix3d Refined(const RegistrationInput& in, const double* c) {
  return RotationFromVector(Eigen::Vector3d(c[0], c[1], c[2])) * in.nominal;
}

// The directions of pair (a, b) both orientations see with margin at poses r_a, r_b.
PairSamples SelectSamples(const std::vector<Eigen::Vector3d>& sphere, const Sampler& a,
                          const Eigen::Matrix3d& r_a, const Sampler& b, const Eigen::Matrix3d& r_b,
                          double margin_deg) {
  PairSamples out;
  double sum = 0;
  for (const Eigen::Vector3d& w : sphere) {
    const Eigen::Vector3d v_a = r_a * w, v_b = r_b * w;
    if (a.input->cone.MarginDeg(v_a) < margin_deg || b.input->cone.MarginDeg(v_b) < margin_deg)
      continue;
    if (!a.input->far_field.SeenAround(v_a) || !b.input->far_field.SeenAround(v_b)) continue;
    out.directions.push_back(w);
    sum += 0.5 * (a.At(v_a) + b.At(v_b));
    out.theta_max_deg =
        std::max(out.theta_max_deg, std::acos(std::min({1.0, v_a.z(), v_b.z()})) * kDegPerRad);
  }
  if (!out.directions.empty()) out.scale = sum / double(out.directions.size());
  return out;
}

// Relative RMS of I_a - I_b and the ratio sum I_a / sum I_b over the samples at poses r_a, r_b,
// each I divided by the gain profile (overlap_cost.h) at its angle from its capture axis.
void ComparePair(const PairSamples& s, const Sampler& a, const Eigen::Matrix3d& r_a,
                 const Sampler& b, const Eigen::Matrix3d& r_b, const double* profile, double* rms,
                 double* ratio) {
  double sum_a = 0, sum_b = 0, sum2 = 0;
  for (const Eigen::Vector3d& w : s.directions) {
    const Eigen::Vector3d v_a = r_a * w, v_b = r_b * w;
    const double g_a = GainProfile(profile, v_a.z()), g_b = GainProfile(profile, v_b.z());
    // As the cost compares them (overlap_cost.h): divided by g, scaled back by the mean gain.
    const double i_a = a.At(v_a) / g_a * 0.5 * (g_a + g_b);
    const double i_b = b.At(v_b) / g_b * 0.5 * (g_a + g_b);
    sum_a += i_a;
    sum_b += i_b;
    sum2 += (i_a - i_b) * (i_a - i_b);
  }
  const double n = double(s.directions.size()), mean = 0.5 * (sum_a + sum_b) / n;
  *rms = n > 0 && mean > 0 ? std::sqrt(sum2 / n) / mean : 0;
  *ratio = sum_b > 0 ? sum_a / sum_b : 0;
}

// The symmetric positive semi-definite m's pseudo-inverse on its eigen-directions above
// kFreeCurvatureRatio of its largest eigenvalue.
Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& m) {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(m.rows(), m.cols());
  if (m.size() == 0) return out;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(m);
  const double largest = eigen.eigenvalues().maxCoeff();
  for (int i = 0; i < eigen.eigenvalues().size(); ++i)
    if (eigen.eigenvalues()(i) > kFreeCurvatureRatio * largest)
      out += eigen.eigenvectors().col(i) * eigen.eigenvectors().col(i).transpose() /
             eigen.eigenvalues()(i);
  return out;
}

}  // namespace

double Registration::Gain(double theta_deg) const {
  return GainProfile(gain_profile.data(), std::cos(theta_deg / kDegPerRad));
}

void RegistrationOptions::Check() const {
  if (directions < 1000)
    throw BadInput("directions: expected >= 1000, got " + std::to_string(directions));
  if (!(margin_deg >= 0)) throw BadInput("margin_deg: expected >= 0, got " + Num(margin_deg));
  if (!(nodes_per_tan >= 4))
    throw BadInput("nodes_per_tan: expected >= 4, got " + Num(nodes_per_tan));
  if (!(loss_scale > 0)) throw BadInput("loss_scale: expected > 0, got " + Num(loss_scale));
  if (!(max_relative_rms > 0))
    throw BadInput("max_relative_rms: expected > 0, got " + Num(max_relative_rms));
  if (max_iterations < 1 || threads < 1) throw BadInput("max_iterations, threads: expected >= 1");
}

Registration RegisterOrientations(const std::vector<RegistrationInput>& inputs,
                                  const CoverageReport& coverage,
                                  const RegistrationOptions& options) {
  options.Check();
  const int count = int(inputs.size());
  LUMISLAB_CHECK(count >= 2, "at least two orientations");
  std::vector<Sampler> samplers(static_cast<size_t>(count));
  for (int k = 0; k < count; ++k) {
    const FarFieldGrid& g = inputs[size_t(k)].far_field;
    samplers[size_t(k)].input = &inputs[size_t(k)];
    samplers[size_t(k)].grid =
        std::make_unique<ceres::Grid2D<double, 1>>(g.values.data(), 0, g.ny, 0, g.nx);
    samplers[size_t(k)].interpolator =
        std::make_unique<FarFieldInterpolator>(*samplers[size_t(k)].grid);
  }
  const std::vector<Eigen::Vector3d> sphere = FibonacciDirections(options.directions);
  std::vector<std::array<double, 3>> corrections(static_cast<size_t>(count), {0.0, 0.0, 0.0});
  auto pose = [&](int k) { return Refined(inputs[size_t(k)], corrections[size_t(k)].data()); };
  auto select = [&]() {
    std::vector<PairSamples> pairs;
    for (const PairOverlap& p : coverage.pairs) {
      if (p.overlap_sr < kMinOverlapSr) continue;
      PairSamples s = SelectSamples(sphere, samplers[size_t(p.a)], pose(p.a), samplers[size_t(p.b)],
                                    pose(p.b), options.margin_deg);
      s.a = p.a;
      s.b = p.b;
      s.overlap_sr = p.overlap_sr;
      pairs.push_back(std::move(s));
    }
    return pairs;
  };

  Registration out;
  // The gain profile's coefficients (g = 1 at the start, and throughout when not fitted).
  std::array<double, kGainProfileTerms> profile = {0.0, 0.0};
  std::vector<PairSamples> pairs = select();
  for (const PairSamples& s : pairs) {
    RegisteredPair r;
    r.a = s.a;
    r.b = s.b;
    r.overlap_sr = s.overlap_sr;
    ComparePair(s, samplers[size_t(s.a)], pose(s.a), samplers[size_t(s.b)], pose(s.b),
                profile.data(), &r.rms_before, &r.ratio);
    out.pairs.push_back(r);
  }

  // Rounds: the samples chosen at the nominal poses, then again at the refined ones (a
  // correction of a few degrees moves directions across the cones' margins), until a round moves
  // no correction by more than kRoundChangeDeg (at most kMaxRounds).
  std::unique_ptr<ceres::Problem> problem;
  bool fit_profile = false;
  std::vector<std::array<double, 3>> previous = corrections;
  for (int round = 0; round < kMaxRounds; ++round) {
    if (round > 0) {
      double change = 0;
      for (int k = 0; k < count; ++k)
        change = std::max(change, (Eigen::Vector3d(corrections[size_t(k)].data()) -
                                   Eigen::Vector3d(previous[size_t(k)].data()))
                                          .norm() *
                                      kDegPerRad);
      if (round >= 2 && change < kRoundChangeDeg) break;
      // Data that disagree are not chased further: after the second round, a pair beyond the
      // threshold ends the rounds (the refusal below names it).
      bool disagree = false;
      for (const PairSamples& s : pairs) {
        if (int(s.directions.size()) < kMinPairSamples || round < 2) continue;
        double rms = 0, ratio = 1;
        ComparePair(s, samplers[size_t(s.a)], pose(s.a), samplers[size_t(s.b)], pose(s.b),
                    profile.data(), &rms, &ratio);
        disagree = disagree || rms > options.max_relative_rms;
      }
      if (disagree) break;
      previous = corrections;
      pairs = select();
    }
    int compared = 0;
    for (const PairSamples& s : pairs)
      compared += int(s.directions.size()) >= kMinPairSamples && s.scale > 0;
    fit_profile = options.fit_gain_profile && compared >= kMinGainProfilePairs;
    if (!fit_profile) profile = {0.0, 0.0};
    problem = std::make_unique<ceres::Problem>();
    for (const PairSamples& s : pairs) {
      if (int(s.directions.size()) < kMinPairSamples || !(s.scale > 0)) continue;
      const RegistrationInput& a = inputs[size_t(s.a)];
      const RegistrationInput& b = inputs[size_t(s.b)];
      for (const Eigen::Vector3d& w : s.directions)
        problem->AddResidualBlock(
            OverlapCost::Create(&a.far_field, samplers[size_t(s.a)].interpolator.get(),
                                a.nominal * w, &b.far_field,
                                samplers[size_t(s.b)].interpolator.get(), b.nominal * w, s.scale),
            new ceres::HuberLoss(options.loss_scale), corrections[size_t(s.a)].data(),
            corrections[size_t(s.b)].data(), profile.data());
    }
    if (problem->HasParameterBlock(corrections[0].data()))
      problem->SetParameterBlockConstant(corrections[0].data());
    if (problem->HasParameterBlock(profile.data())) {
      if (!fit_profile) problem->SetParameterBlockConstant(profile.data());
      // g stays within [0.5, 1.5] over the cones (1 - cos theta <= 0.6): a far field off by more
      // is not what the profile is for.
      for (int i = 0; i < kGainProfileTerms; ++i) {
        problem->SetParameterLowerBound(profile.data(), i, -0.5);
        problem->SetParameterUpperBound(profile.data(), i, 0.5);
      }
    }
    if (problem->NumResidualBlocks() == 0) break;
    ceres::Solver::Summary summary;
    ceres::Solve(RefinerSolverOptions(ceres::DENSE_QR, options.max_iterations, options.threads),
                 problem.get(), &summary);
    out.iterations += int(summary.iterations.size());
    out.converged = summary.termination_type == ceres::CONVERGENCE;
  }

  // Uncertainty: the Jacobian of the (robustified) relative residuals at the solution, its
  // normal matrix's eigen-decomposition, the covariance sigma^2 H^-1 on the directions the
  // overlaps fix and "unconstrained" on the others (ceres::Covariance's pseudo-inverse would
  // give those a zero, i.e. a fake small, variance).
  out.orientations.resize(static_cast<size_t>(count));
  std::vector<int> block_of(static_cast<size_t>(count),
                            -1);  // column block of each free orientation
  std::vector<double*> blocks;
  for (int k = 1; k < count; ++k)
    if (problem && problem->HasParameterBlock(corrections[size_t(k)].data())) {
      block_of[size_t(k)] = int(blocks.size());
      blocks.push_back(corrections[size_t(k)].data());
    }
  fit_profile = fit_profile && !blocks.empty();
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(3 * blocks.size(), 3 * blocks.size());
  Eigen::VectorXd free_weight = Eigen::VectorXd::Zero(3 * blocks.size());
  std::vector<Eigen::VectorXd> free_vectors;
  if (!blocks.empty()) {
    ceres::Problem::EvaluateOptions evaluate;
    evaluate.parameter_blocks = blocks;
    if (fit_profile) evaluate.parameter_blocks.push_back(profile.data());
    double cost = 0;
    std::vector<double> residuals;
    ceres::CRSMatrix crs;
    problem->Evaluate(evaluate, &cost, &residuals, nullptr, &crs);
    Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
    for (int r = 0; r < crs.num_rows; ++r)
      for (int i = crs.rows[size_t(r)]; i < crs.rows[size_t(r) + 1]; ++i)
        jacobian(r, crs.cols[size_t(i)]) = crs.values[size_t(i)];
    const int dof = std::max(1, crs.num_rows - crs.num_cols);
    const double variance = 2.0 * cost / dof;
    out.residuals = crs.num_rows;
    out.residual_sigma = std::sqrt(variance);
    // The rotations' information with the gain profile marginalised out (its Schur complement),
    // so that their sigmas include what the profile can take of the residuals; the profile's
    // sigma likewise with the rotations' constrained directions marginalised out.
    const long nr = 3 * long(blocks.size()), np = fit_profile ? kGainProfileTerms : 0;
    const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
    Eigen::MatrixXd rotation_info = normal.topLeftCorner(nr, nr);
    if (np > 0) {
      const Eigen::MatrixXd h_rp = normal.topRightCorner(nr, np);
      const Eigen::MatrixXd h_pp = normal.bottomRightCorner(np, np);
      rotation_info -= h_rp * PseudoInverse(h_pp) * h_rp.transpose();
      const Eigen::MatrixXd profile_cov =
          variance * PseudoInverse(h_pp - h_rp.transpose() *
                                              PseudoInverse(normal.topLeftCorner(nr, nr)) * h_rp);
      for (int i = 0; i < kGainProfileTerms; ++i)
        out.gain_profile_sigma[size_t(i)] = std::sqrt(std::max(0.0, profile_cov(i, i)));
    }
    // Correlated residuals (kCorrelationDeg): the covariance of independent ones times the
    // number of residuals per independent cell.
    double cells = 0;
    for (const PairSamples& s : pairs)
      if (int(s.directions.size()) >= kMinPairSamples)
        cells += std::max(1.0, s.overlap_sr / std::pow(kCorrelationDeg / kDegPerRad, 2));
    const double correlation = std::max(1.0, crs.num_rows / std::max(1.0, cells));
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(rotation_info);
    const double largest = eigen.eigenvalues().maxCoeff();
    const double free_sigma_rad = kFreeSigmaDeg / kDegPerRad;
    for (int i = 0; i < eigen.eigenvalues().size(); ++i) {
      const double lambda = eigen.eigenvalues()(i);
      const Eigen::VectorXd v = eigen.eigenvectors().col(i);
      const bool free = !(lambda > kFreeCurvatureRatio * largest) ||
                        variance * crs.num_rows / lambda > free_sigma_rad * free_sigma_rad;
      if (free) {
        free_weight += v.cwiseAbs2();
        free_vectors.push_back(v);
      } else {
        cov += correlation * variance / lambda * v * v.transpose();
      }
    }
  }
  // What the overlaps do not fix stays nominal: the solver's drift along a free direction (its
  // curvature is the far fields' own errors) is taken out of the corrections.
  for (const Eigen::VectorXd& v : free_vectors) {
    double along = 0;
    for (size_t j = 0; j < blocks.size(); ++j)
      along += v.segment<3>(3 * long(j)).dot(Eigen::Vector3d(blocks[j]));
    for (size_t j = 0; j < blocks.size(); ++j)
      Eigen::Map<Eigen::Vector3d>(blocks[j]) -= along * v.segment<3>(3 * long(j));
  }
  // The pairs after the fit, on the final samples, at the poses reported.
  for (RegisteredPair& r : out.pairs)
    for (const PairSamples& s : pairs)
      if (s.a == r.a && s.b == r.b) {
        r.samples = int(s.directions.size());
        ComparePair(s, samplers[size_t(s.a)], pose(s.a), samplers[size_t(s.b)], pose(s.b),
                    profile.data(), &r.rms_after, &r.ratio);
      }
  out.gain_profile_fitted = fit_profile;
  out.gain_profile = profile;
  for (const PairSamples& s : pairs)
    out.gain_profile_theta_max_deg = std::max(out.gain_profile_theta_max_deg, s.theta_max_deg);

  for (int k = 0; k < count; ++k) {
    RegisteredOrientation& o = out.orientations[size_t(k)];
    o.gauge = k == 0;
    o.rotation = pose(k);
    // From the rotation itself, so that the angle is within [0, 180] whatever the solver's
    // parameters became.
    const Eigen::AngleAxisd c(o.rotation * inputs[size_t(k)].nominal.transpose());
    o.correction_deg = c.axis() * c.angle() * kDegPerRad;
    o.angle_deg = c.angle() * kDegPerRad;
    if (k == 0) continue;
    const int j = block_of[size_t(k)];
    if (j < 0) {  // no pair compared: nothing fixes it
      o.unconstrained = {true, true, true};
      o.sigma_deg.setConstant(std::numeric_limits<double>::infinity());
      o.free_axes = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()};
      continue;
    }
    for (int i = 0; i < 3; ++i) {
      o.unconstrained[size_t(i)] = free_weight(3 * j + i) > 0.05;
      o.sigma_deg(i) = o.unconstrained[size_t(i)]
                           ? std::numeric_limits<double>::infinity()
                           : std::sqrt(cov(3 * j + i, 3 * j + i)) * kDegPerRad;
    }
    // A free direction of the corrections (capture frame of k) is a rotation of the luminaire
    // about the luminaire-frame axis R_k^T p.
    for (const Eigen::VectorXd& v : free_vectors) {
      const Eigen::Vector3d p = v.segment<3>(3 * j);
      if (p.norm() > 0.3) o.free_axes.push_back((o.rotation.transpose() * p).normalized());
    }
  }

  // Radiometric scales that disagree (a calibration of one orientation that does not belong)
  // would otherwise be taken up by the rotations.
  for (const RegisteredPair& r : out.pairs) {
    if (r.samples < kMinPairSamples || std::abs(r.ratio - 1) <= kMaxPairScaleDeviation) continue;
    if (!out.disagreement.empty()) out.disagreement += "; ";
    out.disagreement += "orientations " + inputs[size_t(r.a)].name + " and " +
                        inputs[size_t(r.b)].name + " disagree in scale: intensity ratio " +
                        Num(r.ratio) + " over their overlap (at most " +
                        Num(100 * kMaxPairScaleDeviation) +
                        " % from 1): check each one's calib/scale.json and slab";
  }
  // An orientation compared with others whose rotation the overlaps fix in no direction: the
  // fit cannot place it (its neighbours disagree with it everywhere).
  for (int k = 1; k < count; ++k) {
    const RegisteredOrientation& o = out.orientations[size_t(k)];
    if (block_of[size_t(k)] < 0 ||
        !(o.unconstrained[0] && o.unconstrained[1] && o.unconstrained[2]))
      continue;
    if (!out.disagreement.empty()) out.disagreement += "; ";
    out.disagreement += "the overlaps fix the rotation of " + inputs[size_t(k)].name +
                        " in no direction (residual sigma " + Num(out.residual_sigma) +
                        "): its slab or its nominal pose does not fit its neighbours";
  }

  std::vector<int> disagreeing(static_cast<size_t>(count), 0);  // pairs each orientation is in
  int disagreements = 0;
  for (const RegisteredPair& r : out.pairs) {
    if (r.samples < kMinPairSamples || !(r.rms_after > options.max_relative_rms)) continue;
    // A pair that agreed at the nominal poses was dragged by the fit: not counted for the
    // culprit below.
    if (r.rms_before > options.max_relative_rms) {
      ++disagreements;
      ++disagreeing[size_t(r.a)];
      ++disagreeing[size_t(r.b)];
    }
    if (!out.disagreement.empty()) out.disagreement += "; ";
    out.disagreement +=
        "orientations " + inputs[size_t(r.a)].name + " and " + inputs[size_t(r.b)].name +
        " disagree over their overlap beyond noise: " + "relative RMS " + Num(r.rms_after) +
        " after the registration (" + Num(r.rms_before) + " before; threshold " +
        Num(options.max_relative_rms) + "), intensity ratio " + Num(r.ratio) + " over " +
        std::to_string(r.samples) + " directions (" + Num(r.overlap_sr) + " sr)";
  }
  // One orientation in every pair that disagrees before and after the fit (two or more) is the
  // likely culprit.
  for (int k = 0; k < count && disagreements >= 2; ++k)
    if (disagreeing[size_t(k)] == disagreements)
      out.disagreement += "; " + inputs[size_t(k)].name +
                          " is in every pair that disagrees at the nominal poses and after the "
                          "fit: its slab (another luminaire, another scale) or its nominal pose "
                          "is the likely cause";
  return out;
}

}  // namespace lumislab
