// The Ceres solver settings the calibrate refiners share (screen/screen_refiner.cc,
// camera/camera_refiner.cc, orientations/registration.cc; of lumislab_calibrate only they
// include Ceres, which compiles slowly): tight tolerances, because the problems are small and
// the parameters feed sub-pixel geometry, and no logging.
#pragma once

#include <ceres/ceres.h>

namespace lumislab {

inline ceres::Solver::Options RefinerSolverOptions(ceres::LinearSolverType linear_solver,
                                                   int max_iterations, int threads) {
  ceres::Solver::Options solver;
  solver.linear_solver_type = linear_solver;
  solver.max_num_iterations = max_iterations;
  solver.num_threads = threads;
  solver.function_tolerance = 1e-14;
  solver.gradient_tolerance = 1e-14;
  solver.parameter_tolerance = 1e-12;
  solver.logging_type = ceres::SILENT;
  return solver;
}

}  // namespace lumislab
