// A camera on the network, for the gphoto2 driver's tests and the virtual lab: a TCP listener on
// 127.0.0.1 that speaks PTP/IP (CIPA DC-005) as a plain PTP camera with no vendor extension, so
// that the real libgphoto2 (camlibs/ptp2, port "ptpip:127.0.0.1:<port>") takes its generic path:
//   connection: Init Command Request/Ack on the first connection, Init Event Request/Ack on the
//     second; Operation Request/Response, Start Data/Data/End Data on the first; Event packets on
//     the second;
//   operations: GetDeviceInfo, OpenSession, CloseSession, GetStorageIDs, GetStorageInfo,
//     GetObjectHandles, GetObjectInfo, GetObject, DeleteObject, InitiateCapture (then the event
//     ObjectAdded, then CaptureComplete), GetDevicePropDesc, GetDevicePropValue,
//     SetDevicePropValue for ExposureTime (0x500D), FNumber (0x5007) and ExposureIndex (0x500F),
//     each an enumeration; anything else is answered OperationNotSupported.
// One host at a time, as a real camera. Every socket wait has a timeout; the thread ends with the
// emulator.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace lumislab {

class PtpipCameraEmulator {
 public:
  // What the camera is set to when the shutter opens.
  struct ShotSettings {
    double exposure_time_s = 0;
    double f_number = 0;
    int iso = 0;
  };
  // One captured file: its extension ("jpg", "dng"; the object's format follows it) and bytes.
  struct Photo {
    std::string extension;
    std::string bytes;
  };
  using PhotoMaker = std::function<Photo(const ShotSettings&)>;

  // A small grey JPEG whose EXIF holds the shot's exposure time, f-number and ISO, and make
  // "Lumislab", model "PTP/IP Emulator" (lib/photo/camera_write.h).
  static Photo DefaultPhoto(const ShotSettings& shot);
  // The exposure times the camera offers (s, ascending): 1/3 stops from 1/4000 to 30 s, as PTP
  // holds them (integer units of 0.1 ms, so 1/4000 is 0.0002).
  static std::vector<double> ExposureTimes();

  // Listens on 127.0.0.1:`port` (0: an ephemeral port, see port()). IoError when it cannot.
  explicit PtpipCameraEmulator(int port = 0, PhotoMaker maker = DefaultPhoto);
  ~PtpipCameraEmulator();
  PtpipCameraEmulator(const PtpipCameraEmulator&) = delete;
  PtpipCameraEmulator& operator=(const PtpipCameraEmulator&) = delete;

  int port() const { return port_; }
  std::string ptpip_path() const;  // "ptpip:127.0.0.1:<port>", libgphoto2's port path

  // Faults. Disappear: the camera is switched off (connections closed, no longer listening).
  // SetCaptureDelay: the time from InitiateCapture to the ObjectAdded event (s). Stall: the
  // camera stops answering but keeps its connections open.
  void Disappear();
  void SetCaptureDelay(double seconds);
  void Stall();

  ShotSettings settings() const;
  int captures() const;        // photos taken so far
  int photos_on_card() const;  // photos taken and not deleted
  // The operations received so far, in order, by PTP name ("OpenSession", "GetDeviceInfo",
  // "SetDevicePropValue 0x500d", ...), and the GUID libgphoto2 sent in its Init Command Request.
  std::vector<std::string> operations() const;
  std::string host_guid() const;

 private:
  struct Object {
    std::string filename;
    uint16_t format = 0;
    std::string bytes;
  };
  struct Connection;

  void Serve();
  bool AcceptSession(Connection& conn);
  void ServeSession(Connection& conn);
  void HandleOperation(Connection& conn, const std::string& payload);
  void SendPendingEvents(Connection& conn);
  void Record(const std::string& text);

  PhotoMaker maker_;
  int listen_fd_ = -1;
  int port_ = 0;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> stalled_{false};
  std::atomic<double> capture_delay_s_{0};

  mutable std::mutex mutex_;    // guards what follows
  uint32_t exposure_time_ = 0;  // PTP units: 0.1 ms
  uint16_t f_number_ = 0;       // PTP units: 1/100
  uint16_t iso_ = 0;
  std::map<uint32_t, Object> objects_;
  uint32_t next_handle_ = 1;
  int captures_ = 0;
  std::vector<std::string> operations_;
  std::string host_guid_;
};

}  // namespace lumislab
