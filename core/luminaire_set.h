// A luminaire measured from several orientations (docs/formats.md §19): the luminaire folder,
// its `luminaire.json` (the orientations and their nominal poses, each an ordinary dataset
// folder beside it) and `registration.json` (the poses refined from the overlaps, written by
// `lumislab-calibrate orientations`); the cone of directions one orientation sees, the taper
// that blends neighbouring orientations where both see a direction, and the coverage and
// overlap of a set of orientations, shared by the planner, the registration, the merged far
// field and the preview.
//
// Frames: the luminaire frame is the luminaire's own; an orientation's capture frame is the
// frame of its dataset (S at z = 0, the screen at z = d). Pose k maps the first to the second:
// directions w_capture = R_k w_luminaire, points x_capture = R_k x_luminaire + centre_k.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace lumislab {

struct Dataset;
struct SamplingGrid;
struct SlabInfo;

constexpr int kLuminaireSetSchemaVersion = 1;
constexpr int kRegistrationSchemaVersion = 1;
// Two orientations overlap enough to register when both see at least this solid angle with a
// margin (a 10 x 10 degree patch).
constexpr double kMinOverlapSr = 0.03;
// Two orientations' intensities over the directions both see may differ by at most this
// fraction in flux (their ratio within 1 +- 0.05): beyond it a scale calibration, a slab or a
// pose does not belong, and the registration and the exports refuse the pair.
constexpr double kMaxPairScaleDeviation = 0.05;
// The taper's width (degrees of margin inside the cone over which an orientation's weight rises
// from 0 to 1).
constexpr double kDefaultTaperDeg = 4.0;

// What one orientation sees: directions whose every point of S lands on the screen, i.e. the
// rectangle of half-angles atan(half_w / d) x atan(half_h / d) about +z of the capture frame.
struct OrientationCone {
  double distance_mm = 0;  // d
  double half_w_mm = 0;    // usable half-width on the screen plane: the screen's half-width less
  double half_h_mm = 0;    // the half-extent of the positions' support on S (ConeOfDataset)

  // Margin (degrees) of capture-frame direction w inside the cone: min over the two axes of the
  // limit angle less the direction's angle in that axis plane; negative outside, -90 behind S.
  double MarginDeg(const Eigen::Vector3d& w_capture) const;
};

// The cone of a dataset: d, and the screen's half-sizes (the slab window) less the positions'
// support on S as the far field integrates it (the grid's half-extent plus h, a bell's reach).
OrientationCone ConeOfDataset(const Dataset& dataset);
// The same from a slab's layout (its window is the screen; every orientation of a folder shares
// it): what the preview and the benches have in hand.
OrientationCone ConeOfSlab(const SlabInfo& info);

// n directions of equal solid angle over the sphere (or the hemisphere z >= 0): a Fibonacci
// lattice, the sampling of AnalyseCoverage and of the registration's overlaps.
std::vector<Eigen::Vector3d> FibonacciDirections(int n, bool hemisphere = false);

// The taper of an orientation at a capture-frame direction: 0 outside the cone, smoothstep
// 3t^2 - 2t^3 of t = margin / taper_deg inside, 1 beyond taper_deg. The preview's shader
// (preview/shaders) carries a copy of this formula; tests/preview pins the two equal.
double ConeTaper(const OrientationCone& cone, const Eigen::Vector3d& w_capture,
                 double taper_deg = kDefaultTaperDeg);

struct Orientation {
  std::string name;     // unique, e.g. "o03"
  std::string dataset;  // its dataset folder, relative to the luminaire folder
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();  // nominal: R = Rz Ry Rx (degrees)
  Eigen::Vector3d centre_mm = Eigen::Vector3d::Zero();     // luminaire origin in the capture frame
  // How the lab gets there (optional, written by the planner): the hand mount (0, 1, ...) and
  // the rotation axis's angle; the driver moves the axis and asks the operator to remount.
  std::optional<int> mount;
  std::optional<double> axis_deg;

  // After registration (registration.json), else the nominal pose:
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // R_k, capture_from_luminaire
  bool registered = false;
  Eigen::Vector3d correction_deg = Eigen::Vector3d::Zero();  // rotation vector R_k R_nominal^T
  // Its 1-sigma per component, degrees; +infinity where the overlaps do not constrain it.
  Eigen::Vector3d sigma_deg = Eigen::Vector3d::Zero();

  Eigen::Matrix3d NominalRotation() const;
};

struct LuminaireSet {
  std::string folder;    // the luminaire folder as given
  std::string coverage;  // "sphere" or "hemisphere": what the lab asked to measure
  std::vector<Orientation> orientations;

  // The dataset folder of orientation k (folder / dataset).
  std::string DatasetFolder(size_t k) const;
};

// True when `folder` holds a luminaire.json (the callers' test of folder kind).
bool IsLuminaireFolder(const std::string& folder);
// Reads luminaire.json and, when present, registration.json (whose orientations must be
// luminaire.json's, by name). Errors name the file and the field (exit 2).
LuminaireSet LoadLuminaireSet(const std::string& folder);
// Writes luminaire.json (atomically; the registered poses are not part of it).
void WriteLuminaireSet(const LuminaireSet& set);
// The same content under any file name (a plan: `lumislab-plan orientations --out`, read by
// `acquire synth|capture --orientations`): read with `folder` as the set's folder and no
// registration, errors naming `file`; written atomically.
LuminaireSet LoadLuminaireSetFile(const std::string& file, const std::string& folder);
void WriteLuminaireSetFile(const LuminaireSet& set, const std::string& file);
// The path of the two files.
std::string LuminaireJsonPath(const std::string& folder);
std::string RegistrationJsonPath(const std::string& folder);

// Coverage of a set of orientations over the sphere (or the hemisphere z >= 0 of the luminaire
// frame), from a Fibonacci sphere of `samples` directions, and the overlap of every pair.
struct PairOverlap {
  int a = 0, b = 0;       // orientation indices, a < b
  double overlap_sr = 0;  // solid angle both see with margin > 0
};
struct CoverageReport {
  double covered_fraction = 0;  // of the sphere / hemisphere seen by at least one orientation
  double unseen_sr = 0;
  std::vector<PairOverlap> pairs;  // every pair with overlap_sr > 0
  // Empty when every orientation is connected to the first through pairs of overlap_sr >=
  // kMinOverlapSr; otherwise why not, naming the orientation(s) (by `names` where given) and
  // the largest overlap found.
  std::string overlap_problem;
};
CoverageReport AnalyseCoverage(const std::vector<Eigen::Matrix3d>& capture_from_luminaire,
                               const std::vector<OrientationCone>& cones, bool hemisphere,
                               int samples = 20000, const std::vector<std::string>& names = {});

}  // namespace lumislab
