// The one name order of photo files (core/input_file.h): digit runs compared as numbers, as
// cameras count without leading zeros (gphoto2's %n: capt1 ... capt18), and a total order.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/input_file.h"

namespace lumislab {
namespace {

TEST(NameOrder, NumbersCompareAsNumbers) {
  EXPECT_TRUE(NameOrderLess("IMG_9.JPG", "IMG_10.JPG"));
  EXPECT_FALSE(NameOrderLess("IMG_10.JPG", "IMG_9.JPG"));
  EXPECT_TRUE(NameOrderLess("capt2.tif", "capt18.tif"));
  EXPECT_TRUE(NameOrderLess("IMG_0009.JPG", "IMG_0010.JPG"));  // padded: as before
  EXPECT_TRUE(NameOrderLess("a", "a0"));
  EXPECT_TRUE(NameOrderLess("a2b", "a10"));
  // Longer than any integer type: compared by their digits.
  EXPECT_TRUE(NameOrderLess("x99999999999999999999999", "x100000000000000000000000"));
  EXPECT_TRUE(NameOrderLess("DSC_5.NEF", "DSC_5.jpg"));  // equal numbers: the rest decides
}

TEST(NameOrder, IsATotalOrder) {
  // Equal numbers with other leading zeros are still two names, ordered by their text; every
  // pair is ordered exactly one way, consistently with a sort.
  std::vector<std::string> names = {"IMG_1",  "IMG_01", "IMG_001", "IMG_10", "IMG_9",
                                    "IMG_09", "IMG_",   "IMG",     "img_1",  "IMG_1a",
                                    "IMG_1_", "IMG_0",  "IMG_00",  "IMG-1",  "1",
                                    "01",     "",       "10a",     "9z",     "IMG_2.JPG"};
  for (const auto& a : names)
    for (const auto& b : names) {
      EXPECT_FALSE(NameOrderLess(a, b) && NameOrderLess(b, a)) << a << " " << b;
      if (a != b) EXPECT_TRUE(NameOrderLess(a, b) || NameOrderLess(b, a)) << a << " " << b;
      for (const auto& c : names)
        if (NameOrderLess(a, b) && NameOrderLess(b, c))
          EXPECT_TRUE(NameOrderLess(a, c)) << a << " " << b << " " << c;
    }
  std::sort(names.begin(), names.end(), NameOrderLess);
  const auto at = [&](const std::string& n) { return std::find(names.begin(), names.end(), n); };
  EXPECT_LT(at("IMG_9"), at("IMG_10"));
  EXPECT_LT(at("IMG_09"), at("IMG_10"));
  EXPECT_LT(at("IMG_2.JPG"), at("IMG_10"));
}

}  // namespace
}  // namespace lumislab
