// The photometrist's pictures without GL (docs/method.md §4.9): the colour map's ends and its
// monotone luminance, the scale's ticks and automatic range, iso-lines on a radial ramp at the
// level they stand for, the bar's range in the picture, the bitmap font, and the polar plot's
// geometry.
#include "lib/lightfield/false_colour.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "lib/lightfield/polar_plot.h"

namespace lumislab {
namespace {

double Luma(Rgb8 c) {  // relative luminance of an sRGB colour (Rec. 709 primaries)
  auto linear = [](uint8_t v) {
    const double x = v / 255.0;
    return x <= 0.04045 ? x / 12.92 : std::pow((x + 0.055) / 1.055, 2.4);
  };
  return 0.2126 * linear(c.r) + 0.7152 * linear(c.g) + 0.0722 * linear(c.b);
}

TEST(FalseColour, ViridisEndsAndMonotoneLuminance) {
  EXPECT_EQ(Viridis(0), (Rgb8{68, 1, 84}));     // #440154
  EXPECT_EQ(Viridis(1), (Rgb8{253, 231, 37}));  // #fde725
  EXPECT_EQ(Viridis(-5), Viridis(0));           // clamped
  EXPECT_EQ(Viridis(NAN), Viridis(0));
  EXPECT_EQ(Viridis(7), Viridis(1));
  double previous = -1;
  for (int k = 0; k <= 1000; ++k) {
    const double y = Luma(Viridis(k / 1000.0));
    // Up to one 8-bit step of red (red falls while green rises over the first quarter).
    EXPECT_GE(y, previous - 5e-4) << "t = " << k / 1000.0;
    previous = std::max(previous, y);
  }
  for (int k = 1; k <= 64; ++k) EXPECT_GT(Luma(Viridis(k / 64.0)), Luma(Viridis((k - 1) / 64.0)));
  EXPECT_GT(Luma(Viridis(1)), 10 * Luma(Viridis(0)));
}

TEST(FalseColour, LinearAndLogTicks) {
  FalseColourScale linear{0, 120, false};
  const std::vector<double> ticks = linear.Ticks();
  ASSERT_EQ(ticks.size(), 7u);  // step 20
  EXPECT_DOUBLE_EQ(ticks.front(), 0);
  EXPECT_DOUBLE_EQ(ticks.back(), 120);
  EXPECT_DOUBLE_EQ(linear.Position(60), 0.5);
  EXPECT_EQ(linear.Position(-3), 0);
  EXPECT_EQ(linear.Position(500), 1);

  FalseColourScale log{0.1, 1000, true};
  EXPECT_EQ(log.Ticks(), (std::vector<double>{0.1, 1, 10, 100, 1000}));
  EXPECT_NEAR(log.Position(10), 0.5, 1e-12);
  EXPECT_EQ(log.Position(0), 0);  // no light: the bottom colour
  FalseColourScale narrow{1, 20, true};
  EXPECT_EQ(narrow.Ticks(), (std::vector<double>{1, 2, 5, 10, 20}));

  EXPECT_THROW((FalseColourScale{0, 10, true}).Check("--false-colour-range"), Error);
  EXPECT_THROW((FalseColourScale{5, 5, false}).Check("--false-colour-range"), Error);
  EXPECT_EQ(FormatTick(0.25, 0.05), "0.25");
  EXPECT_EQ(FormatTick(1500, 500), "1500");
  EXPECT_EQ(FormatTick(0.01, 0.01), "0.01");
  EXPECT_EQ(FormatTick(-1e-17, 0.5), "0.0");
  EXPECT_EQ(IrradianceUnitLabel("lux"), "lx");
  EXPECT_EQ(IrradianceUnitLabel("W/m^2"), "W/m\u00B2");
  EXPECT_EQ(IntensityUnitLabel("lux"), "cd");
  EXPECT_EQ(IntensityUnitLabel("W/m^2"), "W/sr");
}

TEST(FalseColour, AutoScaleCoversThe995thPercentile) {
  std::vector<float> values(1000);
  for (int k = 0; k < 1000; ++k) values[k] = float(k) * 0.1f;  // 0 .. 99.9
  values[999] = 1e6f;                                          // one hot pixel
  const FalseColourScale linear = AutoScale(values, false);
  EXPECT_EQ(linear.min, 0);
  EXPECT_DOUBLE_EQ(linear.max, 100);  // 99.4 rounded up to the tick step 10
  const FalseColourScale log = AutoScale(values, true);
  EXPECT_DOUBLE_EQ(log.max, 100);
  EXPECT_DOUBLE_EQ(log.min, 0.1);  // three decades
  const FalseColourScale dark = AutoScale(std::vector<float>(10, 0.f), false);
  EXPECT_EQ(dark.max, 1);
}

// A radial ramp v = r (pixels from the centre): the iso-line of level L must run all round at
// radius L, never further than half a pixel step from it.
TEST(FalseColour, IsoLinesOnARadialRampSitAtTheirLevel) {
  const int n = 101;
  const double c = 50;
  std::vector<float> values(n * n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) values[y * n + x] = float(std::hypot(x - c, y - c));
  for (const bool log : {false, true}) {
    const double level = 30;
    const std::vector<uint8_t> mask = IsoLineMask(values, n, n, {level}, log);
    int marked = 0;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        if (mask[y * n + x]) {
          ++marked;
          EXPECT_LE(std::abs(values[y * n + x] - level), 0.5 + 1e-6) << x << "," << y;
        }
    // Closed: every direction meets a marked pixel within one pixel of the circle.
    for (int a = 0; a < 720; ++a) {
      const double phi = a * M_PI / 360;
      bool found = false;
      for (int dy = -1; dy <= 1 && !found; ++dy)
        for (int dx = -1; dx <= 1 && !found; ++dx) {
          const int x = int(std::lround(c + level * std::cos(phi))) + dx;
          const int y = int(std::lround(c + level * std::sin(phi))) + dy;
          found = mask[y * n + x] != 0;
        }
      EXPECT_TRUE(found) << "angle " << a / 2.0;
    }
    EXPECT_LT(marked, int(2 * M_PI * level * 1.5));  // about one pixel wide
  }
}

// The picture: the ramp's pixels take the map's colour of their value, the bar runs from the
// top colour (max) down to the bottom one (min), and values above max saturate.
TEST(FalseColour, PictureAndBarShowTheRange) {
  const int w = 200, h = 160;
  std::vector<float> values(w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) values[y * w + x] = float(x);  // 0 .. 199 left to right
  FalseColourOptions options;
  options.scale = {0, 150, false};
  options.iso_lines = false;
  const Rgb8Image image = RenderFalseColour(values, w, h, options);
  ASSERT_EQ(image.width, w + BarPanelWidth(h));
  ASSERT_EQ(image.height, h);
  EXPECT_EQ(image.at(0, 80), Viridis(0));
  EXPECT_EQ(image.at(75, 80), Viridis(0.5));
  EXPECT_EQ(image.at(180, 80), Viridis(1));
  // The bar: find the column's top and bottom colours.
  const int bar_x = w + 15;
  EXPECT_EQ(image.at(bar_x, 24), Viridis(1));
  const Rgb8 bottom = image.at(bar_x, h - 12);  // one row above the tick at 0
  EXPECT_NEAR(bottom.g, Viridis(0).g, 4);       // t = 1/125 there
  EXPECT_NEAR(bottom.b, Viridis(0).b, 4);
  // Iso-lines on: the ticks are 0, 20, ..., 140, so the level-60 line is drawn at x = 60 (in
  // black or white) and x = 50 keeps its colour.
  options.iso_lines = true;
  const Rgb8Image lined = RenderFalseColour(values, w, h, options);
  EXPECT_FALSE(lined.at(60, 80) == Viridis(60 / 150.0));
  EXPECT_EQ(lined.at(50, 80), Viridis(50 / 150.0));
}

TEST(Raster, TextHasInkAndWidth) {
  Rgb8Image image(60, 12, {0, 0, 0});
  DrawText(image, 1, 1, "W/m\u00B2", {255, 255, 255});
  EXPECT_EQ(TextWidth("W/m\u00B2"), 4 * 6 - 1);  // four glyphs
  int ink = 0;
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 60; ++x) ink += image.at(x, y).r > 0;
  EXPECT_GT(ink, 30);
  EXPECT_EQ(image.at(40, 5), (Rgb8{0, 0, 0}));  // nothing past the text
}

// The polar plot: a constant intensity I draws a semicircle of radius I in the plot's units,
// the same for both planes, and the SVG carries both curves and the unit.
TEST(PolarPlot, ConstantIntensityIsACircle) {
  PolarPlotData data;
  for (int g = 0; g <= 90; g += 5) data.gamma_deg.push_back(g);
  data.c0.assign(data.gamma_deg.size(), 100);
  data.c180 = data.c90 = data.c270 = data.c0;
  data.unit = "cd";
  const PolarPlot plot = MakePolarPlot(data, 400);
  // The curves: width 2 and more than one segment (the legend's swatches are one segment).
  std::vector<const PolarPlot::Line*> curves;
  for (const auto& line : plot.lines)
    if (line.width == 2 && line.xy.size() > 4) curves.push_back(&line);
  ASSERT_EQ(curves.size(), 2u);
  // The first point is C180 at gamma = 90, level with the centre (plot.width / 2, cy); every
  // point lies at the same distance from it.
  const auto& xy = curves[0]->xy;
  const double cy = xy[1];
  const double r0 = std::hypot(xy[0] - plot.width / 2, 0.0);
  EXPECT_GT(r0, 50);
  for (size_t k = 0; k < xy.size(); k += 2)
    EXPECT_NEAR(std::hypot(xy[k] - plot.width / 2, xy[k + 1] - cy), r0, 1e-6);
  EXPECT_EQ(curves[0]->xy, curves[1]->xy);  // the same intensities in both planes
  const std::string svg = PolarPlotSvg(plot);
  EXPECT_NE(svg.find("C0\u2013C180"), std::string::npos);
  EXPECT_NE(svg.find("C90\u2013C270"), std::string::npos);
  EXPECT_NE(svg.find("I in cd"), std::string::npos);
  const Rgb8Image image = PolarPlotImage(plot);
  EXPECT_EQ(image.width, int(plot.width));
  data.c90.pop_back();
  EXPECT_THROW(MakePolarPlot(data), Error);
}

}  // namespace
}  // namespace lumislab
