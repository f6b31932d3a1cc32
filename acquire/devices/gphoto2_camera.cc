#include "acquire/devices/gphoto2_camera.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <gphoto2/gphoto2.h>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <sstream>
#include <thread>

#include "core/atomic_file.h"
#include "core/log.h"
#include "core/stop_signal.h"
#include "lib/photo/exif.h"

namespace lumislab {
namespace {

// Under the sanitizers only (the sanitizer build's tests): libgphoto2 loads every camera and port
// driver to list them and unloads them again, and loads the camera's driver again to connect.
// What those drivers and the libraries they pull in allocate and never free (libheif's
// constructor through libgd; libusb's device list through usb1.so; ptp2.so's parameters when
// gp_camera_init fails, which skips its camera_exit: each reproduced by a plain C program) then
// has no module name for fuzz/sanitizers/lsan.supp to match, and LeakSanitizer's thread tracer
// crashed on the dynamic TLS the unloaded libraries left behind. Loaded here once for good
// (RTLD_NODELETE), libgphoto2's own loads find them resident and never unload them.
void KeepDriversLoaded() {
#if defined(LUMISLAB_SANITIZED) && defined(LUMISLAB_GPHOTO2_CAMLIBS)
  static std::once_flag once;
  std::call_once(once, [] {
    for (const char* dir : {LUMISLAB_GPHOTO2_IOLIBS, LUMISLAB_GPHOTO2_CAMLIBS}) {
      std::error_code ec;
      for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
        if (entry.path().extension() == ".so")
          dlopen(entry.path().c_str(), RTLD_LAZY | RTLD_LOCAL | RTLD_NODELETE);
    }
  });
#endif
}

using Clock = std::chrono::steady_clock;

// The generic PTP/IP model of camlibs/ptp2 (its ptpip_models table).
const char kPtpipModel[] = "PTP/IP Camera";
// PTP holds exposure times in units of 0.1 ms, so a generic PTP camera's times are rounded to it.
constexpr double kPtpExposureUnitS = 1e-4;

std::string Lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

std::string Join(const std::vector<std::string>& items, const std::string& none = "none") {
  if (items.empty()) return none;
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : ", ") + item;
  return text;
}

std::string FormatSeconds(double s) { return Num(s, 6) + " s"; }

// libgphoto2's ptpip code writes to sockets with write(), so a camera that went away raises
// SIGPIPE, which would end the process. While a call runs, SIGPIPE is blocked in this thread and
// one raised meanwhile is taken off the pending set before it is unblocked.
class SigpipeBlock {
 public:
  SigpipeBlock() {
    sigemptyset(&pipe_);
    sigaddset(&pipe_, SIGPIPE);
    sigset_t pending;
    sigpending(&pending);
    was_pending_ = sigismember(&pending, SIGPIPE) == 1;
    pthread_sigmask(SIG_BLOCK, &pipe_, &old_);
  }
  ~SigpipeBlock() {
    sigset_t pending;
    sigpending(&pending);
    if (!was_pending_ && sigismember(&pending, SIGPIPE) == 1) {
      const timespec zero{0, 0};
      sigtimedwait(&pipe_, nullptr, &zero);
    }
    pthread_sigmask(SIG_SETMASK, &old_, nullptr);
  }
  SigpipeBlock(const SigpipeBlock&) = delete;
  SigpipeBlock& operator=(const SigpipeBlock&) = delete;

