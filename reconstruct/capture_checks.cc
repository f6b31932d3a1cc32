#include "reconstruct/capture_checks.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>

#include "core/log.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

// brackets.exposure_order: log(estimated ratio) / log(recorded ratio) of consecutive exposures
// (1: the pixels agree with the recorded order and step; -1: the two photos exchanged; about 0:
// the pixels carry no light that tells, e.g. noise above the noise model's floor at an unlit
// position, where the study's noisy bracket point measured -0.002). Below -0.5 the pixels say
// the longer exposure is the darker one by at least half the recorded step.
constexpr double kMinOrderFraction = -0.5;
// brackets.recorded_ratios: reconstruct's advice threshold (reconstruct/photo_merge.h).
constexpr double kRatioWarn = kRatioAdviceAbove;

// slides.sign: a position fails when its light is mostly negative (negative > 2 x positive:
// noise-only positions have both about equal) and its negative flux exceeds this share of the
// brightest position's positive flux. The bound for a legitimate capture: a point source seen
// through the dual filter gives position (i, j) the flux Phi~(u0 - c_ij) times its light, and
// -min Phi~ / max Phi~ over the grid is at most 0.152 (K = 1), 0.160 (K = 2), 0.156 (K = 3) for
// any source position a grid of 2 x 2 or more covers; wider sources mix positions and give
// less. Measured on legitimate captures: up to 0.152 (the hard cases' point sources, randomised
// sweep), 0.033 (the demo scene), 0 (the real-camera, camera-folder, capture, live and watch
// chains); on broken ones: 1.06 (the brightest positions' slides exchanged in dataset.json),
// 1.09 and 30.5 (the demo with one or every position swapped), no positive position at all (a
// stray photo first: every photo one place late).
constexpr double kMaxNegativeShare = 0.5;
constexpr double kNegativeDominance = 2;

// positions.shift: positions compared are lit (magnitude >= 10 % of the brightest's): the
// centroid of a faint position is noise. A neighbour pair warns when the centroid moves against
// the grid by more than this many spacings. Measured: the smallest step on legitimate captures
// -1.12 spacings (a hard-case sweep's point sources under the negative lobes), 2.6 (demo), 31 ...
// 38 (the test scenes); two neighbours exchanged: -41.6 (demo), -31.9 (the test scene).
constexpr double kLitShare = 0.1;

// positions.distinct: a lit neighbour pair whose thumbnails differ (||a - b|| / (||a|| + ||b||))
// by less than this share of the capture's median neighbour pair warns. Measured (the least pair
// over the median): legitimate 0.56 (one emitter 300 mm behind S), 0.78 (the default scene),
// 0.80 (the four-emitter wide scene), 0.83 (15 x 11 at 2 mm), 0.88 - 1 (the test scenes, a
// narrow beam, an emitter off the grid); a position photographed twice with noise, or the same
// photos listed for two positions, 0.034.
constexpr double kDistinctShare = 0.1;
constexpr int kDistinctMinPairs = 4;  // fewer pairs: no median to compare with
constexpr double kMaxBackwardSpacings = 4;
// ... and only where such a jump is isolated: at most this many pairs (or this share of them)
// move against the grid at all. The light of several emitters moves its centroid back and forth
// as one emitter or another dominates the window: a legitimate four-emitter scene (the wide
// study scene, 400 x 300 photos) has 11 of 108 pairs backward, 5 by more than 4 spacings (down
// to -13.4); the default luminaire on a 15 x 11 grid at 2 mm 12 of 216, down to -30.7 spacings.
// Single-emitter and the default scene at 5 mm: none backward. Two neighbours of the default
// scene exchanged: 1 pair, -41.5 spacings.
constexpr int kMaxIsolatedBackward = 2;
// A row whose lit pairs along s (at least this many) all move backward while another row's all
// move forward warns too (every other row reversed: the scan order mistold). The red team's rows
// capture imported as serpentine: rows 1 of 3 reversed; none of the legitimate captures above
// has a whole row backward.
constexpr int kMinRowPairs = 3;
constexpr double kIsolatedShare = 0.02;

std::string PositionName(int i, int j) {
  return "(" + std::to_string(i) + ", " + std::to_string(j) + ")";
}

}  // namespace

