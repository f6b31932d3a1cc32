// lumislab-acquire import: a folder of camera photos and a setup file become a dataset
// (docs/formats.md §3). The photos stay where the camera wrote them: dataset.json names their
// folder (photo_folder) and each file in it; nothing is copied or modified.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/dataset.h"

namespace lumislab {

struct ImportOptions {
  std::string photos_dir;  // the camera's folder
  std::string setup_file;  // dataset.json without photos; calibration.photo relative to photos_dir
  std::string out_dir;     // the dataset folder to write (dataset.json)
  // Exactly one way of telling which photo is which:
  std::string manifest;  // CSV, one row per photo: i,j,slide,file[,exposure]
  std::string pattern;   // file-name template: {i} {j} {slide}, optional {exposure} and {bracket}
  // "name": the photos' name order is the capture order; "capture": their EXIF capture time is.
  std::string order;
  // With `order`: how the grid was scanned, and the exposures of each slide's bracket, in the
  // order they were taken (relative exposures; one value: no brackets).
  std::string scan = "rows";  // rows | serpentine | columns
  std::vector<double> exposures;
  // Photos per slide (a bracket's exposures), for --order without --exposures (each photo's
  // exposure then from EXIF) and --pattern; 0: --exposures' count, else as many as the fullest
  // slide holds (import) or 1 (watch, --order).
  int brackets = 0;
  // The relative exposure of a photo nothing else gives one for (no manifest exposure, pattern
  // {exposure} or --exposures, and no EXIF exposure time, f-number and ISO); without it such a
  // photo is an error.
  std::optional<double> exposure;
  bool force = false;  // rewrite an existing dataset.json
  // Positions without both slides (all exposures) are left out and listed in dataset.json's
  // missing_positions instead of refusing the folder (with --order: the photos after the last
  // one are missing; a gap in the middle shifts every later photo and cannot be told).
  bool partial = false;

  void Check() const;  // BadInput naming the option
};

struct ImportReport {
  bool skipped = false;                      // dataset.json existed (no --force)
  int photos = 0;                            // slide photos listed
  int brackets = 1;                          // exposures per slide
  std::vector<std::string> unused;           // image files in the folder that no photo entry names
  std::vector<std::pair<int, int>> missing;  // --partial: the positions left out
};

// Builds dataset.json for the photos: every named file must be a regular file holding an image
// (PNG, JPEG, TIFF, EXR or RAW by its content), every grid position must have both slides (or,
// with `partial`, be listed as missing), and every slide the same number of exposures; BadInput
// naming the file, line or position otherwise.
ImportReport RunImport(const ImportOptions& options);

// The dataset for the options: the setup file, photo_folder naming the camera's folder relative
// to the dataset folder, no photos yet.
Dataset ImportSkeleton(const ImportOptions& options);
// Reads `dataset` back through the one dataset reader (duplicates, ranges) and writes it as
// <out_dir>/dataset.json (atomic).
void WriteImportedDataset(const Dataset& dataset, const std::string& out_dir);

// Whether `name`, a file of the photo folder, is one lumislab writes into the dataset folder
// (dataset.json) while the photo folder is the dataset folder (--photos F --out F): such a file is
// never a photo. (Its temporaries have a leading '.' and the stages write into subfolders, which
// FolderFiles never lists.)
bool IsDatasetFile(const ImportOptions& options, const std::string& name);

// The grid position of the k-th photo position of a scan (rows: i fastest; serpentine: rows,
// every other one reversed; columns: j fastest).
std::pair<int, int> ScanPosition(const SamplingGrid& grid, const std::string& scan, int k);

}  // namespace lumislab
