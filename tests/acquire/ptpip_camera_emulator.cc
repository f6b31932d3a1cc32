#include "ptpip_camera_emulator.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <sstream>

#include "core/error.h"
#include "lib/photo/camera_write.h"

namespace lumislab {
namespace {

using Clock = std::chrono::steady_clock;

// PTP/IP packet types (CIPA DC-005 §2.3; libgphoto2 camlibs/ptp2/ptp.h PTPIP_*).
enum : uint32_t {
  kInitCommandRequest = 1,
  kInitCommandAck = 2,
  kInitEventRequest = 3,
  kInitEventAck = 4,
  kOperationRequest = 6,
  kOperationResponse = 7,
  kEvent = 8,
  kStartData = 9,
  kData = 10,
  kEndData = 12,
  kProbeRequest = 13,
  kProbeResponse = 14,
};

// PTP operation, response and event codes, data types and object formats (ISO 15740).
enum : uint16_t {
  kGetDeviceInfo = 0x1001,
  kOpenSession = 0x1002,
  kCloseSession = 0x1003,
  kGetStorageIds = 0x1004,
  kGetStorageInfo = 0x1005,
  kGetObjectHandles = 0x1007,
  kGetObjectInfo = 0x1008,
  kGetObject = 0x1009,
  kDeleteObject = 0x100B,
  kInitiateCapture = 0x100E,
  kGetDevicePropDesc = 0x1014,
  kGetDevicePropValue = 0x1015,
  kSetDevicePropValue = 0x1016,

  kOk = 0x2001,
  kGeneralError = 0x2002,
  kSessionNotOpen = 0x2003,
  kOperationNotSupported = 0x2005,
  kInvalidStorageId = 0x2008,
  kInvalidObjectHandle = 0x2009,
  kDevicePropNotSupported = 0x200A,
  kInvalidDevicePropValue = 0x201C,
  kSessionAlreadyOpen = 0x201E,

  kObjectAdded = 0x4002,
  kCaptureComplete = 0x400D,

  kUint16 = 0x0004,
  kUint32 = 0x0006,

  kFormatUndefined = 0x3000,
  kFormatJpeg = 0x3801,
  kFormatTiff = 0x380D,
  kFormatDng = 0x3811,

  kExposureTime = 0x500D,  // UINT32, 0.1 ms
  kFNumber = 0x5007,       // UINT16, 1/100
  kExposureIndex = 0x500F  // UINT16, ISO
};

constexpr uint32_t kStorageId = 0x00010001;
constexpr double kSocketTimeoutS = 2.0;

// --- little-endian packing (PTP and PTP/IP are little-endian) ---

void Put16(std::string& out, uint16_t v) {
  out += static_cast<char>(v & 0xff);
  out += static_cast<char>(v >> 8);
}
void Put32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out += static_cast<char>((v >> (8 * i)) & 0xff);
}
void Put64(std::string& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out += static_cast<char>((v >> (8 * i)) & 0xff);
}
uint16_t Get16(const std::string& in, size_t at) {
  if (at + 2 > in.size()) return 0;
  return static_cast<uint16_t>(static_cast<uint8_t>(in[at]) | static_cast<uint8_t>(in[at + 1])
                                                                  << 8);
}
uint32_t Get32(const std::string& in, size_t at) {
  if (at + 4 > in.size()) return 0;
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i)
    v |= static_cast<uint32_t>(static_cast<uint8_t>(in[at + i])) << (8 * i);
  return v;
}
// A PTP string: the number of UCS-2 characters including the terminating zero, then those
// characters; the empty string is a single zero byte.
void PutPtpString(std::string& out, const std::string& text) {
  if (text.empty()) {
    out += '\0';
    return;
  }
  out += static_cast<char>(text.size() + 1);
  for (char c : text) Put16(out, static_cast<uint8_t>(c));
  Put16(out, 0);
}
void PutArray16(std::string& out, const std::vector<uint16_t>& values) {
  Put32(out, static_cast<uint32_t>(values.size()));
  for (uint16_t v : values) Put16(out, v);
}

std::string Hex(uint32_t v, int digits) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%0*x", digits, v);
  return text;
}

