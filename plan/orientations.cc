#include "plan/orientations.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>

#include "core/geometry.h"
#include "core/parallel.h"

namespace lumislab {
namespace {

// The search's own sampling of the sphere: coarser than AnalyseCoverage's, held as bitsets so
// that a greedy step over hundreds of candidates costs word operations. AnalyseCoverage gives
// the verdict on the set the search proposes.
constexpr int kSearchSamples = 6000;

using Bits = std::vector<uint64_t>;

// AnalyseCoverage's default sampling, named for the calls that pass names.
constexpr int kCoverageSamples = 20000;

std::string OrientationName(size_t k) {
  char name[32];
  std::snprintf(name, sizeof name, "o%02zu", k);
  return name;
}

int Count(const Bits& a) {
  int n = 0;
  for (uint64_t w : a) n += __builtin_popcountll(w);
  return n;
}
int CountAnd(const Bits& a, const Bits& b) {
  int n = 0;
  for (size_t k = 0; k < a.size(); ++k) n += __builtin_popcountll(a[k] & b[k]);
  return n;
}
int CountAndNot(const Bits& a, const Bits& b) {
  int n = 0;
  for (size_t k = 0; k < a.size(); ++k) n += __builtin_popcountll(a[k] & ~b[k]);
  return n;
}
void Or(Bits* a, const Bits& b) {
  for (size_t k = 0; k < a->size(); ++k) (*a)[k] |= b[k];
}

// Luminaire-frame directions of the region to cover (a Fibonacci sphere, z >= 0 only for a
// hemisphere) and the solid angle each stands for.
struct Samples {
  std::vector<Eigen::Vector3d> w;
  double sr_each = 0;
};
Samples SearchSamples(bool hemisphere) {
  Samples s;
  const double golden = kPi * (3 - std::sqrt(5.0));
  for (int k = 0; k < kSearchSamples; ++k) {
    const double z = 1 - (k + 0.5) * 2.0 / kSearchSamples;
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    const Eigen::Vector3d w(r * std::cos(golden * k), r * std::sin(golden * k), z);
    if (!hemisphere || z >= 0) s.w.push_back(w);
  }
  s.sr_each = 4 * kPi / kSearchSamples;
  return s;
}

struct Candidate {
  PlannedOrientation pose;
  Bits seen;  // samples with margin > 0
};

Eigen::Matrix3d AxisMountRotation(double axis_deg, double tilt_deg) {
  return RotationZyxDegrees({0, axis_deg, 0}) * RotationZyxDegrees({tilt_deg, 0, 0});
}

// The turns of one lattice: tilts and axis angles multiples of step (axis angles in
// (-180, 180]); the identity first.
std::vector<Candidate> Candidates(const OrientationPlanInput& in, const Samples& samples, int step,
                                  int threads) {
  std::vector<Candidate> out;
  for (int tilt = 0; tilt < 360; tilt += step)
    for (int a = 0; a < 360; a += step) {
      Candidate c;
      c.pose.mount_tilt_deg = tilt > 180 ? tilt - 360 : tilt;
      c.pose.axis_deg = a > 180 ? a - 360 : a;
      c.pose.rotation = AxisMountRotation(c.pose.axis_deg, c.pose.mount_tilt_deg);
      out.push_back(std::move(c));
    }
  const size_t words = (samples.w.size() + 63) / 64;
  ParallelFor(int(out.size()), threads, [&](int q) {
    Candidate& c = out[size_t(q)];
    c.seen.assign(words, 0);
    for (size_t k = 0; k < samples.w.size(); ++k)
      if (in.cone.MarginDeg(c.pose.rotation * samples.w[k]) > 0)
        c.seen[k / 64] |= uint64_t(1) << (k % 64);
  });
  return out;
}

// True when every chosen candidate connects to the first through pairs that overlap by at least
// the planned margin.
bool Connected(const std::vector<const Candidate*>& set, int min_common) {
  std::vector<bool> reached(set.size(), false);
  std::vector<size_t> queue{0};
  reached[0] = true;
  while (!queue.empty()) {
    const size_t a = queue.back();
    queue.pop_back();
    for (size_t b = 0; b < set.size(); ++b)
      if (!reached[b] && CountAnd(set[a]->seen, set[b]->seen) >= min_common) {
        reached[b] = true;
        queue.push_back(b);
      }
  }
  return std::all_of(reached.begin(), reached.end(), [](bool r) { return r; });
}

int MountCount(const std::vector<const Candidate*>& set, bool rotation_axis) {
  if (!rotation_axis) return int(set.size());
  std::vector<double> tilts;
  for (const Candidate* c : set)
    if (std::find(tilts.begin(), tilts.end(), c->pose.mount_tilt_deg) == tilts.end())
      tilts.push_back(c->pose.mount_tilt_deg);
  return int(tilts.size());
}

std::vector<Eigen::Matrix3d> Rotations(const std::vector<PlannedOrientation>& set) {
  std::vector<Eigen::Matrix3d> r;
  for (const PlannedOrientation& o : set) r.push_back(o.rotation);
  return r;
}

std::string CoveragePercent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f %%", 100 * fraction);
  return buf;
}

void DropRedundant(std::vector<const Candidate*>* chosen, int needed, int min_common);
void SwapTwoForOne(const std::vector<Candidate>& candidates, const Bits& covered, int min_common,
                   std::vector<const Candidate*>* chosen);

// Greedy set cover over one lattice's candidates. `stall` is set to the candidate that would
// add most while overlapping no chosen one enough, when the cover stops short.
std::vector<const Candidate*> GreedyCover(const std::vector<Candidate>& candidates, int needed,
                                          int min_common, bool rotation_axis, int max_count,
                                          const Candidate** stall) {
  std::vector<const Candidate*> chosen{&candidates[0]};
  Bits covered = candidates[0].seen;
  std::vector<double> tilts{candidates[0].pose.mount_tilt_deg};
  *stall = nullptr;
  while (Count(covered) < needed && int(chosen.size()) < max_count) {
    const Candidate* best = nullptr;
    int best_gain = 0, best_unconnected_gain = 0;
    bool best_same_mount = false;
    for (const Candidate& c : candidates) {
      const int gain = CountAndNot(c.seen, covered);
      if (gain == 0) continue;
      const bool connected = std::any_of(chosen.begin(), chosen.end(), [&](const Candidate* o) {
        return CountAnd(c.seen, o->seen) >= min_common;
      });
      if (!connected) {
        if (gain > best_unconnected_gain) {
          best_unconnected_gain = gain;
          *stall = &c;
        }
        continue;
      }
      // Most new directions; among equals a mount already in use (fewer remounts).
      const bool same_mount = !rotation_axis || std::find(tilts.begin(), tilts.end(),
                                                          c.pose.mount_tilt_deg) != tilts.end();
      if (gain > best_gain || (gain == best_gain && same_mount && !best_same_mount)) {
        best = &c;
        best_gain = gain;
        best_same_mount = same_mount;
      }
    }
    if (!best) return chosen;
    *stall = nullptr;
    chosen.push_back(best);
    Or(&covered, best->seen);
    tilts.push_back(best->pose.mount_tilt_deg);
  }
  DropRedundant(&chosen, needed, min_common);
  SwapTwoForOne(candidates, covered, min_common, &chosen);
  return chosen;
}

// Two for one: where one candidate sees all that two chosen ones alone saw and keeps the set
// connected, it replaces them (the greedy's early choices are often improved so), until no such
// swap is left. The first orientation stays.
void SwapTwoForOne(const std::vector<Candidate>& candidates, const Bits& covered, int min_common,
                   std::vector<const Candidate*>* chosen_set) {
  std::vector<const Candidate*>& chosen = *chosen_set;
  for (bool improved = true; improved && chosen.size() > 2;) {
    improved = false;
    for (size_t i = 1; i < chosen.size() && !improved; ++i)
      for (size_t j = i + 1; j < chosen.size() && !improved; ++j) {
        std::vector<const Candidate*> rest;
        for (size_t k = 0; k < chosen.size(); ++k)
          if (k != i && k != j) rest.push_back(chosen[k]);
        Bits unseen = covered;
        for (const Candidate* c : rest)
          for (size_t w = 0; w < unseen.size(); ++w) unseen[w] &= ~c->seen[w];
        for (const Candidate& c : candidates) {
          if (CountAndNot(unseen, c.seen) > 0) continue;
          rest.push_back(&c);
          if (Connected(rest, min_common)) {
            chosen = rest;
            improved = true;
            break;
          }
          rest.pop_back();
        }
      }
  }
}

// Drops, latest first, what the others cover without breaking the connection.
void DropRedundant(std::vector<const Candidate*>* chosen_set, int needed, int min_common) {
  std::vector<const Candidate*>& chosen = *chosen_set;
  Bits covered(chosen[0]->seen.size(), 0);
  for (const Candidate* c : chosen) Or(&covered, c->seen);
  for (size_t k = chosen.size(); k-- > 1;) {
    std::vector<const Candidate*> rest = chosen;
    rest.erase(rest.begin() + long(k));
    Bits cover(covered.size(), 0);
    for (const Candidate* c : rest) Or(&cover, c->seen);
    if (Count(cover) >= std::min(needed, Count(covered)) && Connected(rest, min_common))
      chosen = rest;
  }
}

// Mount indices in order of first use (the first orientation's mount is 0), then the
// orientations grouped by mount and ordered by axis angle, the first kept first.
std::vector<PlannedOrientation> Ordered(const std::vector<const Candidate*>& chosen,
                                        bool rotation_axis) {
  std::vector<PlannedOrientation> out;
  std::vector<double> tilts;
  for (const Candidate* c : chosen) {
    PlannedOrientation o = c->pose;
    const auto it = std::find(tilts.begin(), tilts.end(), o.mount_tilt_deg);
    o.mount = rotation_axis ? int(it - tilts.begin()) : 0;
    if (it == tilts.end()) tilts.push_back(o.mount_tilt_deg);
    out.push_back(o);
  }
  std::stable_sort(out.begin() + 1, out.end(),
                   [](const PlannedOrientation& a, const PlannedOrientation& b) {
                     return a.mount != b.mount ? a.mount < b.mount : a.axis_deg < b.axis_deg;
                   });
  if (!rotation_axis)
    for (size_t k = 0; k < out.size(); ++k) out[k].mount = int(k);
  return out;
}

std::vector<std::string> Names(size_t count) {
  std::vector<std::string> names;
  for (size_t k = 0; k < count; ++k) names.push_back(OrientationName(k));
  return names;
}

void Analyse(const OrientationPlanInput& in, OrientationPlan* plan) {
  const std::vector<Eigen::Matrix3d> rotations = Rotations(plan->orientations);
  const std::vector<OrientationCone> cones(rotations.size(), in.cone);
  plan->coverage =
      AnalyseCoverage(rotations, cones, in.hemisphere, kCoverageSamples, Names(rotations.size()));
  plan->cumulative_coverage.clear();
  for (size_t k = 1; k <= rotations.size(); ++k)
    plan->cumulative_coverage.push_back(
        k == rotations.size()
            ? plan->coverage.covered_fraction
            : AnalyseCoverage({rotations.begin(), rotations.begin() + long(k)},
                              {cones.begin(), cones.begin() + long(k)}, in.hemisphere)
                  .covered_fraction);
}

}  // namespace

