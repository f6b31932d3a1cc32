// The lab's time for a capture (docs/method.md §4.7, §4.8): every grid position costs one stage
// move and settle, then for each slide (T+, T-) one exposure per bracket,
//   seconds = positions x (move + slides x brackets x exposure).
// One model for lumislab-study (which measures what a setting costs) and lumislab-plan (which
// recommends one), with its constants as the same command-line flags in both.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace lumislab {

struct LabModel {
  double move_s = 2.0;      // stage move and settle per position, s
  double exposure_s = 0.5;  // one exposure with readout, s
  int slides = 2;           // slides per position (T+ and T-)
  int brackets = 1;         // exposures per slide

  // positions x (move + slides x brackets x exposure), s.
  double Seconds(int positions) const {
    return positions * (move_s + slides * brackets * exposure_s);
  }
  // "2 s move + 2 slides x 1 bracket(s) x 0.5 s", for reports and logs.
  std::string Describe() const;
};

// Registers --move-s, --exposure-s, --slides and, when `brackets_option`, --brackets (the study
// takes the brackets from its scene instead), bound to `model`, defaults shown.
void AddLabModelOptions(CLI::App* app, LabModel* model, bool brackets_option);

}  // namespace lumislab
