// The device a URI names (acquire/devices/device.h): the scheme picks the driver, the rest is
// the driver's. An unknown scheme or a malformed URI is BadInput naming the option and listing
// the schemes.
#pragma once

#include <memory>
#include <string>

#include "acquire/devices/device.h"

namespace lumislab {

// grbl:<port>[?baud=N] | command:<program> | manual
std::unique_ptr<Stage> MakeStage(const std::string& uri);
// gphoto2[:<model>][@<port>] | command:<program> | folder:<dir>
std::unique_ptr<Camera> MakeCamera(const std::string& uri);

}  // namespace lumislab