OrientationPlan PlanOrientations(const OrientationPlanInput& in) {
  const Samples samples = SearchSamples(in.hemisphere);
  const int needed = int(samples.w.size());
  const int min_common = int(std::ceil(kPlannedOverlapMargin * kMinOverlapSr / samples.sr_each));
  const char* region = in.hemisphere ? "hemisphere" : "sphere";
  std::optional<OrientationPlan> best;
  OrientationPlan fallback;  // the largest coverage, when no lattice reaches the request
  double fallback_coverage = -1;
  double best_cost = 0;
  for (int step : kOrientationStepsDeg) {
    const std::vector<Candidate> candidates = Candidates(in, samples, step, in.threads);
    const Candidate* stall = nullptr;
    const std::vector<const Candidate*> chosen =
        GreedyCover(candidates, needed, min_common, in.rotation_axis, in.max_orientations, &stall);
    OrientationPlan plan;
    plan.step_deg = step;
    plan.orientations = Ordered(chosen, in.rotation_axis);
    Analyse(in, &plan);
    const double covered = plan.coverage.covered_fraction;
    if (!plan.coverage.overlap_problem.empty()) {
      plan.problem = plan.coverage.overlap_problem;
    } else if (covered < in.min_coverage) {
      std::ostringstream why;
      why << plan.orientations.size() << " orientation(s) on " << step << " degree turns cover "
          << CoveragePercent(covered) << " of the " << region << " (requested "
          << CoveragePercent(in.min_coverage) << ")";
      if (int(chosen.size()) >= in.max_orientations) {
        why << ": the limit of " << in.max_orientations << " orientations";
      } else if (stall) {
        // What the registration would say of the next orientation that would add coverage.
        std::vector<Eigen::Matrix3d> r = Rotations(plan.orientations);
        r.push_back(stall->pose.rotation);
        const CoverageReport next =
            AnalyseCoverage(r, std::vector<OrientationCone>(r.size(), in.cone), in.hemisphere,
                            kCoverageSamples, Names(r.size()));
        why << ": no further turn overlaps the chosen ones enough to register"
            << (next.overlap_problem.empty() ? "" : " (" + next.overlap_problem + ")");
      } else {
        why << ": no further turn sees an unseen direction";
      }
      plan.problem = why.str();
    }
    if (plan.problem.empty()) {
      const double cost = double(plan.orientations.size()) +
                          (in.rotation_axis ? kRemountCost * (MountCount(chosen, true) - 1) : 0.0);
      if (!best || cost < best_cost - 1e-9 ||
          (cost < best_cost + 1e-9 && plan.orientations.size() < best->orientations.size())) {
        best = plan;
        best_cost = cost;
      }
    } else if (covered > fallback_coverage) {
      fallback = plan;
      fallback_coverage = covered;
    }
  }
  return best ? *best : fallback;
}

