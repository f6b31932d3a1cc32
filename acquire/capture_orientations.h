// lumislab-acquire capture --orientations <plan.json> --out <luminaire folder>: a luminaire
// captured from several orientations (docs/formats.md §19, "Capturing orientations in the lab").
// The plan is a luminaire.json (`lumislab-plan orientations` writes one: each orientation's
// nominal pose, its hand mount and its rotation axis angle). For each orientation in order the
// luminaire is brought to it: with a rotation axis in the setup (lab.rotation_axis) the stage
// turns it to axis_deg and the operator is asked only when the mount changes; without one the
// operator is asked to turn it for every orientation. Each orientation is then captured into
// <lum>/<dataset> exactly as a single capture is, the devices staying connected in between.
//
// <lum>/
//   luminaire.json       the orientations complete so far, in the plan's order (written
//                        atomically once each is complete; absent until the first is)
//   o00/, o01/, ...      one dataset folder per orientation (acquire/capture.h); the one being
//                        captured has a partial dataset.json and is not in luminaire.json yet
//   capture/plan.json    the plan the run was started with (a resumed run must give the same)
//   capture/placed       the orientation the luminaire was last brought to (axis moved, operator
//                        confirmed): a resumed run asks again only when it must
//   capture/devices.log  the moves and requests between the datasets (each dataset has its own)
// Resumable: the same command goes on at the first orientation not in luminaire.json, and inside
// it as a single capture does.
#pragma once

#include <string>

#include "acquire/capture.h"
#include "acquire/lab_setup.h"
#include "core/luminaire_set.h"

namespace lumislab {

// The plan at `plan_file` (luminaire.json format; errors name that file and the field).
LuminaireSet LoadOrientationPlan(const std::string& plan_file);

// The plan against the lab, before anything moves; BadInput naming the file and the field:
// every axis_deg within the rotation axis' travel (lab.stage.travel_mm.<axis>), and the
// orientations of one mount that the axis reaches turned from each other about the axis the setup
// names (lab.rotation_axis.about) by the difference of their axis_deg (within
// kPlanAxisToleranceDeg). Without a rotation axis there is nothing to check: the operator turns
// the luminaire.
constexpr double kPlanAxisToleranceDeg = 0.1;
void CheckPlanAgainstLab(const LuminaireSet& plan, const std::string& plan_file,
                         const LabSetup& lab, const std::string& setup_file);

// How the luminaire gets to orientation k: the axis target (none: the operator turns it) and
// whether the operator is asked, given the orientation it was last brought to (-1: none yet, the
// luminaire on the first orientation's mount as the operator put it before the run).
struct OrientationStep {
  std::optional<double> axis_deg;
  bool ask = false;
  std::string action;   // remount or orientation (the operator program's first argument)
  std::string request;  // what the operator reads
};
OrientationStep StepTo(const LuminaireSet& plan, size_t k, int placed, const LabSetup& lab);

// The whole run (RunCapture with options.orientations_file).
CaptureReport RunOrientationsCapture(const CaptureOptions& options);

}  // namespace lumislab
