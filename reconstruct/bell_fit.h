// Regularised least-squares fit of box-averaged texel data onto the bell basis (docs/method.md §3).
//
// Every texel of the slab carries one bell function centred on it (in texel units). The box
// average of the bell field over a texel is b = B c, B = Bx (x) By with the 1D stencil
// [w1, w0, w1] = [1/12, 5/6, 1/12] (BellIntegral over the texel and its neighbours). Only seen
// texels are unknowns; where a neighbour is not seen (or lies outside the window) its coefficient
// is taken equal to the texel's own (a Neumann boundary), so constants are reproduced exactly
// everywhere and each 1D factor has eigenvalues in [w0 - 2 w1, 1] = [2/3, 1]: B^T B >= 0.19.
// We solve (B^T B + lambda D^T D) c = B^T b over the seen texels, D = first differences between
// seen neighbours, by Jacobi-preconditioned conjugate gradients started at c = b.
#pragma once

#include <vector>

namespace lumislab {

struct BellStencil {
  double w0 = 0;                   // box average of phi over its own texel (5/6)
  double w1 = 0;                   // box average of phi over a neighbouring texel (1/12)
  static BellStencil FromBasis();  // computed with core BellIntegral
};

struct BellFitOptions {
  double lambda = 1e-4;     // weight of D^T D relative to B^T B (whose diagonal is ~0.5)
  int max_iterations = 60;  // CG converges in ~10-20 (condition number <= ~5)
  double tolerance = 1e-6;  // on ||residual|| / ||B^T b|| per channel (output is float)
};

struct BellFitReport {
  int iterations = 0;            // largest over the channels
  double relative_residual = 0;  // largest over the channels
};

// A width x height grid of texels with `channels` interleaved channels (row-major).
// `seen` has width*height entries (nonzero = seen). Unseen texels come out as 0.
// data: box-averaged values b; returns the coefficients c (= values at the texel centres).
std::vector<double> FitBell(const std::vector<double>& data, const std::vector<unsigned char>& seen,
                            int width, int height, int channels, const BellFitOptions& options,
                            BellFitReport* report = nullptr);

// b = B c over the seen texels (unseen -> 0), the forward model of the fit; for tests and noise
// studies.
std::vector<double> ApplyBellBoxOperator(const std::vector<double>& coefficients,
                                         const std::vector<unsigned char>& seen, int width,
                                         int height, int channels);

}  // namespace lumislab
