// What export reads from a luminaire folder (docs/formats.md §19, "Exports of a luminaire
// folder"): every orientation's complete slab with its pose (registration.json's when the folder
// was registered, else the nominal one with a warning), in one unit, as the merged light field
// of lib/lightfield/merged_far_field.h takes them.
#pragma once

#include <string>
#include <vector>

#include "core/luminaire_set.h"
#include "export/report_uncertainty.h"
#include "lib/lightfield/merged_far_field.h"

namespace lumislab {

struct LuminaireSource {
  LuminaireSet set;
  std::vector<PosedSlab> slabs;  // one per orientation, in luminaire.json's order
  std::string units;             // their common unit (CommonUnits)
  // "6 orientations (o00, ..., o05), registered: corrections up to 1.52 deg (o03), 1-sigma up
  // to 0.012 deg" or "... nominal poses (not registered: ...)": what the files and the report
  // state.
  std::string Orientations() const;
  // "registration.json: o01 correction (rx, ry, rz) deg +- sigma; ..." one line per orientation.
  std::vector<std::string> RegistrationRows() const;
  // The folder holding the analytic luminaire of a synthetic luminaire folder (<folder>/truth).
  std::string TruthDir() const;
};

// Reads the luminaire folder: LoadLuminaireSet, then each orientation's slab, which must be
// complete (RequireCompleteSlab: exit 2 naming it) and whose total light is checked into its own
// dataset's checks.json under `stage`; the units must agree (CommonUnits). An unregistered folder
// is a warning naming the command that registers it: the nominal angles of a hand remount are
// good to a degree or two, which the merge then carries.
LuminaireSource LoadLuminaireSource(const std::string& folder, int threads,
                                    const std::string& stage);

// The orientation that looks along the luminaire's gamma = 0 axis (its capture +z nearest the
// luminaire's +z: the largest R_k(2, 2)): the planes of `irradiance` and the report are its.
size_t FrontOrientation(const LuminaireSet& set);

// The stated uncertainty of a merged far field: the largest (by the flux term) of the
// orientations' (EstimateFarFieldUncertainty of each slab); the registration's and the blend's
// terms are not in it.
FarFieldUncertainty LuminaireUncertainty(const LuminaireSource& source, int samples,
                                         const UncertaintyOptions& options);

// `info` of a luminaire folder, from its files alone (no slab positions read): the coverage
// asked, each orientation (dataset, nominal rotation, registration's correction and 1-sigma, its
// slab's state and unit) and the planner's coverage of the set (AnalyseCoverage of the cones at
// the current poses: the fraction seen, the pairs' overlaps, why it cannot be registered). As
// text, or JSON with `json`.
std::string LuminaireFolderInfo(const std::string& folder, bool json);

// The merged far field of the folder's orientations (ComputeMergedFarField) on a C / gamma grid,
// refused (exit 2 naming the pair, the folder and what to check) when two orientations'
// intensities over the directions both weigh differ by more than kMaxPairScaleDeviation in flux:
// a scale calibration, a slab or a pose that does not belong, which the blend would otherwise
// hide in a wrong total.
MergedFarField MergedFarFieldChecked(const LuminaireSource& source,
                                     const std::vector<double>& c_deg,
                                     const std::vector<double>& gamma_deg,
                                     const FarFieldOptions& options);

// The command that registers `folder` (its registration.json).
std::string RegisterCommand(const std::string& folder);

}  // namespace lumislab