 private:
  sigset_t pipe_, old_;
  bool was_pending_ = false;
};

// libgphoto2 2.5.28 to at least 2.5.31 closes file descriptor 0 at every PTP/IP camera's exit:
// ptp_ptpip_disconnect closes params->jpgfd, the socket of Fuji's JPEG stream, which the generic
// PTP/IP connection never opens and leaves at 0. That is stdin, or whatever socket or file took
// the number 0 later (a second camera's connection, a listening socket). So fd 0 is kept open
// while libgphoto2 runs (/dev/null when it was closed, so that no socket of ours gets 0), and
// after a call that may have closed it, stdin is put back unless another thread took 0 meanwhile.
void KeepDescriptorZeroOpen() {
  if (::fcntl(0, F_GETFD) != -1) return;
  const int fd = ::open("/dev/null", O_RDONLY);
  if (fd > 0) ::close(fd);  // another thread took 0 first: that is as good
}

class DescriptorZeroGuard {
 public:
  DescriptorZeroGuard() {
    KeepDescriptorZeroOpen();
    saved_ = ::fcntl(0, F_DUPFD_CLOEXEC, 3);
  }
  ~DescriptorZeroGuard() {
    if (saved_ < 0) return;
    if (::fcntl(0, F_GETFD) == -1) {
      const int fd = ::fcntl(saved_, F_DUPFD, 0);  // the lowest free number: 0 unless taken
      if (fd > 0) ::close(fd);
    }
    ::close(saved_);
  }
  DescriptorZeroGuard(const DescriptorZeroGuard&) = delete;
  DescriptorZeroGuard& operator=(const DescriptorZeroGuard&) = delete;

 private:
  int saved_ = -1;
};

// libgphoto2's error log lines go to the camera whose call is running in this thread.
thread_local std::vector<std::string>* current_messages = nullptr;

void OnContextText(GPContext*, const char* text, void*) {
  if (current_messages && text) current_messages->push_back(text);
}

void OnLogLine(GPLogLevel, const char* domain, const char* text, void*) {
  if (current_messages && text) current_messages->push_back(std::string(domain) + ": " + text);
}

GPContextFeedback OnCancelQuery(GPContext*, void*) {
  return StopRequested() ? GP_CONTEXT_FEEDBACK_CANCEL : GP_CONTEXT_FEEDBACK_OK;
}

// A number at the start of `text`: its value and how many characters it took; 0 when none.
size_t ReadNumber(const std::string& text, size_t at, double* value) {
  const char* begin = text.c_str() + at;
  char* end = nullptr;
  *value = std::strtod(begin, &end);
  if (end == begin || !std::isfinite(*value)) return 0;
  return static_cast<size_t>(end - begin);
}

// The value of an aperture or ISO choice for comparing spellings ("f/8" and "8", "8.0").
std::optional<double> NumberIn(const std::string& choice) {
  std::string text = Lower(choice);
  if (text.rfind("f/", 0) == 0) text = text.substr(2);
  double value = 0;
  const size_t n = ReadNumber(text, 0, &value);
  if (n == 0 || n != text.size()) return std::nullopt;
  return value;
}

// "ptpip:<host>:<port>" -> "ptpip:<host>:<port>:<port>". A PTP/IP camera takes its command and
// event connections on one port, but camlibs/ptp2 (ptp_ptpip_connect) opens the event connection
// on 15740 unless the path names another port after the command port.
std::string WithEventPort(const std::string& port) {
  if (port.rfind("ptpip:", 0) != 0) return port;
  const size_t host_end = port.find(':', 6);
  if (host_end == std::string::npos || port.find(':', host_end + 1) != std::string::npos)
    return port;
  return port + port.substr(host_end);
}

}  // namespace

std::optional<double> ParseShutterSpeed(const std::string& choice) {
  std::string text = Lower(choice);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.pop_back();
  if (!text.empty() && (text.back() == 's' || text.back() == '"')) text.pop_back();
  if (text.empty() || !std::isdigit(static_cast<unsigned char>(text[0]))) return std::nullopt;
  double whole = 0, numerator = 0, denominator = 0;
  size_t at = ReadNumber(text, 0, &whole);
  if (at == 0) return std::nullopt;
  if (at == text.size()) return whole > 0 ? std::optional<double>(whole) : std::nullopt;
  if (text[at] == ' ') {  // "1 1/3"
    const size_t n = ReadNumber(text, at + 1, &numerator);
    if (n == 0 || at + 1 + n >= text.size() || text[at + 1 + n] != '/') return std::nullopt;
    at += 1 + n;
  } else {
    numerator = whole;
    whole = 0;
  }
  if (text[at] != '/') return std::nullopt;
  const size_t n = ReadNumber(text, at + 1, &denominator);
  if (n == 0 || at + 1 + n != text.size() || denominator <= 0) return std::nullopt;
  const double seconds = whole + numerator / denominator;
  return seconds > 0 ? std::optional<double>(seconds) : std::nullopt;
}

