// The `orientations` subcommand of lumislab-calibrate: registers the orientations of a luminaire
// folder (docs/formats.md §19) from their slabs' overlaps -> <lum>/registration.json.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "calibrate/orientations/registration.h"
#include "core/command_line.h"

namespace lumislab {

struct OrientationsCommand {
  CLI::App* sub = nullptr;  // set by AddOrientationsCommand
  std::string luminaire;    // the luminaire folder
  bool force = false;
  RegistrationOptions options;
};

void AddOrientationsCommand(CLI::App* app, CommonOptions* common, OrientationsCommand* command);
// Reads luminaire.json and every orientation's slab, refuses (exit 2) a set the planner's
// coverage analysis cannot register or whose overlaps disagree after the fit (naming the pair),
// prints the table and writes registration.json.
int RunOrientationsCommand(OrientationsCommand* command, int threads);

// The file's text (schema 1, docs/formats.md §19 "registration.json").
std::string RegistrationJson(const LuminaireSet& set, const Registration& registration,
                             const RegistrationOptions& options);

}  // namespace lumislab
