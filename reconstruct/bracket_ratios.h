// The exposure ratios between the brackets of a slide, estimated from the pixels
// (BracketRatios::kEstimated, reconstruct/photo_merge.h), and the effective exposures they give.
#pragma once

#include <vector>

#include "reconstruct/merge_exposure.h"
#include "reconstruct/photo_merge.h"

namespace lumislab::merge {

// The ratio of each slide's consecutive exposures (shortest first): the median of the ratios of
// the values well above the near-black floor (4 x Exposure::floor_u) in both, on a grid of at
// most ~2^18 of the w x h pixels; the recorded ratio where fewer than kMinRatioSamples are.
std::vector<BracketRatio> EstimateRatios(std::vector<Exposure>& exposures, int w, int h);

// Effective exposures from the estimated ratios: the middle exposure of each slide (the lower
// of the two middle ones) keeps its recorded value, the others are chained from it.
void ApplyRatios(std::vector<Exposure>& exposures, const std::vector<BracketRatio>& ratios);

}  // namespace lumislab::merge