std::unique_ptr<Camera> MakeGphoto2Camera(const std::string& uri, const std::string& model,
                                          const std::string& port) {
  return std::make_unique<Gphoto2Camera>(uri, model, port);
}

Gphoto2Camera::Gphoto2Camera(std::string uri, std::string model, std::string port)
    : Camera(std::move(uri)), model_(std::move(model)), port_(std::move(port)) {
  log_ = &no_log_;
}

Gphoto2Camera::~Gphoto2Camera() { Close(); }

// Runs one libgphoto2 call: logs it and its result, collects what libgphoto2 says meanwhile.
template <typename F>
int Gphoto2Camera::Run(const std::string& text, F&& call) {
  messages_.clear();
  log_->Sent(uri(), text);
  int result;
  {
    SigpipeBlock block;
    current_messages = &messages_;
    result = call();
    current_messages = nullptr;
  }
  log_->Received(uri(), result >= GP_OK ? "OK" : Describe(result));
  for (const std::string& message : messages_) log_->Note(uri(), "libgphoto2: " + message);
  return result;
}

std::string Gphoto2Camera::Describe(int result) const {
  std::string text = gp_result_as_string(result);
  text += " (" + std::to_string(result) + ")";
  // The last few lines libgphoto2 logged: the cause is usually among them.
  const size_t first = messages_.size() > 3 ? messages_.size() - 3 : 0;
  for (size_t i = first; i < messages_.size(); ++i) text += "; " + messages_[i];
  return text;
}

std::vector<Gphoto2Camera::Detected> Gphoto2Camera::Detect() {
  CameraList* list = nullptr;
  gp_list_new(&list);
  std::vector<Detected> found;
  if (Run("gp_abilities_list_detect",
          [&] { return gp_abilities_list_detect(abilities_, ports_, list, context_); }) >= GP_OK) {
    for (int i = 0; i < gp_list_count(list); ++i) {
      const char* name = nullptr;
      const char* value = nullptr;
      gp_list_get_name(list, i, &name);
      gp_list_get_value(list, i, &value);
      found.push_back({name ? name : "", value ? value : ""});
      log_->Note(uri(), "detected " + found.back().model + " at " + found.back().port);
    }
  }
  gp_list_free(list);
  return found;
}

// Fills in the model or port the URI left out: a ptpip: port is the generic PTP/IP model;
// anything else is autodetected (USB). BadInput naming what was found when nothing fits.
void Gphoto2Camera::ChooseModelAndPort(std::string* model, std::string* port) {
  if (!port->empty() && gp_port_info_list_lookup_path(ports_, port->c_str()) < GP_OK) {
    std::vector<std::string> paths;
    for (int i = 0; i < gp_port_info_list_count(ports_); ++i) {
      GPPortInfo info;
      char* path = nullptr;
      if (gp_port_info_list_get_info(ports_, i, &info) >= GP_OK &&
          gp_port_info_get_path(info, &path) >= GP_OK && path && *path)
        paths.push_back(path);
    }
    throw BadInput(uri() + ": connecting: libgphoto2 has no port " + *port +
                   " (ports: " + Join(paths) + ")");
  }
  if (!model->empty() && gp_abilities_list_lookup_model(abilities_, model->c_str()) < GP_OK) {
    // The models that share the most words with it ("Canon EOS 8OD": the Canon EOS models).
    const auto words = [](const std::string& text) {
      std::vector<std::string> out;
      std::istringstream in(Lower(text));
      for (std::string w; in >> w;) out.push_back(w);
      return out;
    };
    const std::vector<std::string> wanted = words(*model);
    std::vector<std::pair<int, std::string>> scored;
    for (int i = 0; i < gp_abilities_list_count(abilities_); ++i) {
      CameraAbilities a;
      if (gp_abilities_list_get_abilities(abilities_, i, &a) < GP_OK) continue;
      int shared = 0;
      for (const std::string& w : words(a.model))
        shared += std::count(wanted.begin(), wanted.end(), w) > 0;
      if (shared > 0) scored.emplace_back(-shared, a.model);
    }
    std::sort(scored.begin(), scored.end());
    std::vector<std::string> similar;
    for (size_t i = 0; i < scored.size() && i < 12; ++i)
      similar.push_back("\"" + scored[i].second + "\"");
    throw BadInput(uri() + ": connecting: libgphoto2 knows no camera model \"" + *model +
                   "\" (models like it: " + Join(similar) + ")");
  }
  if (model->empty() && port->rfind("ptpip:", 0) == 0) *model = kPtpipModel;
  *port = WithEventPort(*port);
  if (!model->empty() && !port->empty()) return;

  const std::vector<Detected> found = Detect();
  for (const Detected& d : found) {
    if ((model->empty() || d.model == *model) && (port->empty() || d.port == *port)) {
      *model = d.model;
      *port = d.port;
      return;
    }
  }
  std::vector<std::string> listed;
  for (const Detected& d : found) listed.push_back(d.model + " at " + d.port);
  throw BadInput(uri() + ": connecting: no camera" + (model->empty() ? "" : " " + *model) +
                 " found" + (port->empty() ? "" : " at " + *port) + " (detected: " + Join(listed) +
                 ")");
}