std::string OperationName(uint16_t code) {
  switch (code) {
    case kGetDeviceInfo:
      return "GetDeviceInfo";
    case kOpenSession:
      return "OpenSession";
    case kCloseSession:
      return "CloseSession";
    case kGetStorageIds:
      return "GetStorageIDs";
    case kGetStorageInfo:
      return "GetStorageInfo";
    case kGetObjectHandles:
      return "GetObjectHandles";
    case kGetObjectInfo:
      return "GetObjectInfo";
    case kGetObject:
      return "GetObject";
    case kDeleteObject:
      return "DeleteObject";
    case kInitiateCapture:
      return "InitiateCapture";
    case kGetDevicePropDesc:
      return "GetDevicePropDesc";
    case kGetDevicePropValue:
      return "GetDevicePropValue";
    case kSetDevicePropValue:
      return "SetDevicePropValue";
    default:
      return "Operation " + Hex(code, 4);
  }
}

// --- sockets: every wait bounded ---

// Waits until `fd` is readable (or writable) for at most `seconds`; false on a timeout.
bool WaitFor(int fd, short events, double seconds) {
  pollfd p{fd, events, 0};
  const int ms = static_cast<int>(std::lround(seconds * 1000));
  int n;
  do {
    n = ::poll(&p, 1, ms);
  } while (n < 0 && errno == EINTR);
  return n > 0;
}

bool ReadAll(int fd, char* data, size_t size) {
  size_t done = 0;
  while (done < size) {
    if (!WaitFor(fd, POLLIN, kSocketTimeoutS)) return false;
    // libgphoto2 writes a request and its data in separate packets without TCP_NODELAY: an
    // acknowledgement at once lets the next one go without waiting for the delayed one.
    const int yes = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_QUICKACK, &yes, sizeof yes);
    const ssize_t n = ::recv(fd, data + done, size - done, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<size_t>(n);
  }
  return true;
}

