// A tiny synthetic dataset for the reconstruct tests, independent of the acquire stage: a small
// screen, a few grid positions, small photos filled analytically from smooth functions through a
// known (optionally perspective and distorted) ScreenCalibration.
#pragma once

#include <string>
#include <vector>

#include "core/dataset.h"
#include "core/screen_calibration.h"
#include "core/slab.h"

namespace lumislab::testing {

struct SyntheticOptions {
  int nu = 2, nv = 1;
  double spacing_mm = 5;
  double screen_mm = 120;
  int image_px = 480;
  double px_per_mm = 3.0;
  double perspective = 0;    // image_from_screen w = 1 + perspective * x_mm (oblique view)
  double k1 = 0;             // radial distortion of the calibration
  std::string ext = ".exr";  // ".exr" (float) or ".png" (16-bit)
  std::vector<double> exposures = {1.0};
  double amplitude = 0.6;  // peak of the T+ photo at exposure 1 (>= 1 saturates)
  bool write_calibration = true;
  double noise_sigma = 0;  // white Gaussian noise on every photo value (normalised units)
  unsigned noise_seed = 1;
};

struct SyntheticDataset {
  SyntheticOptions options;
  Dataset dataset;
  ScreenCalibration calibration;
  std::string dir;
  int saturated_pixels_total = 0;  // pixels clipped in every exposure of a slide

  // Normalised linear value at exposure 1 of slide p/n, channel c, at lab point (x, y) mm.
  double Photo(int i, int j, bool positive, int c, double x, double y) const;
  // E_ij(s, t) in slab units (W/m^2), luminaire frame.
  double Truth(int i, int j, int c, double s, double t) const;
  // Exact box average of E_ij over the texel [s0, s1] x [t0, t1] (erf of the Gaussians).
  double TruthBox(int i, int j, int c, double s0, double s1, double t0, double t1) const;
  // Writes the photos of one position (atomically); Make writes all unless told otherwise.
  void WritePhotos(int i, int j);
};

SyntheticDataset MakeSyntheticDataset(const std::string& dir, const SyntheticOptions& options,
                                      bool write_photos = true);

// E_ij at the texel centres (3 channels).
ImageF PointTruth(const SyntheticDataset& ds, int i, int j, const SlabLayout& layout);
// What the prescribed fit must return for perfect data: FitBell applied to the exact texel box
// averages, on the seen mask of `p`. The fit matches box averages (flux), so it differs from the
// centre values by -(texel^2 / 24) Laplacian(E): the bell basis's own approximation error.
ImageF ExpectedFit(const SyntheticDataset& ds, int i, int j, const SlabLayout& layout,
                   const SlabPosition& p);
// ||E - ref|| / ||ref|| over texels seen in `p` where |ref| >= 1% of its max, RGB together.
double RelativeL2(const SlabPosition& p, const ImageF& reference);

std::string FreshTestDir(const std::string& name);

}  // namespace lumislab::testing
