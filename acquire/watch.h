// lumislab-acquire watch: `import` while the photos arrive (docs/formats.md §3), from any
// tethering software (gphoto2 --capture-tethered, a camera vendor's tool, a copy). dataset.json
// is written at once with the setup and no photos, then rewritten (atomically) each time a grid
// position becomes complete, so that `reconstruct --watch` and `preview --watch` follow a real
// capture live.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "acquire/import.h"

namespace lumislab {

struct WatchOptions {
  ImportOptions import;  // the folder, setup, dataset and how the photos are named (not partial)
  // A file is taken once its size and modification time have not changed for this long (s),
  // then decoded (BadInput when it is not a whole image): a file still being copied is waited
  // for, not read, unless its copy stalls for this long.
  double settle_s = 1;
  double poll_s = 0.2;        // s between two looks at the folder
  double idle_timeout_s = 0;  // stop after this long without a new or growing file (0: never)

  void Check() const;  // BadInput naming the option
};

struct WatchReport {
  bool skipped = false;                      // dataset.json was complete already (no --force)
  bool complete = false;                     // every position and the board photo arrived
  bool stopped = false;                      // a stop signal ended it
  bool idle = false;                         // --idle-timeout ended it
  int photos = 0;                            // slide photos listed
  std::vector<std::pair<int, int>> missing;  // positions not complete at the end
  std::vector<std::string> unused;           // files no photo entry names
};

// Watches until the capture is complete, a stop signal (core/stop_signal.h) or the idle
// timeout. A photo that is bad once it has settled (not an image, cut short, another camera,
// size, lens or ISO, named twice, out of order) is BadInput naming it.
WatchReport RunWatch(const WatchOptions& options);

}  // namespace lumislab