PositionLight MeasureLight(const SlabPosition& p, const SlabLayout& layout) {
  PositionLight out;
  out.i = p.i, out.j = p.j;
  double ws = 0, wt = 0;
  for (int row = 0; row < layout.res_y; ++row)
    for (int col = 0; col < layout.res_x; ++col) {
      const size_t k = size_t(row) * layout.res_x + col;
      if (!(p.mask.data[k] > 0)) continue;
      const double e = double(p.irradiance.data[k * 3]) + p.irradiance.data[k * 3 + 1] +
                       p.irradiance.data[k * 3 + 2];
      (e > 0 ? out.positive : out.negative) += std::abs(e);
      const Eigen::Vector2d c = layout.TexelCentre(col, row);
      ws += std::abs(e) * c.x(), wt += std::abs(e) * c.y();
      const int side = PositionLight::kThumbnailSide;
      out.thumbnail[size_t(row * side / layout.res_y) * side + col * side / layout.res_x] += e;
    }
  const double w = out.Magnitude();
  if (w > 0) out.centre_s = ws / w, out.centre_t = wt / w;
  return out;
}

CaptureChecks::CaptureChecks(const Dataset& dataset, CheckLog* log)
    : dataset_(dataset), log_(*log) {}

std::string CaptureChecks::SlidePhotos(int i, int j) const {
  std::string p, n;
  for (const PhotoEntry& e : dataset_.PhotosOf(i, j))
    if ((e.positive ? p : n).empty()) (e.positive ? p : n) = dataset_.PhotoPath(e.file);
  return p + " (slide p) and " + n + " (slide n)";
}

void CaptureChecks::AddPosition(const SlabPosition& position, const SlabLayout& layout,
                                const PositionReport& report) {
  const PositionLight light = MeasureLight(position, layout);
  LogDebug("position ", PositionName(position.i, position.j), ": light ", light.positive, " - ",
           light.negative, ", centroid (", light.centre_s, ", ", light.centre_t, ") mm");
  std::lock_guard<std::mutex> lock(mutex_);
  light_[{position.j, position.i}] = light;
  for (const BracketRatio& b : report.bracket_ratios) {
    if (b.samples == 0) continue;
    ++brackets_;
    // The two photos: the slide's entries at the recorded exposures (stored as float by the
    // merge, hence the tolerance).
    const auto photos = [&] {
      std::pair<std::string, std::string> out;  // shorter, longer
      for (const PhotoEntry& e : dataset_.PhotosOf(position.i, position.j)) {
        if (e.positive != b.positive) continue;
        if (std::abs(e.exposure / b.recorded_short - 1) < 1e-5)
          out.first = dataset_.PhotoPath(e.file);
        if (std::abs(e.exposure / b.recorded_long - 1) < 1e-5)
          out.second = dataset_.PhotoPath(e.file);
      }
      return out;
    };
    // brackets.recorded_ratios: a step whose ratio in the pixels is off the recorded one alike
    // at every brightness (reconstruct's advice, BracketRatio::DeviationIsTheExposures).
    const double deviation = std::abs(b.Deviation());
    if (deviation > kRatioWarn && b.DeviationIsTheExposures()) {
      ++ratios_off_;
      if (deviation > ratio_worst_) {
        const auto [shorter, longer] = photos();
        ratio_worst_ = deviation;
        ratio_where_ = longer + " against " + shorter + ": " + Num(b.estimated, 3) +
                       " in the pixels, " + Num(b.Recorded(), 3) + " recorded";
      }
    }
    const double fraction = std::log(b.estimated) / std::log(b.Recorded());
    if (fraction >= order_fraction_) continue;
    const auto [shorter, longer] = photos();
    order_fraction_ = fraction;
    order_where_ = longer + " (exposure " + Num(b.recorded_long, 3) + ") and " + shorter +
                   " (exposure " + Num(b.recorded_short, 3) + ")";
    if (fraction < kMinOrderFraction)
      log_.Fail("brackets.exposure_order",
                longer + ": exposure: expected values " + Num(b.Recorded(), 3) + "x those of " +
                    shorter + " (recorded " + Num(b.recorded_long, 3) + " against " +
                    Num(b.recorded_short, 3) + "), got " + Num(b.estimated, 3) +
                    "x in the pixels well exposed in both: the longer exposure is the darker "
                    "photo (exposures exchanged in dataset.json, or --exposures in another "
                    "order than the camera took them)",
                {{"position", {position.i, position.j}},
                 {"slide", b.positive ? "p" : "n"},
                 {"recorded_ratio", b.Recorded()},
                 {"estimated_ratio", b.estimated},
                 {"log_ratio_fraction", fraction},
                 {"min_log_ratio_fraction", kMinOrderFraction}});
  }
}

