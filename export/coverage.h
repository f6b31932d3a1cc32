// Which directions of an exported file the capture saw, and how much light a model of the
// luminaire puts in the others (docs/formats.md §17, "Coverage"). The far field's `seen` mask
// says which grid directions the screen saw; a file claims its whole grid, so the unseen ones
// (written as 0) are light missing from the file unless the luminaire sends none there.
// `ies`, `ldt` and `tm25` refuse such a file unless --allow-partial, which states the coverage in
// it (IES [_COVERAGE], EULUMDAT's measurement report field, TM-25 additional_info).
#pragma once

#include <string>
#include <vector>

#include "core/slab.h"
#include "lib/lightfield/far_field.h"
#include "lib/photometry/intensity_distribution.h"

namespace lumislab {

struct Coverage {
  size_t directions = 0;  // grid directions of the file
  size_t unseen = 0;      // of which the capture did not see (written as 0)
  // Per C plane of the grid: the largest gamma up to which every grid gamma was seen (degrees;
  // -1: not even gamma 0).
  std::vector<double> seen_gamma_max_deg;
  std::vector<double> c_deg;
  // The model's share of the flux in the unseen grid directions (0..1), and what the model is.
  double model_unseen_share = 0;
  bool analytic = false;  // the synthetic luminaire of truth/ (else a stated Lambertian model)
  std::string model;      // in words
  double model_flux = 0;  // the model's total flux over the grid (slab units: lm or W)
  // Every grid direction seen, but the cells around them reach directions the capture did not
  // see (the share and the cone then come from a fine grid; cli_formats.cc CheckCells).
  bool cells_beyond_cone = false;

  bool Partial() const { return (unseen > 0 || cells_beyond_cone) && model_unseen_share > 0; }
  // "gamma 0-37.5 deg seen (37.5 in C 0, 47.5 in C 45, ...)": the seen cone.
  std::string SeenCone() const;
  // The full statement: seen cone, unseen count and share, the model's share of the flux there.
  std::string Text() const;
  // The same in about 50 characters (EULUMDAT's 78-byte text fields, after the report number):
  // "partial g<=37.5: unseen 54.2% dirs, 22.6% flux (truth)".
  std::string Short() const;
};

// The coverage of the grid of `d` by the far field `ff` (computed on the same grid), with the
// model's flux there: the analytic luminaire of `slab_dir`/../truth/luminaire.json when the slab
// is a synthetic dataset's (point emitters; lm = K x W for a lux slab, K the dataset's lux
// meter's, truth/reference.json luminous_efficacy_lm_w, else DefaultLuminousEfficacy()), else a
// Lambertian emitter, I = I0 cos(gamma) for gamma < 90, matched to the seen flux (a model: the
// capture cannot say what it did not see).
Coverage GridCoverage(const IntensityDistribution& d, const FarField& ff, const SlabInfo& info,
                      const std::string& slab_dir);

// The same with the analytic luminaire looked for in `truth_dir` (luminaire.json, reference.json
// with the lux meter's K): a luminaire folder's <folder>/truth, in the luminaire frame. Without
// one, the model of a luminaire folder (`isotropic_model`) is an isotropic emitter matched to the
// seen flux: a luminaire measured from several orientations is one whose light goes beyond a
// hemisphere, so directions no orientation saw count as missing light.
Coverage GridCoverageWithTruth(const IntensityDistribution& d, const FarField& ff,
                               const SlabInfo& info, const std::string& truth_dir,
                               bool isotropic_model = false);

// True when `slab_dir` belongs to a synthetic dataset (truth/luminaire.json beside it).
bool SyntheticSlab(const std::string& slab_dir);

}  // namespace lumislab