void Gphoto2Camera::Connect(const CameraSettings& settings, DeviceLog* log) {
  Close();
  if (StopRequested()) throw DeviceStopped(uri(), "connecting");
  settings_ = settings;
  log_ = log ? log : &no_log_;
  context_ = gp_context_new();
  gp_context_set_error_func(context_, OnContextText, nullptr);
  gp_context_set_message_func(context_, OnContextText, nullptr);
  gp_context_set_cancel_func(context_, OnCancelQuery, nullptr);
  // One log function for the process (it files each line under the camera whose call runs in
  // the thread): one per camera would file every line once per camera.
  static std::once_flag log_func_added;
  std::call_once(log_func_added, [] { gp_log_add_func(GP_LOG_ERROR, OnLogLine, nullptr); });

  KeepDriversLoaded();
  gp_abilities_list_new(&abilities_);
  gp_port_info_list_new(&ports_);
  if (Run("gp_abilities_list_load", [&] { return gp_abilities_list_load(abilities_, context_); }) <
          GP_OK ||
      Run("gp_port_info_list_load", [&] { return gp_port_info_list_load(ports_); }) < GP_OK)
    throw BadInput(uri() + ": connecting: libgphoto2 cannot load its camera drivers: " +
                   Describe(GP_ERROR_LIBRARY));
  std::string model = model_, port = port_;
  ChooseModelAndPort(&model, &port);

  KeepDescriptorZeroOpen();  // so that libgphoto2's sockets do not get 0
  gp_camera_new(&camera_);
  CameraAbilities abilities;
  gp_abilities_list_get_abilities(
      abilities_, gp_abilities_list_lookup_model(abilities_, model.c_str()), &abilities);
  gp_camera_set_abilities(camera_, abilities);
  GPPortInfo info;
  gp_port_info_list_get_info(ports_, gp_port_info_list_lookup_path(ports_, port.c_str()), &info);
  gp_camera_set_port_info(camera_, info);
  const int result = Run("gp_camera_init " + model + " @ " + port,
                         [&] { return gp_camera_init(camera_, context_); });
  if (result < GP_OK) {
    const std::string what = Describe(result);
    gp_camera_free(camera_);
    camera_ = nullptr;
    throw BadInput(uri() + ": connecting: no camera answers as " + model + " at " + port + ": " +
                   what);
  }
  if (!settings.aperture.empty())
    ApplyChoice({"f-number", "aperture"}, settings.aperture, "aperture");
  if (!settings.iso.empty()) ApplyChoice({"iso", "isospeed"}, settings.iso, "iso");
  if (!settings.image_format.empty())
    ApplyChoice({"imageformat", "imagequality"}, settings.image_format, "image_format");
  ReadShutterSpeeds();
}