void CaptureChecks::Finish(const std::string& slab_dir, const SlabInfo& info) {
  for (int j = 0; j < dataset_.grid.nv; ++j)
    for (int i = 0; i < dataset_.grid.nu; ++i)
      if (!light_.count({j, i}) && fs::exists(SlabPositionPath(slab_dir, i, j)))
        light_[{j, i}] = MeasureLight(ReadSlabPosition(slab_dir, info, i, j), info.layout);
  if (brackets_ > 0)
    log_.Pass("brackets.exposure_order",
              std::to_string(brackets_) +
                  " bracket step(s): every longer exposure the brighter photo (smallest log "
                  "ratio estimated / recorded " +
                  Num(order_fraction_, 3) + ", " + order_where_ + ")",
              {{"steps", brackets_},
               {"log_ratio_fraction", order_fraction_},
               {"min_log_ratio_fraction", kMinOrderFraction}});
  if (brackets_ > 0) {
    const nlohmann::json values = {{"steps", brackets_},
                                   {"steps_off", ratios_off_},
                                   {"worst_deviation", ratio_worst_},
                                   {"warn_above", kRatioWarn}};
    if (ratios_off_ > 0)
      log_.Warn("brackets.recorded_ratios",
                std::to_string(ratios_off_) + " of " + std::to_string(brackets_) +
                    " bracket step(s) measure an exposure ratio more than " +
                    Num(100 * kRatioWarn, 3) +
                    " % off the recorded one at every brightness (worst " +
                    Num(100 * ratio_worst_, 3) + " %, " + ratio_where_ +
                    "): the recorded exposures are not the camera's (nominal EXIF times, a "
                    "wrong --exposures); --bracket-ratios estimated uses the pixels' ratios",
                values);
    else
      log_.Pass("brackets.recorded_ratios",
                std::to_string(brackets_) +
                    " bracket step(s): no exposure ratio off the "
                    "recorded one by more than " +
                    Num(100 * kRatioWarn, 3) + " % at every brightness",
                values);
  }
  CheckSlideSigns();
  CheckNeighbours();
  CheckDistinct();
  log_.Save();
}

void CaptureChecks::CheckSlideSigns() {
  if (light_.empty()) return;
  double brightest = 0;  // the largest positive flux
  const PositionLight* worst = nullptr;
  double worst_share = 0, total = 0;
  int dominated = 0, swapped = 0;
  for (const auto& [key, l] : light_) {
    brightest = std::max(brightest, l.Flux());
    total += l.Flux();
  }
  for (const auto& [key, l] : light_) {
    if (!(l.negative > kNegativeDominance * l.positive) || l.negative == 0) continue;
    ++dominated;
    const double share = brightest > 0 ? -l.Flux() / brightest : HUGE_VAL;
    swapped += share > kMaxNegativeShare;
    if (!worst || share > worst_share) worst = &l, worst_share = share;
  }
  // (No position with positive light: the share is unbounded, recorded as null.)
  const nlohmann::json shown =
      std::isfinite(worst_share) ? nlohmann::json(worst_share) : nlohmann::json();
  const nlohmann::json values = {{"positions", light_.size()},
                                 {"mostly_negative_positions", dominated},
                                 {"swapped_looking_positions", swapped},
                                 {"largest_negative_share", shown},
                                 {"max_negative_share", kMaxNegativeShare},
                                 {"total_flux", total}};
  if (worst && worst_share > kMaxNegativeShare) {
    const bool all = brightest <= 0;
    const std::string message =
        SlidePhotos(worst->i, worst->j) + ": slides: expected T+ and T- of one light (the " +
        "light through p minus n negative at most " + Num(kMaxNegativeShare, 3) +
        " of the brightest position's), got " +
        (all ? std::string("a negative total at every position")
             : Num(worst_share, 3) + " of it negative at position " +
                   PositionName(worst->i, worst->j)) +
        ": the two slides look swapped" +
        (swapped > 1 ? " (at " + std::to_string(swapped) +
                           " positions: the photo list shifted by one photo, e.g. a stray test "
                           "shot first?)"
                     : std::string(" (p and n exchanged in dataset.json?)"));
    // A grid one position wide does not cover a luminaire across it: light beyond the grid is
    // seen through the filter's negative lobes only, at every position (the hard cases' sweep
    // has such captures), so there the sign cannot tell and is a warning.
    if (dataset_.grid.nu < 2 || dataset_.grid.nv < 2) {
      log_.Warn("slides.sign", message + "; or the light lies beyond a grid one position wide",
                values);
      return;
    }
    log_.Fail("slides.sign", message, values);
  }
  log_.Pass("slides.sign",
            std::to_string(light_.size()) + " position(s): light through p minus n positive (" +
                std::to_string(dominated) + " mostly negative, at most " + Num(worst_share, 3) +
                " of the brightest position's: the filter's negative lobes)",
            values);
}

