// The invariants of an accepted far-field distribution, shared by fuzz_ies and fuzz_eulumdat
// (compiled into both: fuzz/CMakeLists.txt).
#pragma once

#include <string>

#include "fuzz/fuzz_util.h"
#include "lib/photometry/intensity_distribution.h"

namespace lumislab::fuzz {

// A finite total flux >= 0, and Intensity() finite, >= 0 and at most the largest stored value
// towards every direction of a 7.5 x 2.5 degree grid (C beyond 0-360 included).
void CheckDistribution(const IntensityDistribution& d, const std::string& format);
// `back`, what a writer made of `d` and its reader read: the same gamma angles, the same C
// planes (an asymmetric grid that ends at 360 may lose its 360 plane, which repeats 0), and the
// same total flux (the writers print 7-8 significant digits).
void CheckSameDistribution(const IntensityDistribution& d, const IntensityDistribution& back,
                           const std::string& format);

}  // namespace lumislab::fuzz