// Sets the first of the widgets `names` the camera has to the choice that `value` spells (the
// same text, or the same number: "8" is "f/8"). BadInput listing the choices otherwise.
void Gphoto2Camera::ApplyChoice(const std::vector<std::string>& names, const std::string& value,
                                const std::string& what) {
  CameraWidget* widget = nullptr;
  std::string name;
  for (const std::string& n : names) {
    if (Run("gp_camera_get_single_config " + n, [&] {
          return gp_camera_get_single_config(camera_, n.c_str(), &widget, context_);
        }) >= GP_OK) {
      name = n;
      break;
    }
  }
  if (!widget)
    throw BadInput(uri() + ": connecting: " + what + " \"" + value +
                   "\": the camera has no such setting (no widget " + Join(names) + ")");
  std::vector<std::string> choices;
  CameraWidgetType type;
  gp_widget_get_type(widget, &type);
  if (type == GP_WIDGET_RADIO || type == GP_WIDGET_MENU) {
    for (int i = 0; i < gp_widget_count_choices(widget); ++i) {
      const char* choice = nullptr;
      if (gp_widget_get_choice(widget, i, &choice) >= GP_OK && choice) choices.push_back(choice);
    }
  }
  std::string chosen;
  if (type == GP_WIDGET_TEXT) chosen = value;
  for (const std::string& c : choices)
    if (Lower(c) == Lower(value)) chosen = c;
  const std::optional<double> number = NumberIn(value);
  for (const std::string& c : choices)
    if (chosen.empty() && number && NumberIn(c) && std::fabs(*NumberIn(c) - *number) < 1e-6)
      chosen = c;
  if (chosen.empty()) {
    gp_widget_free(widget);
    throw BadInput(uri() + ": connecting: " + what + " \"" + value +
                   "\" is not one the camera offers (" + name + ": " + Join(choices) + ")");
  }
  gp_widget_set_value(widget, chosen.c_str());
  const int result = Run("gp_camera_set_single_config " + name + " " + chosen, [&] {
    return gp_camera_set_single_config(camera_, name.c_str(), widget, context_);
  });
  gp_widget_free(widget);
  if (result < GP_OK)
    throw BadInput(uri() + ": connecting: the camera refused " + what + " \"" + chosen +
                   "\": " + Describe(result));
}

void Gphoto2Camera::ReadShutterSpeeds() {
  shutter_choices_.clear();
  CameraWidget* widget = nullptr;
  if (Run("gp_camera_get_single_config shutterspeed", [&] {
        return gp_camera_get_single_config(camera_, "shutterspeed", &widget, context_);
      }) < GP_OK)
    return;  // SetShutterSpeed says so
  for (int i = 0; i < gp_widget_count_choices(widget); ++i) {
    const char* choice = nullptr;
    if (gp_widget_get_choice(widget, i, &choice) < GP_OK || !choice) continue;
    if (const std::optional<double> s = ParseShutterSpeed(choice))
      shutter_choices_.emplace_back(*s, choice);
  }
  gp_widget_free(widget);
  std::sort(shutter_choices_.begin(), shutter_choices_.end());
  log_->Note(uri(), std::to_string(shutter_choices_.size()) + " shutter speeds from " +
                        (shutter_choices_.empty() ? "-" : shutter_choices_.front().second) +
                        " to " + (shutter_choices_.empty() ? "-" : shutter_choices_.back().second));
}

std::vector<double> Gphoto2Camera::ShutterSpeeds() {
  std::vector<double> seconds;
  for (const auto& [s, choice] : shutter_choices_)
    if (seconds.empty() || s > seconds.back()) seconds.push_back(s);
  return seconds;
}