void CaptureChecks::ForEachLitNeighbourPair(
    const std::function<void(const PositionLight&, const PositionLight&, bool)>& visit) const {
  double lit = 0;
  for (const auto& entry : light_) lit = std::max(lit, entry.second.Magnitude());
  for (const auto& entry : light_) {
    const PositionLight& a = entry.second;
    for (const bool along_i : {true, false}) {
      const auto it =
          light_.find(along_i ? std::make_pair(a.j, a.i + 1) : std::make_pair(a.j + 1, a.i));
      if (it == light_.end()) continue;
      const PositionLight& b = it->second;
      if (a.Magnitude() < kLitShare * lit || b.Magnitude() < kLitShare * lit) continue;
      visit(a, b, along_i);
    }
  }
}

void CaptureChecks::CheckNeighbours() {
  const double h = dataset_.grid.spacing_mm;
  int pairs = 0;
  double least = HUGE_VAL;  // the smallest centroid step, in spacings
  std::string least_where;
  std::vector<std::string> backward;
  int any_backward = 0;                     // pairs whose centroid moves against the grid at all
  std::map<int, std::pair<int, int>> rows;  // per row j: lit pairs along s, those backward
  ForEachLitNeighbourPair([&](const PositionLight& a, const PositionLight& b, bool along_i) {
    ++pairs;
    const double step = (along_i ? b.centre_s - a.centre_s : b.centre_t - a.centre_t) / h;
    LogDebug("positions.shift: ", PositionName(a.i, a.j), " -> ", PositionName(b.i, b.j), " ", step,
             " spacings");
    if (step < 0) ++any_backward;
    if (along_i) {
      auto& row = rows[a.j];
      ++row.first;
      if (step < 0) ++row.second;
    }
    const std::string where = PositionName(a.i, a.j) + " -> " + PositionName(b.i, b.j);
    if (step < least) least = step, least_where = where;
    if (step < -kMaxBackwardSpacings)
      backward.push_back(where + " (" + Num(step, 3) + " spacings along " + (along_i ? "s" : "t") +
                         ")");
  });
  if (pairs == 0) return;
  const int isolated = std::max(kMaxIsolatedBackward, int(kIsolatedShare * pairs));
  const nlohmann::json values = {{"pairs", pairs},
                                 {"smallest_step_spacings", least},
                                 {"min_step_spacings", -kMaxBackwardSpacings},
                                 {"pairs_backward", any_backward},
                                 {"max_pairs_backward", isolated}};
  // Whole rows backward while others run forward: the rows were scanned the other way than the
  // import was told (rows against serpentine), every other row's photos reversed.
  std::vector<int> reversed;
  int forward_rows = 0;
  for (const auto& [j, row] : rows) {
    if (row.first < kMinRowPairs) continue;
    if (row.second == row.first) reversed.push_back(j);
    if (row.second == 0) ++forward_rows;
  }
  if (!reversed.empty() && forward_rows > 0) {
    std::string list;
    for (size_t k = 0; k < reversed.size(); ++k)
      list += (k ? ", " : "") + std::to_string(reversed[k]);
    log_.Warn("positions.shift",
              dataset_.Path("dataset.json") + ": photos: in row(s) j = " + list +
                  " the light moves against the grid at every lit pair, in " +
                  std::to_string(forward_rows) +
                  " other row(s) with it: the rows were scanned the other way than the import "
                  "was told (--scan rows against serpentine)?",
              values);
    return;
  }
  if (!backward.empty() && any_backward <= isolated) {
    std::string list;
    for (size_t k = 0; k < backward.size() && k < 4; ++k) list += (k ? ", " : "") + backward[k];
    if (backward.size() > 4) list += " and " + std::to_string(backward.size() - 4) + " more";
    log_.Warn("positions.shift",
              dataset_.Path("dataset.json") +
                  ": photos: the light's centroid on the screen moves against the grid at " +
                  std::to_string(backward.size()) + " of " + std::to_string(pairs) +
                  " neighbour pairs: " + list +
                  "; photos of another position (the list shifted or positions exchanged)? "
                  "(a converging luminaire does this too)",
              values);
    return;
  }
  log_.Pass(
      "positions.shift",
      std::to_string(pairs) + " lit neighbour pairs: " +
          (backward.empty() ? std::string("the light moves with the grid")
                            : std::to_string(any_backward) +
                                  " move against the grid, as the light of several emitters does") +
          " (smallest step " + Num(least, 3) + " spacings, " + least_where + ")",
      values);
}

