// Cameras lumislab cannot talk to itself: `command:<program>` (a capture program that writes a
// photo where it is told) and `folder:<dir>` (a tethering program saves each photo in a folder;
// lumislab waits for it). Neither can be set by lumislab: the exposure time of each photo is
// passed to the program, or shown to the operator, and read back from the photo's EXIF.
#pragma once

#include <memory>
#include <string>

#include "acquire/devices/device.h"

namespace lumislab {

// command:<program>. A photo is `<program> capture <path> <exposure time s>`: the program writes
// the photo to <path> (any format lumislab reads: the extension comes from its content) and
// exits 0. Bounded by capture_timeout_s.
std::unique_ptr<Camera> MakeCommandCamera(const std::string& uri, const std::string& program);
// folder:<dir>. Each Capture waits (capture_timeout_s) for the next new file in <dir> that has
// stopped growing (acquire/settle_tracker.h) and copies it into the capture; the files there at
// Connect are not photos of this capture. The exposure time wanted is told on the terminal.
std::unique_ptr<Camera> MakeFolderCamera(const std::string& uri, const std::string& dir);

// The file extension (lower case, no dot) of a photo by its content: jpg, tif, png, exr, or the
// camera's raw extension `raw_extension` (dng when empty). BadInput naming `path` when it is no
// photo lumislab reads.
std::string PhotoExtensionOf(const std::string& path, const std::string& raw_extension = "");

}  // namespace lumislab