LuminaireSet OrientationPlanSet(const OrientationPlanInput& in, const OrientationPlan& plan) {
  LuminaireSet set;
  set.coverage = in.hemisphere ? "hemisphere" : "sphere";
  for (size_t k = 0; k < plan.orientations.size(); ++k) {
    const PlannedOrientation& p = plan.orientations[k];
    Orientation o;
    o.name = OrientationName(k);
    o.dataset = o.name;
    // The lattice's angles, without the last bits of the decomposition nor a -0.
    o.rotation_deg = (RotationZyxDegreesOf(p.rotation) * 1e9).array().round() / 1e9 + 0.0;
    o.centre_mm = in.centre_mm;
    o.mount = p.mount;
    if (in.rotation_axis) o.axis_deg = p.axis_deg;
    o.rotation = p.rotation;
    set.orientations.push_back(o);
  }
  return set;
}

namespace {

std::string Fixed(double v, int decimals) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, std::abs(v) < 0.5e-6 ? 0.0 : v);
  return buf;
}

}  // namespace

std::string OrientationPlanTable(const OrientationPlanInput& in, const OrientationPlan& plan) {
  const LuminaireSet set = OrientationPlanSet(in, plan);
  std::ostringstream out;
  out << "orientations: " << set.orientations.size() << " covering the " << set.coverage
      << " (turns in steps of " << plan.step_deg << " degrees; a capture sees +-"
      << Fixed(std::atan2(in.cone.half_w_mm, in.cone.distance_mm) * 180 / kPi, 1) << " x +-"
      << Fixed(std::atan2(in.cone.half_h_mm, in.cone.distance_mm) * 180 / kPi, 1) << " degrees)\n";
  out << "name  rotation_deg [x y z]      mount tilt  axis_deg  sees (C, gamma)  "
         "coverage  overlaps (sr) with neighbours\n";
  for (size_t k = 0; k < set.orientations.size(); ++k) {
    const Orientation& o = set.orientations[k];
    const PlannedOrientation& p = plan.orientations[k];
    // The luminaire direction at the screen's centre: R^T of the capture frame's +z.
    const Eigen::Vector2d cg = TypeCAngles(p.rotation.transpose() * Eigen::Vector3d::UnitZ());
    char row[160];
    std::snprintf(
        row, sizeof row, "%-5s [%7s %7s %7s]  %5d %5s  %8s  (%5s, %5s)   %7s  ", o.name.c_str(),
        Fixed(o.rotation_deg.x(), 1).c_str(), Fixed(o.rotation_deg.y(), 1).c_str(),
        Fixed(o.rotation_deg.z(), 1).c_str(), p.mount, Fixed(p.mount_tilt_deg, 0).c_str(),
        in.rotation_axis ? Fixed(p.axis_deg, 0).c_str() : "-", Fixed(cg.x(), 0).c_str(),
        Fixed(cg.y(), 0).c_str(),
        k < plan.cumulative_coverage.size() ? CoveragePercent(plan.cumulative_coverage[k]).c_str()
                                            : "-");
    out << row;
    for (const PairOverlap& pair : plan.coverage.pairs) {
      if (pair.overlap_sr < kMinOverlapSr || (pair.a != int(k) && pair.b != int(k))) continue;
      out << ' ' << set.orientations[size_t(pair.a == int(k) ? pair.b : pair.a)].name << ':'
          << Fixed(pair.overlap_sr, 3);
    }
    out << '\n';
  }
  out << "coverage " << CoveragePercent(plan.coverage.covered_fraction) << " of the "
      << set.coverage << " (unseen " << Fixed(plan.coverage.unseen_sr, 4)
      << " sr); every orientation "
      << (plan.coverage.overlap_problem.empty() ? "connected to o00 through overlaps >= "
                                                : "NOT connected: ")
      << (plan.coverage.overlap_problem.empty() ? Fixed(kMinOverlapSr, 2) + " sr"
                                                : plan.coverage.overlap_problem)
      << '\n';
  if (in.rotation_axis)
    out << "mount tilt: the luminaire turned about the capture frame's x on the axis's plate; "
           "axis_deg: the A axis about +y\n";
  return out.str();
}

}  // namespace lumislab
