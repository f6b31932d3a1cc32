// The far field's light and its check ("farfield.total_light", "farfield.negative_share";
// docs/verifies.md, "Slabs and exports"): the far field of a legitimate slab dips below 0 only
// where the dual filter rings; one whose negative directions hold a large share of |I| dOmega is
// written with those directions clipped to 0, far from what the photos meant.
#pragma once

#include <string>

#include "core/checks.h"
#include "core/slab_light.h"
#include "lib/lightfield/far_field.h"

namespace lumislab {

// The same of a far field: the signed integral of I over the seen directions (I dOmega, W; lm
// for lux slabs) and the share of |I| dOmega the negative directions hold.
SlabLight MeasureFarFieldLight(const FarField& far);

// Checks "farfield.negative_share" (a warning above kMaxFarFieldNegativeShare: the file written
// clips those directions to 0) and "farfield.total_light" (JudgeTotalLight).
SlabLight CheckFarFieldLight(const FarField& far, const SlabInfo& info, const std::string& slab_dir,
                             CheckLog& checks);

}  // namespace lumislab
