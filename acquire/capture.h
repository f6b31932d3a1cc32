// lumislab-acquire capture: lumislab runs the capture (docs/formats.md §3, "Capturing"). It moves
// the luminaire over the grid of setup.json on a stage, has the slides put in, chooses the
// bracket from a test shot, photographs every position through both slides, checks each photo
// as it arrives, and writes the dataset as `acquire watch` does: photos/ and a dataset.json that
// grows position by position, so that `reconstruct --watch` and `preview --watch` follow it
// live. The devices are those of acquire/devices/device.h, chosen by URI.
//
// <out>/
//   dataset.json          the complete positions so far (missing_positions: the others)
//   photos/pos_<i>_<j>_<p|n>_<k>.<ext>, photos/board.<ext>
//   capture/setup.json    the setup the capture ran with (lab block included)
//   capture/exposure.json the bracket chosen (kept: a resumed capture uses the same)
//   capture/shots.csv     the journal: each photo once checked, and each finished slide
//   capture/devices.log   every command sent to a device and every reply
//   capture/test/         the test shots
// Resumable: the journal says which slides of which positions are finished; a run that was
// stopped or killed at any moment goes on after them, and the photos of an unfinished slide are
// taken again.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "acquire/devices/operator.h"
#include "acquire/lab_setup.h"
#include "core/dataset.h"
#include "core/lab_model.h"
#include "lib/photo/photo_io.h"

namespace lumislab {

struct CaptureOptions {
  std::string setup_file;  // dataset.json without photos, with the "lab" block
  std::string stage_uri;
  std::string camera_uri;
  std::string out_dir;
  // slide-pass: every position through T+, then every position through T- (one slide change);
  // position: both slides at each position (the slide axis alternates p n, n p); auto:
  // slide-pass when the operator changes the slides, position with a slide axis.
  std::string order = "auto";
  bool dry_run = false;  // print the plan, touch no device and no file
  bool force = false;    // capture again over a complete dataset
  // The operator's confirmations (slides, board) from a program instead of the terminal
  // (acquire/devices/operator.h).
  std::string operator_program;
  LabModel lab;  // the predicted lab time (lumislab-plan's model)
  // `capture --orientations`: the plan (luminaire.json format), out_dir then being the
  // luminaire folder (acquire/capture_orientations.h).
  std::string orientations_file;
  // The board photo of an earlier orientation of the same run (same camera, same screen): taken
  // over instead of asking for the board again. Empty: the board is photographed.
  std::string board_photo;
  double board_shutter_s = 0;

  void Check() const;  // BadInput naming the option
};

// One slide at one position: `brackets` photos.
struct CaptureShot {
  int i = 0, j = 0;
  bool positive = true;
};

struct CapturePlan {
  std::string order;  // slide-pass or position
  std::vector<CaptureShot> shots;
  int moves = 0;         // stage moves between positions (the first one included)
  int slide_swaps = 0;   // slide changes (the first slide put in included)
  double travel_mm = 0;  // grid travel of the u, v axes, plus the slide axis'
  int photos = 0;        // slide photos (the board and test shots not included)
  double lab_s = 0;      // moves x move_s + photos x exposure_s
};

// The order of the shots and what it costs. Rows are scanned serpentine (least travel); the
// second pass of slide-pass runs the first one backwards, starting where it ended.
CapturePlan PlanCapture(const SamplingGrid& grid, const LabSetup& lab, const std::string& order,
                        const LabModel& model);
std::string DescribePlan(const SamplingGrid& grid, const LabSetup& lab, const CapturePlan& plan,
                         const LabModel& model);

struct CaptureReport {
  bool skipped = false;  // the dataset was complete already
  bool dry_run = false;
  int shots_done = 0;     // shots finished by this run
  int shots_resumed = 0;  // shots finished by an earlier run
  int photos = 0;         // slide photos in dataset.json
  int reshots = 0;        // photos taken again shorter because they clipped
  // --orientations: the orientations captured by this run, and those complete before it.
  int orientations_done = 0;
  int orientations_resumed = 0;
};

// The devices of one run, opened from their URIs and connected once: a run of several
// orientations keeps them connected from one dataset to the next. The log writes to the
// capture/devices.log of the dataset being captured.
struct CaptureDevices {
  std::unique_ptr<Stage> stage;
  std::unique_ptr<Camera> camera;
  std::unique_ptr<DeviceLog> log;
  std::unique_ptr<Operator> op;
  bool connected = false;
  bool homed = false;

  // The devices of `options`' URIs, not connected yet (BadInput for a URI that names none).
  static CaptureDevices Open(const CaptureOptions& options);
  // Connects the camera, then the stage (BadInput naming the device when one cannot be used).
  void Connect(const LabSetup& lab);
  void Close() noexcept;
};

// The board photo a dataset's capture journal records (capture/shots.csv), if any.
struct JournalBoard {
  std::string path;
  double shutter_s = 0;
};
std::optional<JournalBoard> CapturedBoard(const std::string& dataset_dir);

// Runs the capture. BadInput (exit 2) before any device moves for a setup, URI, device or travel
// that cannot work; DeviceError / DeviceStopped (exit 1) mid-run, with dataset.json as the last
// complete position left it; IoError (exit 3) when a photo cannot be stored.
CaptureReport RunCapture(const CaptureOptions& options);
// RunCapture's work on one dataset after its checks, with `devices` connected here unless they
// are already; they are closed on an error and left open otherwise.
CaptureReport CaptureDataset(const CaptureOptions& options, Dataset setup, LabSetup lab,
                             CaptureDevices* devices);

// What a photo shows: the 99.99th percentile of its largest linear channel (exposure 1, the
// setup's transfer and levels) and the fraction of its pixels clipped in some channel.
struct PhotoLevels {
  double peak = 0;
  double clipped = 0;
};
PhotoLevels MeasurePhotoLevels(const Dataset& setup, const std::string& path);
// The same of a photo decoded with DecodeForLevels: the setup's transfer and levels, exposure 1.
PhotoLevels MeasurePhotoLevels(const Photo& photo);
Photo DecodeForLevels(const Dataset& setup, const std::string& path);

}  // namespace lumislab