bool WriteAll(int fd, const std::string& data) {
  size_t done = 0;
  while (done < data.size()) {
    if (!WaitFor(fd, POLLOUT, kSocketTimeoutS)) return false;
    // MSG_NOSIGNAL: a host that went away is a failed send, not a SIGPIPE.
    const ssize_t n = ::send(fd, data.data() + done, data.size() - done, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<size_t>(n);
  }
  return true;
}

// One PTP/IP packet: length (u32, including this header), type (u32), payload.
bool ReadPacket(int fd, uint32_t* type, std::string* payload) {
  char header[8];
  if (!ReadAll(fd, header, sizeof header)) return false;
  const std::string h(header, sizeof header);
  const uint32_t length = Get32(h, 0);
  *type = Get32(h, 4);
  if (length < 8 || length > (64u << 20)) return false;
  payload->assign(length - 8, '\0');
  return payload->empty() || ReadAll(fd, &(*payload)[0], payload->size());
}

bool WritePacket(int fd, uint32_t type, const std::string& payload) {
  std::string packet;
  Put32(packet, static_cast<uint32_t>(payload.size() + 8));
  Put32(packet, type);
  return WriteAll(fd, packet + payload);
}

void CloseFd(int& fd) {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

// PTP units of the offered settings.
std::vector<uint32_t> ExposureUnits() {  // 0.1 ms
  std::vector<uint32_t> units;
  for (int d :
       {4000, 3200, 2500, 2000, 1600, 1250, 1000, 800, 640, 500, 400, 320, 250, 200, 160, 125,
        100,  80,   60,   50,   40,   30,   25,   20,  15,  13,  10,  8,   6,   5,   4})
    units.push_back(static_cast<uint32_t>(10000 / d));  // truncated, as PTP's integer units
  for (double s : {0.3, 0.4, 0.5, 0.6, 0.8,  1.0,  1.3,  1.6,  2.0,  2.5, 3.2,
                   4.0, 5.0, 6.0, 8.0, 10.0, 13.0, 15.0, 20.0, 25.0, 30.0})
    units.push_back(static_cast<uint32_t>(std::lround(s * 10000)));
  return units;
}
const std::vector<uint32_t> kFNumbers = {280, 320,  350,  400,  450,  500,  560,  630,  710, 800,
                                         900, 1000, 1100, 1300, 1400, 1600, 1800, 2000, 2200};
const std::vector<uint32_t> kIsos = {100,  125,  160,  200,  250,  320,  400,  500,  640, 800,
                                     1000, 1250, 1600, 2000, 2500, 3200, 4000, 5000, 6400};

uint16_t FormatOf(const std::string& extension) {
  std::string e;
  for (char c : extension) e += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (e == "jpg" || e == "jpeg") return kFormatJpeg;
  if (e == "dng") return kFormatDng;
  if (e == "tif" || e == "tiff") return kFormatTiff;
  return kFormatUndefined;  // camera RAW (CR2, NEF, ...): PTP has no code for it
}

}  // namespace

struct PtpipCameraEmulator::Connection {
  int cmd = -1;
  int evt = -1;
  bool session_open = false;
  bool capture_pending = false;
  Clock::time_point capture_due;
  uint32_t capture_transaction = 0;
  ~Connection() {
    CloseFd(cmd);
    CloseFd(evt);
  }
};

PtpipCameraEmulator::Photo PtpipCameraEmulator::DefaultPhoto(const ShotSettings& shot) {
  static std::atomic<int> counter{0};
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("lumislab_ptpip_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + ".jpg"))
          .string();
  PhotoExif exif;
  exif.exposure_time = shot.exposure_time_s;
  exif.f_number = shot.f_number;
  exif.iso = shot.iso;
  exif.make = "Lumislab";
  exif.model = "PTP/IP Emulator";
  WriteJpeg(path, cv::Mat(48, 64, CV_8UC3, cv::Scalar(90, 128, 160)), 90, exif);
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  std::filesystem::remove(path);
  return {"jpg", bytes.str()};
}

std::vector<double> PtpipCameraEmulator::ExposureTimes() {
  std::vector<double> times;
  for (uint32_t u : ExposureUnits()) times.push_back(u / 10000.0);
  return times;
}

PtpipCameraEmulator::PtpipCameraEmulator(int port, PhotoMaker maker) : maker_(std::move(maker)) {
  exposure_time_ = 80;  // 1/125 s
  f_number_ = 800;
  iso_ = 100;
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
  if (listen_fd_ < 0) throw IoError("ptpip emulator", std::strerror(errno));
  const int yes = 1;
  ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = htons(static_cast<uint16_t>(port));
  socklen_t length = sizeof address;
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      ::listen(listen_fd_, 4) != 0 ||
      ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    const std::string what = std::strerror(errno);
    CloseFd(listen_fd_);
    throw IoError("ptpip emulator 127.0.0.1:" + std::to_string(port), "cannot listen: " + what);
  }
  port_ = ntohs(address.sin_port);
  thread_ = std::thread([this] { Serve(); });
}

PtpipCameraEmulator::~PtpipCameraEmulator() { Disappear(); }

std::string PtpipCameraEmulator::ptpip_path() const {
  return "ptpip:127.0.0.1:" + std::to_string(port_);
}

void PtpipCameraEmulator::Disappear() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();  // the thread closes every socket as it ends
}

void PtpipCameraEmulator::SetCaptureDelay(double seconds) { capture_delay_s_ = seconds; }
void PtpipCameraEmulator::Stall() { stalled_ = true; }

PtpipCameraEmulator::ShotSettings PtpipCameraEmulator::settings() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {exposure_time_ / 10000.0, f_number_ / 100.0, iso_};
}
int PtpipCameraEmulator::captures() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return captures_;
}
int PtpipCameraEmulator::photos_on_card() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(objects_.size());
}
std::vector<std::string> PtpipCameraEmulator::operations() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return operations_;
}
std::string PtpipCameraEmulator::host_guid() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return host_guid_;
}

void PtpipCameraEmulator::Record(const std::string& text) {
  std::lock_guard<std::mutex> lock(mutex_);
  operations_.push_back(text);
}

void PtpipCameraEmulator::Serve() {
  while (!stop_) {
    if (stalled_) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    Connection conn;
    if (AcceptSession(conn)) ServeSession(conn);
  }
  CloseFd(listen_fd_);
}

