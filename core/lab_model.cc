#include "core/lab_model.h"

#include "core/command_line.h"
#include "core/log.h"

namespace lumislab {

std::string LabModel::Describe() const {
  return Num(move_s) + " s move + " + std::to_string(slides) + " slides x " +
         std::to_string(brackets) + " bracket(s) x " + Num(exposure_s) + " s";
}

void AddLabModelOptions(CLI::App* app, LabModel* model, bool brackets_option) {
  app->add_option("--move-s", model->move_s, "lab model: stage move and settle per position, s")
      ->check(FiniteIn(0, 1e6))
      ->capture_default_str();
  app->add_option("--exposure-s", model->exposure_s, "lab model: one exposure with readout, s")
      ->check(FiniteIn(0, 1e6))
      ->capture_default_str();
  app->add_option("--slides", model->slides, "lab model: slides per position")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  if (brackets_option)
    app->add_option("--brackets", model->brackets, "lab model: exposures per slide")
        ->check(CLI::Range(1, 100))
        ->capture_default_str();
}

}  // namespace lumislab
