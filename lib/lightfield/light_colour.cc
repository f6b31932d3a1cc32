#include "lib/lightfield/light_colour.h"

#include <limits>

namespace lumislab {

LightColour TotalLightColour(const SlabInfo& info, const std::vector<SlabPosition>& positions,
                             const ColourCalibration& calibration) {
  LightColour c;
  for (int r = 0; r < 3; ++r)
    c.xyz[r] = MeasureSlabLight(info, positions, calibration.rgb_to_xyz.row(r).transpose()).total;
  c.xy = XyzToXy(c.xyz);
  c.cct = CctFromXy(c.xy);
  return c;
}

FarFieldColour ComputeFarFieldColour(const SlabInfo& info,
                                     const std::vector<SlabPosition>& positions,
                                     const std::vector<double>& c_deg,
                                     const std::vector<double>& gamma_deg,
                                     const ColourCalibration& calibration,
                                     FarFieldOptions options) {
  FarField xyz[3];
  for (int r = 0; r < 3; ++r) {
    options.channel_weights = calibration.rgb_to_xyz.row(r).transpose();
    xyz[r] = ComputeFarField(info, positions, c_deg, gamma_deg, options);
  }
  FarFieldColour out;
  out.c_deg = c_deg;
  out.gamma_deg = gamma_deg;
  out.seen = xyz[1].seen;
  out.colour.resize(xyz[1].values.size());
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  for (size_t k = 0; k < out.colour.size(); ++k) {
    LightColour& c = out.colour[k];
    if (!out.seen[k]) {
      c.xyz.setConstant(kNaN);
      c.xy.setConstant(kNaN);
      c.cct = {kNaN, kNaN};
      continue;
    }
    c.xyz = {xyz[0].values[k], xyz[1].values[k], xyz[2].values[k]};
    c.xy = XyzToXy(c.xyz);
    c.cct = CctFromXy(c.xy);
  }
  return out;
}

}  // namespace lumislab