void Gphoto2Camera::SetShutterSpeed(double seconds) {
  if (!camera_) throw DeviceError(uri(), "setting the shutter speed", "not connected");
  if (shutter_choices_.empty())
    throw BadInput(uri() + ": setting the shutter speed " + FormatSeconds(seconds) +
                   ": the camera offers no shutterspeed setting (is it in manual mode?)");
  const std::pair<double, std::string>* best = nullptr;
  for (const auto& choice : shutter_choices_)
    if (!best || std::fabs(choice.first - seconds) < std::fabs(best->first - seconds))
      best = &choice;
  if (std::fabs(best->first - seconds) > 0.01 * seconds) {
    std::vector<std::string> labels;
    for (const auto& choice : shutter_choices_) labels.push_back(choice.second);
    throw BadInput(uri() + ": setting the shutter speed " + FormatSeconds(seconds) +
                   ": not one the camera offers within 1 % (shutterspeed: " + Join(labels) + ")");
  }
  CameraWidget* widget = nullptr;
  int result = Run("gp_camera_get_single_config shutterspeed", [&] {
    return gp_camera_get_single_config(camera_, "shutterspeed", &widget, context_);
  });
  if (result >= GP_OK) {
    gp_widget_set_value(widget, best->second.c_str());
    result = Run("gp_camera_set_single_config shutterspeed " + best->second, [&] {
      return gp_camera_set_single_config(camera_, "shutterspeed", widget, context_);
    });
    gp_widget_free(widget);
  }
  if (result < GP_OK)
    throw DeviceError(uri(), "setting the shutter speed " + best->second, Describe(result));
  shutter_s_ = best->first;
}

// Waits for the file the trigger made: gp_camera_wait_for_event in 50 ms slices, so that a stop
// signal or capture_timeout_s ends the wait. Returns its folder and name on the camera.
std::pair<std::string, std::string> Gphoto2Camera::WaitForNewFile() {
  const Clock::time_point deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(settings_.capture_timeout_s));
  while (true) {
    if (StopRequested()) throw DeviceStopped(uri(), "capturing");
    if (Clock::now() > deadline)
      throw DeviceError(uri(), "capturing",
                        "no photo within capture_timeout_s " +
                            FormatSeconds(settings_.capture_timeout_s) + " of the trigger");
    CameraEventType type = GP_EVENT_UNKNOWN;
    void* data = nullptr;
    const Clock::time_point start = Clock::now();
    // Not logged, a line each slice would flood the log; what arrives is.
    messages_.clear();
    int result;
    {
      SigpipeBlock block;
      current_messages = &messages_;
      result = gp_camera_wait_for_event(camera_, 50, &type, &data, context_);
      current_messages = nullptr;
    }
    if (result < GP_OK) {
      free(data);
      log_->Received(uri(), "gp_camera_wait_for_event: " + Describe(result));
      throw DeviceError(uri(), "capturing", "waiting for the photo: " + Describe(result));
    }
    if (type == GP_EVENT_FILE_ADDED) {
      const auto* path = static_cast<CameraFilePath*>(data);
      std::pair<std::string, std::string> file(path->folder, path->name);
      free(data);
      log_->Received(uri(), "file added " + file.first + "/" + file.second);
      return file;
    }
    if (type == GP_EVENT_CAPTURE_COMPLETE) log_->Received(uri(), "capture complete");
    if (type == GP_EVENT_UNKNOWN && data)
      log_->Received(uri(), std::string("event ") + static_cast<const char*>(data));
    free(data);
    // The generic PTP wait returns after 1 ms whatever the timeout: no need to poll faster.
    std::this_thread::sleep_until(start + std::chrono::milliseconds(10));
  }
}

