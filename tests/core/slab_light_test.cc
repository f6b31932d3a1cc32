// core/slab_light.h: a slab's total light, its negative shares, and the check every stage that
// reads a slab makes of it ("slab.total_light").
#include "core/slab_light.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/error.h"

namespace lumislab {
namespace {

// A 2 x 1 grid of 2 x 2-texel positions over a 20 x 20 mm window: texels of 100 mm^2.
struct TwoPositions {
  SlabInfo info;
  std::vector<SlabPosition> positions;
  TwoPositions() {
    info.grid = {2, 2, 5};
    info.layout = {20, 20, 2, 2};
    for (int p = 0; p < 2; ++p) {
      SlabPosition pos;
      pos.irradiance = ImageF(2, 2, 3);
      pos.mask = ImageF(2, 2, 1);
      for (float& m : pos.mask.data) m = 1;
      positions.push_back(pos);
    }
    positions.resize(4);  // positions 2, 3 without an image (a partial slab)
  }
  void Set(int p, int texel, float grey) {
    for (int c = 0; c < 3; ++c) positions[p].irradiance.data[3 * texel + c] = grey;
  }
};

TEST(SlabLight, SumsTexelsAndPositionsInLuminance) {
  TwoPositions s;
  s.Set(0, 0, 2);  // texel 0: 2 - 1 = +1
  s.Set(1, 0, -1);
  s.Set(0, 1, -3);  // texel 1: -3, position 0's total 2 - 3 = -1
  s.positions[1].mask.data[2] = 0;
  s.Set(1, 2, 100);  // unseen: left out
  const SlabLight light = MeasureSlabLight(s.info, s.positions);
  const double dA = 1e-4;  // m^2
  EXPECT_EQ(light.positions, 2);
  EXPECT_NEAR(light.total, -2 * dA, 1e-12);
  EXPECT_NEAR(light.positive, 1 * dA, 1e-12);
  EXPECT_NEAR(light.negative, 3 * dA, 1e-12);
  EXPECT_NEAR(light.NegativeShare(), 0.75, 1e-9);
  EXPECT_EQ(light.negative_positions, 2);
  EXPECT_NEAR(light.PositionNegativeShare(), 1.0, 1e-9);
  EXPECT_EQ(light.most_negative, std::make_pair(0, 0));
}

TEST(SlabLight, CheckPassesPositiveAndRefusesNegativeOrNan) {
  TwoPositions s;
  s.Set(0, 0, 1);
  s.Set(1, 3, -0.5);  // some negative ringing: legitimate
  CheckLog good("", "test");
  EXPECT_GT(CheckSlabLight(s.info, s.positions, "lab/slab", good).total, 0);
  ASSERT_EQ(good.records().size(), 1u);
  EXPECT_EQ(good.records()[0].outcome, CheckOutcome::kPassed);
  EXPECT_NEAR(good.records()[0].values["negative_share"].get<double>(), 1.0 / 3, 1e-9);

  s.Set(1, 3, -2);
  CheckLog negative("", "test");
  try {
    CheckSlabLight(s.info, s.positions, "lab/slab", negative);
    FAIL() << "a slab of negative total light was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("lab/slab/slab.json: total light"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(negative.records().back().outcome, CheckOutcome::kFailed);

  s.Set(0, 0, std::numeric_limits<float>::quiet_NaN());
  CheckLog nan("", "test");
  EXPECT_THROW(CheckSlabLight(s.info, s.positions, "lab/slab", nan), Error);
  // No light at all: a black capture, warned; a negative total on a grid of one row is not held
  // to its sign (its positions are all at the edge).
  for (float& v : s.positions[0].irradiance.data) v = 0;
  for (float& v : s.positions[1].irradiance.data) v = 0;
  CheckLog dark("", "test");
  CheckSlabLight(s.info, s.positions, "lab/slab", dark);
  EXPECT_EQ(dark.records().back().outcome, CheckOutcome::kWarning);
  s.Set(1, 3, -2);
  s.info.grid = {4, 1, 5};
  CheckLog row("", "test");
  CheckSlabLight(s.info, s.positions, "lab/slab", row);
  EXPECT_EQ(row.records().back().outcome, CheckOutcome::kPassed);
}

}  // namespace
}  // namespace lumislab
