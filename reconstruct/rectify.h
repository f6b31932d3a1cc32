// Photo pixel space -> slab texels of one grid position, with area averaging (docs/method.md §3,
// docs/formats.md). The texel at (s, t) (luminaire frame) sees the lab screen point (s, t) - c_ij,
// which the screen calibration maps to a photo pixel. Each texel is sampled on a K x K grid (K
// chosen so the samples are at least as dense as the photo pixels), bilinearly (cv::remap), and the
// K x K blocks are box-averaged (cv::resize INTER_AREA with an integer factor).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "core/grid.h"
#include "core/screen_calibration.h"

namespace lumislab {

struct RectifyMap {
  int res_x = 0;
  int res_y = 0;
  int samples_per_texel = 0;  // K
  // The photo is first box-averaged F x F (F = downsample, ~3 averaged pixels per texel) so K
  // stays ~3-4; the map addresses that averaged image. Pixel box + bilinear samples smooth by an
  // extra ~(F px)^2 / 4 second moment, ~1/3 of the texel box's own (texel^2 / 12): a bias of
  // ~texel^2/72 Laplacian(E), negligible for smooth light (measured in the tests).
  int downsample = 1;
  // Averaged-photo pixel of each sample, (res_y K) x (res_x K), in OpenCV's fixed-point remap
  // format: CV_16SC2 integer pixel + CV_16UC1 1/32-pixel fraction index.
  cv::Mat map_xy, map_frac;
  // Per texel: all its corners (hence all samples) inside the photo, the texel on the physical
  // screen, and at least a quarter of its samples reading only the screen.
  std::vector<unsigned char> inside;
  // Near the screen's edge a sample's bilinear read of the averaged image can reach photo pixels
  // beyond the screen: such samples have weight 0 here, the others 1 (CV_32FC1, the size of
  // map_xy), and Rectify takes the mean of the weighted samples. Empty when no seen texel has
  // such a sample (every sample counts).
  cv::Mat sample_weight;
  // The averaged-photo pixels that the samples of the seen texels read (each sample's pixel and
  // its right and lower neighbours, bilinear), clipped to the averaged image; empty when no texel
  // is seen. The rest of the photo does not reach the slab: the merge skips it.
  cv::Rect read_region;
  double max_texel_px = 0;  // largest texel extent in photo pixels (what K follows)
  double min_texel_px = 0;  // smallest (what F follows)
};

// screen_w/h_mm: the physical screen, [-W/2, W/2] x [-H/2, H/2] in the lab frame.
// samples_per_texel = 0 picks K = clamp(ceil(max texel extent in pixels), 2, kMaxSamples).
constexpr int kMaxSamplesPerTexel = 12;
RectifyMap BuildRectifyMap(const ScreenCalibration& calibration, const SlabLayout& layout,
                           const Eigen::Vector2d& centre_mm, double screen_w_mm, double screen_h_mm,
                           int samples_per_texel = 0);

// signal: CV_32FC3/4 averaged-photo image. Returns res_y x res_x texel box averages, same type.
cv::Mat Rectify(const cv::Mat& signal, const RectifyMap& map);

}  // namespace lumislab
