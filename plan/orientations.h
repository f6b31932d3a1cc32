// lumislab-plan orientations: the orientations a lab turns the luminaire to so that the captures
// together see the whole sphere (or the hemisphere z >= 0 of the luminaire frame), every one
// connected to the first through neighbours that overlap enough to register
// (docs/method.md §4.12, "Planning orientations"). What one orientation sees is core's
// OrientationCone; the proposed set is checked with AnalyseCoverage (core/luminaire_set.h).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/luminaire_set.h"

namespace lumislab {

// The luminaire's centre behind S by default: deep enough for a luminaire of this radius (mm)
// plus a margin, whichever way it is turned.
constexpr double kDefaultLuminaireRadiusMm = 50;
constexpr double kCentreDepthMarginMm = 10;
// Candidate turns are multiples of one of these steps (degrees), coarsest first.
constexpr int kOrientationStepsDeg[] = {90, 72, 60, 45, 40, 36, 30, 24, 20, 18, 15};
// With a rotation axis a plan costs its orientations plus this much per hand remount: the
// lattice of least cost wins (among equals the fewer orientations, then the coarser lattice).
constexpr double kRemountCost = 0.5;
// The search's connection test asks this much more overlap than kMinOverlapSr, so that
// AnalyseCoverage, sampling the sphere more finely, finds every planned pair connected.
constexpr double kPlannedOverlapMargin = 1.5;

struct OrientationPlanInput {
  OrientationCone cone;     // what one capture sees (ConeOfDataset)
  bool hemisphere = false;  // cover z >= 0 of the luminaire frame only
  // true: a rotation axis (the stage's A axis) turns the luminaire about the capture frame's +y
  // through centre_mm, and hand remounts tilt it on the axis; false: every orientation is a
  // hand mount.
  bool rotation_axis = true;
  Eigen::Vector3d centre_mm{0, 0, -(kDefaultLuminaireRadiusMm + kCentreDepthMarginMm)};
  double min_coverage = 0.999;  // of the sphere / hemisphere, by AnalyseCoverage
  int max_orientations = 40;
  int threads = 0;  // 0: all cores
};

struct PlannedOrientation {
  // Pose R = Ry(axis_deg) Rx(mount_tilt_deg): the mount tilts the luminaire about the capture
  // frame's x on the axis, the axis then turns it about y (both through centre_mm).
  int mount = 0;  // hand mount index (0 = the first orientation's)
  double mount_tilt_deg = 0;
  double axis_deg = 0;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // capture_from_luminaire
};

struct OrientationPlan {
  std::vector<PlannedOrientation> orientations;  // the first at the identity pose
  int step_deg = 0;                              // the candidate lattice it came from
  CoverageReport coverage;                       // AnalyseCoverage of the set
  std::vector<double> cumulative_coverage;       // after orientations 0..k
  // Empty when the plan reaches min_coverage with every orientation connected; otherwise why
  // not (AnalyseCoverage's reason, or the coverage reached).
  std::string problem;
};

// The least cost (orientations + kRemountCost x remounts) over candidate lattices of
// kOrientationStepsDeg: per lattice a greedy set cover that adds the candidate seeing most of
// what is still unseen among those overlapping a chosen one, then drops what became redundant.
OrientationPlan PlanOrientations(const OrientationPlanInput& in);

// The plan as luminaire.json's content: orientations o00, o01 ... in datasets of the same
// names, coverage "sphere" / "hemisphere", mount and (with a rotation axis) axis_deg.
LuminaireSet OrientationPlanSet(const OrientationPlanInput& in, const OrientationPlan& plan);

// The table lumislab-plan orientations prints.
std::string OrientationPlanTable(const OrientationPlanInput& in, const OrientationPlan& plan);

}  // namespace lumislab
