// The photos of a capture checked against each other while reconstruct reads them
// (docs/verifies.md, "The photos of a capture"), recorded in <dataset>/checks.json under the
// stage "reconstruct" (core/checks.h):
//
//  * brackets.exposure_order: within a slide's bracket the longer recorded exposure has the
//    larger values at the pixels well exposed in both (the ratio the merge estimates from the
//    pixels, reconstruct/bracket_ratios.h); a bracket whose pixels say the other order is
//    exit 2, naming the two photos.
//  * brackets.recorded_ratios: the steps whose ratio in the pixels is off the recorded one by
//    more than kRatioAdviceAbove alike at every brightness (the exposures are not the camera's):
//    a warning naming the worst step's photos, the advice of --bracket-ratios estimated.
//  * slides.sign: the two slides of a position are T+ and T- of the same light (docs/method.md
//    §2.5), so E = peak (E+ - E-) summed over the screen is the light through Phi~_ij: positive
//    at the positions that carry the luminaire's light, negative only under the filter's
//    negative lobes, and there at most 0.16 of the brightest position's. A position whose light
//    is mostly negative and more than 0.5 of that is exit 2, naming its two photos: the slides
//    look swapped (in dataset.json, or every photo shifted by one in the import). A grid one
//    position wide cannot tell (light beyond it is negative everywhere): a warning there.
//  * positions.distinct: neighbouring positions see the light through different filter
//    centres, so their slab images differ; a lit neighbour pair whose images differ by far less
//    than the capture's typical neighbour pair (a tenth of the median) is a warning: the same
//    position photographed twice (and the next one missed), or its photos listed twice. (Not
//    an error even for the same photo files twice: each position's slab image is in the
//    luminaire's frame, so the same photos give images shifted by a spacing, not equal ones.)
//  * positions.shift: neighbouring positions see shifted copies of one light field, to first
//    order: the light through a filter centre c lands around c + d tan(its direction), so its
//    centroid on the screen (luminaire frame) moves with the grid index. A neighbour pair whose
//    centroid moves against the grid by more than 4 spacings, in a capture where such pairs are
//    isolated (at most 2, or 2 % of the pairs, move backward at all: the light of several
//    emitters moves back and forth legitimately), is a warning (photos of another position?). (A
//    list shifted by a whole position shows only where the scan wraps, and only where those
//    positions are lit.)
#pragma once

#include <array>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <utility>

#include "core/checks.h"
#include "core/dataset.h"
#include "core/slab.h"
#include "reconstruct/reconstructor.h"

namespace lumislab {

// The light of one position's slab image, over its seen texels, channels summed.
struct PositionLight {
  int i = 0, j = 0;
  double positive = 0, negative = 0;  // sums of E above 0 and of -E below 0 (E x texels)
  double centre_s = 0, centre_t = 0;  // mm, luminaire frame: the |E|-weighted centroid
  // E (channels summed, seen texels) summed over kThumbnailSide x kThumbnailSide cells of the
  // slab image: what positions.distinct compares between neighbours.
  static constexpr int kThumbnailSide = 16;
  std::array<double, kThumbnailSide * kThumbnailSide> thumbnail{};
  double Flux() const { return positive - negative; }
  double Magnitude() const { return positive + negative; }
};
PositionLight MeasureLight(const SlabPosition& position, const SlabLayout& layout);

class CaptureChecks {
 public:
  // Records into `log` (the run's, shared with reconstruct's other checks), which outlives this.
  CaptureChecks(const Dataset& dataset, CheckLog* log);
  // One position reconstructed (from any thread): its brackets' order checked at once (exit 2
  // naming the photos), its light kept for Finish.
  void AddPosition(const SlabPosition& position, const SlabLayout& layout,
                   const PositionReport& report);
  // The positions of `slab_dir` that an earlier run reconstructed read back (so that a run
  // resumed after a failure checks them again), slides.sign and positions.shift over all
  // positions, and the record saved.
  void Finish(const std::string& slab_dir, const SlabInfo& info);

 private:
  void CheckSlideSigns();
  void CheckNeighbours();
  void CheckDistinct();
  // Calls visit(a, b, along_i) for every neighbour pair (b one step along i or along j from a)
  // whose two positions are lit (magnitude >= kLitShare of the brightest).
  void ForEachLitNeighbourPair(
      const std::function<void(const PositionLight&, const PositionLight&, bool)>& visit) const;
  std::string SlidePhotos(int i, int j) const;  // "<p photo> and <n photo>"

  const Dataset& dataset_;
  CheckLog& log_;
  std::mutex mutex_;
  std::map<std::pair<int, int>, PositionLight> light_;  // (j, i): grid order
  // brackets.exposure_order: the smallest log(estimated) / log(recorded) ratio met, where.
  double order_fraction_ = 1e300;
  std::string order_where_;
  int brackets_ = 0;
  // brackets.recorded_ratios: steps whose ratio is off the recorded one, the worst, where.
  int ratios_off_ = 0;
  double ratio_worst_ = 0;
  std::string ratio_where_;
};

}  // namespace lumislab
