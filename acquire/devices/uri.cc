#include "acquire/devices/uri.h"

#include "acquire/devices/command_camera.h"
#include "acquire/devices/command_stage.h"
#include "acquire/devices/gphoto2_camera.h"
#include "acquire/devices/grbl_stage.h"

namespace lumislab {
namespace {

bool Scheme(const std::string& uri, const std::string& scheme, std::string* rest) {
  if (uri.compare(0, scheme.size() + 1, scheme + ":") != 0) return false;
  *rest = uri.substr(scheme.size() + 1);
  return true;
}

}  // namespace

std::unique_ptr<Stage> MakeStage(const std::string& uri) {
  std::string rest;
  if (uri == "manual") return MakeManualStage(uri);
  if (Scheme(uri, "grbl", &rest)) {
    std::string port = rest;
    int baud = 115200;
    const size_t q = rest.find('?');
    if (q != std::string::npos) {
      port = rest.substr(0, q);
      const std::string query = rest.substr(q + 1);
      const std::string key = "baud=";
      size_t used = 0;
      bool ok = query.compare(0, key.size(), key) == 0;
      if (ok) {
        try {
          baud = std::stoi(query.substr(key.size()), &used);
        } catch (...) {
          ok = false;
        }
        ok = ok && used == query.size() - key.size();
      }
      static const int kBauds[] = {9600, 19200, 38400, 57600, 115200, 230400, 250000};
      bool known = false;
      for (int b : kBauds) known = known || b == baud;
      if (!ok || !known)
        throw InputError("--stage", "",
                         "grbl:<port>[?baud=N], N one of 9600, 19200, 38400, "
                         "57600, 115200, 230400, 250000",
                         uri);
    }
    if (port.empty()) throw InputError("--stage", "", "grbl:<port> (a serial port)", uri);
    return MakeGrblStage(uri, port, baud);
  }
  if (Scheme(uri, "command", &rest)) {
    if (rest.empty()) throw InputError("--stage", "", "command:<program>", uri);
    return MakeCommandStage(uri, rest);
  }
  throw InputError("--stage", "",
                   "a stage URI: grbl:<serial port>[?baud=N], command:<program> or manual", uri);
}

std::unique_ptr<Camera> MakeCamera(const std::string& uri) {
  std::string rest;
  if (uri == "gphoto2" || Scheme(uri, "gphoto2", &rest) || uri.rfind("gphoto2@", 0) == 0) {
    // gphoto2[:<model>][@<port>]: the port is after the last '@' (a model name has none).
    std::string spec = uri.substr(std::string("gphoto2").size());
    if (!spec.empty() && spec[0] == ':') spec.erase(0, 1);
    std::string model = spec, port;
    const size_t at = spec.rfind('@');
    if (at != std::string::npos) {
      model = spec.substr(0, at);
      port = spec.substr(at + 1);
      if (port.empty()) throw InputError("--camera", "", "gphoto2[:<model>][@<port>]", uri);
    }
    return MakeGphoto2Camera(uri, model, port);
  }
  if (Scheme(uri, "command", &rest)) {
    if (rest.empty()) throw InputError("--camera", "", "command:<program>", uri);
    return MakeCommandCamera(uri, rest);
  }
  if (Scheme(uri, "folder", &rest)) {
    if (rest.empty()) throw InputError("--camera", "", "folder:<dir>", uri);
    return MakeFolderCamera(uri, rest);
  }
  throw InputError("--camera", "",
                   "a camera URI: gphoto2[:<model>][@<port>], command:<program> or folder:<dir>",
                   uri);
}

}  // namespace lumislab