// Accepts the command connection and its Init Command Request, then the event connection and
// its Init Event Request; false (connections closed) when the host does not go through with it.
bool PtpipCameraEmulator::AcceptSession(Connection& conn) {
  if (!WaitFor(listen_fd_, POLLIN, 0.05)) return false;
  conn.cmd = ::accept(listen_fd_, nullptr, nullptr);
  if (conn.cmd < 0) return false;
  // A data phase is three packets written one after another: without this, each waits for the
  // host's delayed acknowledgement of the one before (Nagle's algorithm).
  const int yes = 1;
  ::setsockopt(conn.cmd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
  uint32_t type = 0;
  std::string payload;
  if (!ReadPacket(conn.cmd, &type, &payload)) return false;
  if (type == kProbeRequest) {  // a host asking whether the camera is there, nothing more
    WritePacket(conn.cmd, kProbeResponse, "");
    return false;
  }
  if (type != kInitCommandRequest || payload.size() < 16) return false;
  {
    std::string guid;
    for (size_t i = 0; i < 16; ++i) guid += Hex(static_cast<uint8_t>(payload[i]), 2).substr(2);
    std::lock_guard<std::mutex> lock(mutex_);
    host_guid_ = guid;
  }
  Record("InitCommandRequest");
  std::string ack;
  Put32(ack, 1);  // connection number, which the Init Event Request quotes
  for (int i = 0; i < 16; ++i) ack += static_cast<char>(0x4c + i);  // the camera's GUID
  for (char c : std::string("Lumislab PTP/IP Emulator")) Put16(ack, static_cast<uint8_t>(c));
  Put16(ack, 0);
  Put32(ack, 0x00010000);  // protocol version 1.0
  if (!WritePacket(conn.cmd, kInitCommandAck, ack)) return false;

  const Clock::time_point deadline = Clock::now() + std::chrono::seconds(5);
  while (!stop_ && Clock::now() < deadline) {
    if (!WaitFor(listen_fd_, POLLIN, 0.05)) continue;
    conn.evt = ::accept(listen_fd_, nullptr, nullptr);
    if (conn.evt < 0) return false;
    if (!ReadPacket(conn.evt, &type, &payload) || type != kInitEventRequest) return false;
    Record("InitEventRequest");
    return WritePacket(conn.evt, kInitEventAck, "");
  }
  return false;
}

void PtpipCameraEmulator::ServeSession(Connection& conn) {
  while (!stop_) {
    if (stalled_) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    SendPendingEvents(conn);
    pollfd fds[2] = {{conn.cmd, POLLIN, 0}, {conn.evt, POLLIN, 0}};
    // Stall() may have come while polling: what arrived after it stays unanswered.
    if (::poll(fds, 2, 20) <= 0 || stalled_) continue;
    if (fds[1].revents) {  // the host sends nothing on the event connection but its close
      char byte;
      if (::recv(conn.evt, &byte, 1, MSG_DONTWAIT) <= 0) return;
    }
    if (!fds[0].revents) continue;
    uint32_t type = 0;
    std::string payload;
    if (!ReadPacket(conn.cmd, &type, &payload)) return;  // the host closed or broke off
    if (type == kOperationRequest) {
      HandleOperation(conn, payload);
    } else if (type == kProbeRequest) {
      WritePacket(conn.cmd, kProbeResponse, "");
    } else {
      Record("unexpected packet type " + std::to_string(type));
    }
  }
}

void PtpipCameraEmulator::SendPendingEvents(Connection& conn) {
  if (!conn.capture_pending || Clock::now() < conn.capture_due) return;
  conn.capture_pending = false;
  ShotSettings shot = settings();
  Photo photo;
  try {
    photo = maker_(shot);
  } catch (const std::exception& e) {
    Record(std::string("photo maker failed: ") + e.what());
    return;
  }
  uint32_t handle;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    handle = next_handle_++;
    ++captures_;
    std::string name = photo.extension;
    for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    char filename[32];
    std::snprintf(filename, sizeof filename, "IMG_%04d.", captures_ % 10000);
    objects_[handle] = {filename + name, FormatOf(photo.extension), std::move(photo.bytes)};
  }
  for (uint16_t code : {kObjectAdded, kCaptureComplete}) {
    std::string event;
    Put16(event, code);
    Put32(event, conn.capture_transaction);
    if (code == kObjectAdded) Put32(event, handle);
    WritePacket(conn.evt, kEvent, event);
  }
}

