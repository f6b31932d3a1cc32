// The colour of a slab's light (docs/method.md, "Colour"): chromaticity and CCT of the total
// light and of the far field per direction, through the camera's colour calibration
// (calib/colour.json, lib/photometry/colour.h). For the lab report and `export info`.
#pragma once

#include <vector>

#include "lib/lightfield/far_field.h"
#include "lib/photometry/colour.h"

namespace lumislab {

// XYZ of the slab's total light: each row of rgb_to_xyz as the channel weights of the sum over
// positions and seen texels of E dA (MeasureSlabLight), so X, Y, Z are in the slab's flux units
// times the matrix's scale; xy and CCT do not depend on that scale.
LightColour TotalLightColour(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                             const ColourCalibration& calibration);

// The far field's colour per direction: ComputeFarField with each row of rgb_to_xyz as
// options.channel_weights (X, Y, Z intensities), then xy and CCT. Directions the capture did not
// see (seen 0) get NaN, and so does the chromaticity of a direction whose X + Y + Z <= 0 (the dual
// filter's negative lobes can leave a little negative light at a small grid's edge).
struct FarFieldColour {
  std::vector<double> c_deg, gamma_deg;
  std::vector<LightColour> colour;  // colour[ic * gamma_deg.size() + ig]
  std::vector<uint8_t> seen;
};
FarFieldColour ComputeFarFieldColour(const SlabInfo& info,
                                     const std::vector<SlabPosition>& positions,
                                     const std::vector<double>& c_deg,
                                     const std::vector<double>& gamma_deg,
                                     const ColourCalibration& calibration,
                                     FarFieldOptions options = {});

}  // namespace lumislab
