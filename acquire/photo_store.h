// How the synthetic capture stores its slide photos (docs/formats.md §4, §10): the dataset's
// own encodings (lib/photo WritePhoto), an RGGB Bayer mosaic in a DNG for a scene with the `raw`
// effect, and, for `synth --camera-folder`, the files a camera leaves behind: camera-style names
// in capture order and EXIF (lib/photo/camera_write.h), with a setup file instead of a dataset.
#pragma once

#include <string>
#include <vector>

#include "core/dataset.h"
#include "core/image.h"
#include "lib/photo/exif.h"
#include "lib/photo/photo_write.h"
#include "lib/synthetic/scene.h"

namespace lumislab {

// The synthetic camera's f-number and ISO, fixed; its exposure time is the photo's relative
// exposure times kBaseExposureTimeS = N^2 / ISO, so that EXIF's t ISO / N^2 gives the exposure
// back (up to EXIF's rational rounding).
constexpr double kSynthFNumber = 8, kSynthIso = 100;
constexpr double kBaseExposureTimeS = kSynthFNumber * kSynthFNumber / kSynthIso;

struct PhotoStore {
  PhotoEncoding encoding = PhotoEncoding::kHalfExr;  // a dataset's photos without `raw`
  int jpeg_quality = 95;
  bool camera_folder = false;  // camera-style files with EXIF
};

// What the synthetic camera records of photo `photo_index` (its place in the capture) taken at
// relative exposure `exposure`: make, model, lens, N, ISO, t, and DateTimeOriginal one second
// after the previous photo (2026:01:01 00:00:00 for the first).
PhotoExif SynthExif(double exposure, int photo_index);

// Writes one slide photo (normalised linear RGB after the effects) at `path`: a DNG mosaic for
// `raw`; in a camera folder JPEG (response) or 16-bit TIFF with EXIF; else WritePhoto.
void StoreSlidePhoto(const SynthScene& scene, const PhotoStore& store, const std::string& path,
                     const ImageF& photo, double exposure, int photo_index);
// The extension (lower case) of the files StoreSlidePhoto writes: dng, jpg or tif in a camera
// folder, else the scene's (SynthScene::PhotoExtension).
std::string StoredExtension(const SynthScene& scene, const PhotoStore& store);
// "DNG mosaic", "16-bit TIFF", ... for the log.
std::string StoreName(const SynthScene& scene, const PhotoStore& store);

// The camera folder in a synth output folder, and the board photo's name in it.
constexpr const char* kCameraFolder = "camera";
constexpr const char* kCameraBoardPhoto = "BOARD.PNG";
// PhotoList's photos as a camera names them: camera/IMG_0001.<EXT>, ... in capture order (the
// scan by rows, slide p then n, the bracket's stops in order: PhotoList's order), EXT = DNG
// (raw), JPG (response) or TIF.
std::vector<PhotoEntry> CameraFolderPhotoList(const SynthScene& scene);
// setup.json for `acquire import`: dataset.json without photos, with only what a lab knows
// (setup, filter, the board and its photo, relative to the camera folder) and an empty
// radiometry: scale, black level and transfer are the lab's to calibrate.
void WriteSetupFile(const Dataset& dataset, const std::string& path);
// True when `dir` holds a complete camera-folder capture of `scene` (setup.json, every photo,
// the board photo, a complete truth/).
bool CameraFolderComplete(const SynthScene& scene, const std::string& dir);

}  // namespace lumislab