void Gphoto2Camera::Download(const std::string& folder, const std::string& name,
                             const std::string& path) {
  // Into memory first, then written by us: a write that fails (a full disk) is then an IoError
  // naming the file and the system's reason, not one of libgphoto2's generic errors.
  CameraFile* file = nullptr;
  gp_file_new(&file);
  const int result = Run("gp_camera_file_get " + folder + "/" + name, [&] {
    return gp_camera_file_get(camera_, folder.c_str(), name.c_str(), GP_FILE_TYPE_NORMAL, file,
                              context_);
  });
  if (StopRequested() || result < GP_OK) {
    gp_file_free(file);
    if (StopRequested()) throw DeviceStopped(uri(), "downloading " + name);
    throw DeviceError(uri(), "downloading " + name, Describe(result));
  }
  const char* data = nullptr;
  unsigned long size = 0;
  gp_file_get_data_and_size(file, &data, &size);
  try {
    WriteAtomically(path, [&](const std::string& tmp_path) {
      const int fd = ::open(tmp_path.c_str(), O_CREAT | O_WRONLY | O_TRUNC | O_CLOEXEC, 0644);
      if (fd < 0)
        throw IoError(tmp_path, std::string("cannot create the photo: ") + std::strerror(errno));
      size_t done = 0;
      while (done < size) {
        const ssize_t n = ::write(fd, data + done, size - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
          const std::string reason = std::strerror(n < 0 ? errno : ENOSPC);
          ::close(fd);
          throw IoError(path, "cannot write the downloaded photo: " + reason);
        }
        done += size_t(n);
      }
      if (::close(fd) != 0)
        throw IoError(path,
                      std::string("cannot write the downloaded photo: ") + std::strerror(errno));
    });
  } catch (...) {
    gp_file_free(file);
    throw;
  }
  gp_file_free(file);
}

// The exposure the camera used, from the photo's EXIF, against the one set: a camera that did
// not take the setting (auto mode, a dial that overrides) would spoil the whole capture.
void Gphoto2Camera::CheckExposure(const std::string& path) {
  PhotoExif exif;
  try {
    exif = ReadPhotoExif(path);
  } catch (const Error& e) {
    throw DeviceError(uri(), "downloading", std::string("the photo is not readable: ") + e.what());
  }
  if (!exif.exposure_time) {
    log_->Note(uri(), path + ": no exposure time in its EXIF");
    return;
  }
  log_->Note(uri(), path + ": EXIF exposure time " + FormatSeconds(*exif.exposure_time));
  const double tolerance = std::max(0.01 * shutter_s_, kPtpExposureUnitS);
  if (shutter_s_ > 0 && std::fabs(*exif.exposure_time - shutter_s_) > tolerance)
    throw DeviceError(uri(), "capturing",
                      path + " was exposed " + FormatSeconds(*exif.exposure_time) + ", not the " +
                          FormatSeconds(shutter_s_) + " set: the camera did not take the setting");
}

std::string Gphoto2Camera::Capture(const std::string& path_stem) {
  if (!camera_) throw DeviceError(uri(), "capturing", "not connected");
  if (StopRequested()) throw DeviceStopped(uri(), "capturing");
  const int result = Run("gp_camera_trigger_capture",
                         [&] { return gp_camera_trigger_capture(camera_, context_); });
  if (result < GP_OK) throw DeviceError(uri(), "capturing", Describe(result));
  // Named copies, not structured bindings: clang 14 cannot capture those in a lambda.
  const std::pair<std::string, std::string> file = WaitForNewFile();
  const std::string folder = file.first, name = file.second;
  const size_t dot = name.rfind('.');
  const std::string extension = dot == std::string::npos ? "" : Lower(name.substr(dot + 1));
  if (extension.empty())
    throw DeviceError(uri(), "downloading " + name, "the camera's file name has no extension");
  const std::string path = path_stem + "." + extension;
  Download(folder, name, path);
  if (settings_.delete_from_card) {
    const int deleted = Run("gp_camera_file_delete " + folder + "/" + name, [&] {
      return gp_camera_file_delete(camera_, folder.c_str(), name.c_str(), context_);
    });
    if (deleted < GP_OK)
      throw DeviceError(uri(), "deleting " + name + " from the card", Describe(deleted));
  }
  CheckExposure(path);
  return path;
}

void Gphoto2Camera::Close() noexcept {
  try {
    if (camera_) {
      DescriptorZeroGuard guard;
      Run("gp_camera_exit", [&] { return gp_camera_exit(camera_, context_); });
      gp_camera_free(camera_);
    }
  } catch (...) {  // logging failed: the device log's disk is full; closing goes on
  }
  camera_ = nullptr;
  if (abilities_) gp_abilities_list_free(abilities_);
  abilities_ = nullptr;
  if (ports_) gp_port_info_list_free(ports_);
  ports_ = nullptr;
  if (context_) gp_context_unref(context_);
  context_ = nullptr;
  shutter_choices_.clear();
}

}  // namespace lumislab
