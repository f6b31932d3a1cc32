// The photometrist's view of an irradiance (illuminance) image (docs/method.md §4.9): each pixel's
// value through a perceptual colour map (viridis) on a linear or logarithmic scale, iso-lines at
// the scale's ticks, a colour bar with tick labels and the unit, and optionally a length scale
// bar. GL-free: the preview (--view false-colour) and lumislab-export (irradiance on a plane)
// both draw through here.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/image.h"
#include "lib/lightfield/raster.h"

namespace lumislab {

// Viridis (S. van der Walt and N. Smith, matplotlib 1.5/2.0's default colour map, 2015, public
// domain / CC0; https://bids.github.io/colormap/): black-purple at t = 0 through blue and green to
// yellow at t = 1, luminance rising monotonically. Here it is its 9 published samples at
// t = 0, 1/8, ..., 1 (#440154 ... #fde725) joined linearly; t is clamped to [0, 1].
Rgb8 Viridis(double t);

// Value -> position on the colour map, and the ticks where the bar is labelled and the iso-lines
// are drawn.
struct FalseColourScale {
  double min = 0, max = 1;  // in the image's unit; log needs 0 < min < max
  bool log = false;

  // Position in [0, 1] (clamped; values below min, and NaN, give 0).
  double Position(double value) const;
  // "Nice" values inside [min, max]: linear, multiples of 1, 2 or 5 x 10^k giving 4-10 ticks;
  // log, the decades (with 2 and 5 of each when the range spans at most 3 decades).
  std::vector<double> Ticks() const;
  // BadInput naming `what` unless min < max, both finite, and min > 0 for log.
  void Check(const std::string& what) const;
};

// The scale for an image when the user gives none: linear from 0 to the largest value rounded
// up to a nice number; log from 1/1000 of that to it, the top rounded up to a decade. An image
// without light gives [0, 1] ([1e-3, 1] log).
FalseColourScale AutoScale(const std::vector<float>& values, bool log);

// The scalar the picture maps: channel_weights . RGB of each pixel (the slab's weights,
// SlabInfo::channel_weights: the luminance a radiometer or lux meter calibration scales,
// docs/formats.md §16), row 0 on top; a 1-channel image as it is.
std::vector<float> PixelLuminance(const ImageF& image, const Eigen::Vector3d& channel_weights);

// Which pixels draw the iso-line of each level: a pixel is marked when a level lies between its
// value and its right or lower neighbour's and its value is the nearer of the two (in the scale's
// measure: log10 for log), so each iso-line is about one pixel wide and within half a pixel's
// step of the level. 1 = on a line.
std::vector<uint8_t> IsoLineMask(const std::vector<float>& values, int width, int height,
                                 const std::vector<double>& levels, bool log);

struct FalseColourOptions {
  FalseColourScale scale;
  std::string unit = "W/m\u00B2";  // shown above the bar
  bool iso_lines = true;
  double mm_per_pixel = 0;  // > 0: a length scale bar in the picture's lower left corner
  std::string title;        // optional, above the bar's unit
};

// The picture (width x height values through the colour map, iso-lines in black or white,
// whichever stands out) with the colour bar panel to its right: a picture of
// (width + BarPanelWidth) x max(height, 120) pixels.
Rgb8Image RenderFalseColour(const std::vector<float>& values, int width, int height,
                            const FalseColourOptions& options);
int BarPanelWidth(int height);

// What a user asks for (lumislab-preview --view false-colour, lumislab-export irradiance): the
// scale's kind and range, automatic (AutoScale of the picture's values) unless max > min.
struct FalseColourRequest {
  bool log = false;         // --false-colour-scale log
  double min = 0, max = 0;  // --false-colour-range min:max; max <= min: automatic
  FalseColourScale Resolve(const std::vector<float>& values) const;
};
// "min:max" (finite numbers, min < max; min > 0 for log) or "auto" into `request`; BadInput
// naming `option` otherwise.
void ParseFalseColourRange(const std::string& text, const std::string& option,
                           FalseColourRequest* request);

// The whole picture of a linear RGB irradiance image: its PixelLuminance (by the slab's
// channel_weights) through the resolved scale, iso-lines, the bar in `unit`, a scale bar when
// mm_per_pixel > 0 and the title.
Rgb8Image FalseColourPicture(const ImageF& irradiance, const Eigen::Vector3d& channel_weights,
                             const FalseColourRequest& request, const std::string& unit,
                             double mm_per_pixel, const std::string& title = "");

// "1500", "0.25", "2e+05": a tick value with as many decimals as the ticks' step needs.
std::string FormatTick(double value, double step);

// The unit a picture shows for slab.json's `units` (docs/method.md §3.7): irradiance
// ("W/m^2" -> W/m², "lux" -> lx) or, for the far field, intensity (W/sr, cd).
std::string IrradianceUnitLabel(const std::string& slab_units);
std::string IntensityUnitLabel(const std::string& slab_units);

}  // namespace lumislab