void CaptureChecks::CheckDistinct() {
  struct Pair {
    const PositionLight *a, *b;
    double difference;
  };
  std::vector<Pair> pairs;
  ForEachLitNeighbourPair([&](const PositionLight& a, const PositionLight& b, bool) {
    double diff = 0, norm_a = 0, norm_b = 0;
    for (size_t k = 0; k < a.thumbnail.size(); ++k) {
      diff += (a.thumbnail[k] - b.thumbnail[k]) * (a.thumbnail[k] - b.thumbnail[k]);
      norm_a += a.thumbnail[k] * a.thumbnail[k], norm_b += b.thumbnail[k] * b.thumbnail[k];
    }
    pairs.push_back({&a, &b, std::sqrt(diff) / (std::sqrt(norm_a) + std::sqrt(norm_b))});
  });
  if (int(pairs.size()) < kDistinctMinPairs) return;
  std::vector<double> d;
  for (const Pair& p : pairs) d.push_back(p.difference);
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  const double median = d[d.size() / 2];
  const Pair* least =
      &*std::min_element(pairs.begin(), pairs.end(),
                         [](const Pair& x, const Pair& y) { return x.difference < y.difference; });
  const double share = median > 0 ? least->difference / median : 1;
  const nlohmann::json values = {{"pairs", pairs.size()},
                                 {"median_difference", median},
                                 {"least_difference", least->difference},
                                 {"least_share_of_median", share},
                                 {"warn_below_share", kDistinctShare}};
  const std::string where = "positions " + PositionName(least->a->i, least->a->j) + " (" +
                            SlidePhotos(least->a->i, least->a->j) + ") and " +
                            PositionName(least->b->i, least->b->j) + " (" +
                            SlidePhotos(least->b->i, least->b->j) + ")";
  if (share < kDistinctShare) {
    log_.Warn("positions.distinct",
              dataset_.Path("dataset.json") + ": photos: " + where + " differ by " +
                  Num(100 * share, 3) +
                  " % of the capture's median neighbour pair: the same "
                  "position photographed twice (and the next one missed)?",
              values);
    return;
  }
  log_.Pass("positions.distinct",
            std::to_string(pairs.size()) + " lit neighbour pairs differ (the least " +
                Num(100 * share, 3) + " % of the median, " +
                PositionName(least->a->i, least->a->j) + " and " +
                PositionName(least->b->i, least->b->j) + ")",
            values);
}

}  // namespace lumislab