void PtpipCameraEmulator::HandleOperation(Connection& conn, const std::string& request) {
  const uint32_t data_phase = Get32(request, 0);  // 2: the host sends data
  const uint16_t code = Get16(request, 4);
  const uint32_t transaction = Get32(request, 6);
  std::vector<uint32_t> params;
  for (size_t at = 10; at + 4 <= request.size(); at += 4) params.push_back(Get32(request, at));
  const uint32_t p1 = params.empty() ? 0 : params[0];

  std::string host_data;
  if (data_phase == 2) {  // Start Data, then Data packets up to End Data
    uint32_t type = 0;
    std::string payload;
    if (!ReadPacket(conn.cmd, &type, &payload) || type != kStartData) return;
    do {
      if (!ReadPacket(conn.cmd, &type, &payload)) return;
      if (payload.size() >= 4) host_data += payload.substr(4);
    } while (type == kData);
  }
  std::string name = OperationName(code);
  if (code == kGetDevicePropDesc || code == kGetDevicePropValue || code == kSetDevicePropValue)
    name += " " + Hex(p1, 4);
  else if (!params.empty() && code != kOpenSession)
    name += " " + Hex(p1, 8);
  Record(name);

  std::string data;  // the camera's data phase, if any
  uint16_t response = kOk;
  static const std::vector<uint32_t> exposure_units = ExposureUnits();
  const auto choices_of = [&](uint32_t prop) -> const std::vector<uint32_t>* {
    return prop == kExposureTime    ? &exposure_units
           : prop == kFNumber       ? &kFNumbers
           : prop == kExposureIndex ? &kIsos
                                    : nullptr;
  };
  const auto current = [&](uint32_t prop) -> uint32_t {
    return prop == kExposureTime ? exposure_time_ : prop == kFNumber ? f_number_ : iso_;
  };
  const auto put_value = [](std::string& out, uint16_t type, uint32_t v) {
    if (type == kUint32)
      Put32(out, v);
    else
      Put16(out, static_cast<uint16_t>(v));
  };

  std::unique_lock<std::mutex> lock(mutex_);
  if (!conn.session_open && code != kGetDeviceInfo && code != kOpenSession) {
    response = kSessionNotOpen;
  } else {
    switch (code) {
      case kGetDeviceInfo:
        Put16(data, 100);  // PTP 1.00
        Put32(data, 0);    // no vendor extension: libgphoto2's generic PTP path
        Put16(data, 0);
        PutPtpString(data, "");
        Put16(data, 0);  // functional mode: standard
        PutArray16(data,
                   {kGetDeviceInfo, kOpenSession, kCloseSession, kGetStorageIds, kGetStorageInfo,
                    kGetObjectHandles, kGetObjectInfo, kGetObject, kDeleteObject, kInitiateCapture,
                    kGetDevicePropDesc, kGetDevicePropValue, kSetDevicePropValue});
        PutArray16(data, {kObjectAdded, kCaptureComplete});
        PutArray16(data, {kExposureTime, kFNumber, kExposureIndex});
        PutArray16(data, {kFormatJpeg});                           // capture formats
        PutArray16(data, {kFormatJpeg, kFormatDng, kFormatTiff});  // image formats
        PutPtpString(data, "Lumislab");
        PutPtpString(data, "PTP/IP Emulator");
        PutPtpString(data, "1.0");
        PutPtpString(data, "0000000001");
        break;
      case kOpenSession:
        if (conn.session_open) response = kSessionAlreadyOpen;
        conn.session_open = true;
        break;
      case kCloseSession:
        conn.session_open = false;
        break;
      case kGetStorageIds:
        Put32(data, 1);
        Put32(data, kStorageId);
        break;
      case kGetStorageInfo:
        if (p1 != kStorageId) {
          response = kInvalidStorageId;
          break;
        }
        Put16(data, 4);  // removable RAM (a memory card)
        Put16(data, 2);  // generic hierarchical file system
        Put16(data, 0);  // read-write
        Put64(data, 32ull << 30);
        Put64(data, 16ull << 30);
        Put32(data, 0xffffffff);
        PutPtpString(data, "SD");
        PutPtpString(data, "LUMISLAB");
        break;
      case kGetObjectHandles: {
        // Parameters: storage (0xffffffff all), format (0 all), parent (0 all, 0xffffffff the
        // root): every photo lies in the root of the one storage.
        const uint32_t parent = params.size() > 2 ? params[2] : 0;
        std::vector<uint32_t> handles;
        if (parent == 0 || parent == 0xffffffff)
          for (const auto& [handle, object] : objects_) handles.push_back(handle);
        Put32(data, static_cast<uint32_t>(handles.size()));
        for (uint32_t h : handles) Put32(data, h);
        break;
      }
      case kGetObjectInfo: {
        const auto it = objects_.find(p1);
        if (it == objects_.end()) {
          response = kInvalidObjectHandle;
          break;
        }
        const Object& object = it->second;
        Put32(data, kStorageId);
        Put16(data, object.format);
        Put16(data, 0);  // no protection
        Put32(data, static_cast<uint32_t>(object.bytes.size()));
        Put16(data, 0);  // thumb format, size, width, height
        Put32(data, 0);
        Put32(data, 0);
        Put32(data, 0);
        Put32(data, 0);  // image width, height, bit depth
        Put32(data, 0);
        Put32(data, 0);
        Put32(data, 0);  // parent: the root
        Put16(data, 0);  // association type, description, sequence number
        Put32(data, 0);
        Put32(data, 0);
        PutPtpString(data, object.filename);
        PutPtpString(data, "20261204T214001");  // capture date
        PutPtpString(data, "20261204T214001");  // modification date
        PutPtpString(data, "");                 // keywords
        break;
      }
      case kGetObject: {
        const auto it = objects_.find(p1);
        if (it == objects_.end())
          response = kInvalidObjectHandle;
        else
          data = it->second.bytes;
        break;
      }
      case kDeleteObject:
        if (objects_.erase(p1) == 0) response = kInvalidObjectHandle;
        break;
      case kInitiateCapture:
        conn.capture_pending = true;
        conn.capture_due =
            Clock::now() + std::chrono::microseconds(std::lround(capture_delay_s_ * 1e6));
        conn.capture_transaction = transaction;
        break;
      case kGetDevicePropDesc:
      case kGetDevicePropValue:
      case kSetDevicePropValue: {
        const std::vector<uint32_t>* choices = choices_of(p1);
        const uint16_t type = p1 == kExposureTime ? kUint32 : kUint16;
        if (!choices) {
          response = kDevicePropNotSupported;
          break;
        }
        if (code == kGetDevicePropValue) {
          put_value(data, type, current(p1));
        } else if (code == kGetDevicePropDesc) {
          Put16(data, static_cast<uint16_t>(p1));
          Put16(data, type);
          data += '\1';                        // settable
          put_value(data, type, current(p1));  // factory default
          put_value(data, type, current(p1));
          data += '\2';  // enumeration
          Put16(data, static_cast<uint16_t>(choices->size()));
          for (uint32_t v : *choices) put_value(data, type, v);
        } else {
          const uint32_t v = type == kUint32 ? Get32(host_data, 0) : Get16(host_data, 0);
          bool offered = false;
          for (uint32_t c : *choices) offered |= c == v;
          if (!offered || host_data.size() < (type == kUint32 ? 4u : 2u)) {
            response = kInvalidDevicePropValue;
          } else if (p1 == kExposureTime) {
            exposure_time_ = v;
          } else if (p1 == kFNumber) {
            f_number_ = static_cast<uint16_t>(v);
          } else {
            iso_ = static_cast<uint16_t>(v);
          }
        }
        break;
      }
      default:
        response = kOperationNotSupported;
    }
  }
  lock.unlock();
  if (!data.empty() || (response == kOk && code == kGetObject)) {
    std::string start;
    Put32(start, transaction);
    Put64(start, data.size());
    if (!WritePacket(conn.cmd, kStartData, start)) return;
    constexpr size_t kChunk = 64 * 1024;
    size_t at = 0;
    do {
      const size_t n = std::min(kChunk, data.size() - at);
      std::string packet;
      Put32(packet, transaction);
      packet.append(data, at, n);
      at += n;
      if (!WritePacket(conn.cmd, at < data.size() ? kData : kEndData, packet)) return;
    } while (at < data.size());
  }
  std::string reply;
  Put16(reply, response);
  Put32(reply, transaction);
  WritePacket(conn.cmd, kOperationResponse, reply);
}

}  // namespace lumislab
