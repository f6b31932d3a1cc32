// A plain 8-bit RGB picture and what the photometrist's pictures draw on it (false colour, colour
// bar, polar plot: docs/method.md §4.9): filled rectangles, thick polylines (solid or dashed) and
// text in a built-in 5 x 7 bitmap font. No image or font library: lib/lightfield stays free of GL
// and OpenCV; lib/photo's WriteRgb8File writes the result.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lumislab {

struct Rgb8 {
  uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb8& o) const { return r == o.r && g == o.g && b == o.b; }
};

struct Rgb8Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // width * height * 3, RGB interleaved, row 0 on top

  Rgb8Image() = default;
  Rgb8Image(int w, int h, Rgb8 fill);
  Rgb8 at(int x, int y) const;
  // Out-of-image pixels are ignored; alpha in [0, 1] blends over what is there.
  void Set(int x, int y, Rgb8 c, double alpha = 1.0);
};

void FillRect(Rgb8Image& image, int x0, int y0, int x1, int y1, Rgb8 c);  // [x0, x1) x [y0, y1)
// A line of `width` pixels between two points (pixel units, sub-pixel ends); dash > 0: dashes
// and gaps of that length along the line, starting at `dash_phase` (to continue a polyline).
void DrawLine(Rgb8Image& image, double x0, double y0, double x1, double y1, Rgb8 c, double width,
              double dash = 0, double dash_phase = 0);
void DrawPolyline(Rgb8Image& image, const std::vector<double>& xy, Rgb8 c, double width,
                  double dash = 0);

// Text in the built-in 5 x 7 font, each glyph cell 6 x 9 font pixels times `scale`: digits,
// A-Z, a-z, " .,:;-+/=()%^_*'", and from UTF-8 the degree sign, superscript two, gamma and the
// en dash (others draw as '?'). (x, y) is the top left of the first cell.
void DrawText(Rgb8Image& image, int x, int y, const std::string& text, Rgb8 c, int scale = 1);
int TextWidth(const std::string& text, int scale = 1);  // pixels
constexpr int kGlyphHeight = 9;                         // font pixels per line (7 + 2 spacing)

// Each output pixel the mean of 2 x 2 input pixels (anti-aliasing of a picture drawn at twice
// the size).
Rgb8Image Downsample2x(const Rgb8Image& image);

}  // namespace lumislab
