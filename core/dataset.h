// dataset.json (docs/formats.md): the setup, the printed filter, the radiometric scale and the
// photos; and the JSON blocks that several files share (grid, filter, a pair of lengths), each
// parsed by one function with one set of limits.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/basis.h"
#include "core/grid.h"
#include "core/json.h"

namespace lumislab {

// 2 added radiometry.transfer, black_level and white_level (version 1 files read with their
// defaults; a version-1 reader refuses version 2 instead of misreading the photos). 3 added
// photo_folder (photos referenced where a camera wrote them); a dataset without one is still
// written as version 2.
constexpr int kDatasetSchemaVersion = 3;

struct FilterInfo {
  std::string basis = "bell";
  double spacing_mm = 0;
  std::vector<double> dual_coefficients;  // [c0, c1, ...] as in docs/method.md §2
  double peak = 0;                        // max |Phi~| of the 2D filter; slides are Phi~/peak
  DualFilter Filter() const { return DualFilter::FromCoefficients(dual_coefficients); }
  static FilterInfo Of(const DualFilter& filter, double spacing_mm);
};

// The "filter" block of dataset.json and slab.json; spacing_mm must equal the grid's.
FilterInfo ParseFilterInfo(const JsonView& filter, const SamplingGrid& grid);
nlohmann::json FilterInfoJson(const FilterInfo& filter);

// Checkerboard lying on the screen plane, photographed once for the screen calibration.
// Board square (a, b) has its lower-left corner at origin + (a, b) * square (lab mm, screen
// plane); square (0, 0) is black and carries a white dot at its centre that fixes orientation.
struct CalibrationTarget {
  std::string photo;  // relative to the dataset folder, e.g. photos/calib_0.png
  int squares_x = 0;  // number of squares along x
  int squares_y = 0;
  double square_mm = 0;
  Eigen::Vector2d origin_mm{0, 0};  // lab frame, screen plane

  // What the screen calibration needs of a board, checked wherever a board is first read (scene
  // file, dataset.json) so that a capture is never made with a board calibrate would refuse:
  // at least 3 x 3 squares, not square (a square board with one dot looks the same mirrored
  // about its diagonal), a square size > 0. InputError naming `file` and `field`.
  void Check(const std::string& file, const std::string& field) const;
};

// Limits shared by every file that holds a grid. Lengths outside physically meaningful ranges
// are refused, not computed with (a distance of 1e-9 mm or 1e12 mm is a typo, not a setup).
constexpr int kMaxGridSide = 1000;                           // positions per axis
constexpr double kMinDistanceMm = 1, kMaxDistanceMm = 1e5;   // d, S to M
constexpr double kMinSpacingMm = 0.01, kMaxSpacingMm = 1e3;  // h
constexpr double kMinScreenMm = 1, kMaxScreenMm = 1e5;       // screen / slab window sides
constexpr double kMaxCoordinateMm = 1e6;                     // any position in the lab
constexpr int kMinBoardSquares = 3, kMaxBoardSquares = 200;

// {"nu": int, "nv": int, "spacing_mm": > 0}.
SamplingGrid ParseGrid(const JsonView& grid);
nlohmann::json GridJson(const SamplingGrid& grid);
// [w, h] in [kMinScreenMm, kMaxScreenMm] (screen or window size in mm).
Eigen::Vector2d ParseLengthPair(const JsonView& value);
// d in [kMinDistanceMm, kMaxDistanceMm].
double ParseDistance(const JsonView& value);
// The truncation K of a filter (scene files, the printer's --k-max).
int ParseFilterTruncation(const JsonView& k_max);

// The range of dataset.json's photos[].exposure (relative exposure t ISO / N^2, any unit).
constexpr double kMinPhotoExposure = 1e-9, kMaxPhotoExposure = 1e9;

struct PhotoEntry {
  int i = 0;
  int j = 0;
  bool positive = true;   // slide T+ (true) or T- (false)
  std::string file;       // relative to the dataset folder
  double exposure = 1.0;  // relative exposure; linear value / exposure is comparable
};

struct Dataset {
  std::string dir;         // folder it was loaded from
  double distance_mm = 0;  // d
  SamplingGrid grid;
  double screen_w_mm = 0;  // physical screen (lab frame), also the slab window
  double screen_h_mm = 0;
  FilterInfo filter;
  // Irradiance on the screen (W m^-2) per unit of normalised linear pixel value at exposure 1.
  std::optional<double> radiometric_scale;
  double saturation_level = 1.0;  // normalised linear value at or above which a pixel is clipped
  // How photo codes become linear values (lib/photo/photo_io.h): "auto" (8-bit through the sRGB
  // curve, 16-bit and float linear), "linear" or "srgb"; black and white level in normalised
  // units (linear = (v - black) / (white - black)).
  std::string photo_transfer = "auto";
  double black_level = 0;
  double white_level = 1;
  CalibrationTarget calibration;
  // Where the photo files (the slide photos and the calibration photo) are: "" for the dataset
  // folder itself, else a folder absolute or relative to the dataset folder (`acquire import`
  // references a camera's folder instead of copying it). Photo names are relative to it.
  std::string photo_folder;
  std::vector<PhotoEntry> photos;
  // Positions the capture does not have (yet): a partial dataset (`acquire import --partial`,
  // `acquire watch` while photos arrive). Exactly the positions without photos; every other
  // position has both slides. Empty for a complete dataset (the usual case).
  std::vector<std::pair<int, int>> missing_positions;
  bool synthetic = false;

  static Dataset Load(const std::string& dir);  // validates, errors name dataset.json and field
  // The dataset a parsed JSON document describes, for the folder `dir`; errors name the
  // document's file. `with_photos` false reads a setup file (dataset.json without photos).
  static Dataset Parse(const JsonDocument& doc, const std::string& dir, bool with_photos = true);
  void Save(const std::string& dir) const;  // atomic
  nlohmann::json ToJson() const;            // what Save writes
  std::string Path(const std::string& relative) const { return dir + "/" + relative; }
  // A photo's path: `file` (a PhotoEntry's or the calibration photo's) under photo_folder.
  std::string PhotoPath(const std::string& file) const;
  // Photos of one position (both slides, all exposures), in file order; none for a missing one.
  std::vector<PhotoEntry> PhotosOf(int i, int j) const;
  bool Partial() const { return !missing_positions.empty(); }
  SlabLayout Layout(int resolution) const {
    return {screen_w_mm, screen_h_mm, resolution, resolution};
  }
};

// Canonical photo file name: pos_<i>_<j>_<p|n>[_<exposure>].<ext>
std::string PhotoFileName(int i, int j, bool positive, const std::string& ext,
                          const std::string& exposure_tag = "");

}  // namespace lumislab
