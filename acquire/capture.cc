#include "acquire/capture.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <tuple>

#include "acquire/capture_list.h"
#include "acquire/capture_orientations.h"
#include "acquire/devices/command_stage.h"
#include "acquire/devices/operator.h"
#include "acquire/devices/uri.h"
#include "acquire/import.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/json.h"
#include "core/log.h"
#include "core/stop_signal.h"
#include "lib/photo/photo_io.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

// A photo with more than this fraction of its pixels clipped has lost the brightest part of the
// light: the shortest bracket is taken again shorter. (Fewer are a few hot or specular pixels.)
constexpr double kClippedFraction = 1e-5;
// The test shot puts the brightest light of the shortest bracket here (x saturation level):
// room for the light to be brighter at another position than at the grid's centre.
constexpr double kTargetPeak = 0.6;
// Test shots before giving up on finding an exposure; re-shots of one clipping photo; the
// shortest exposure time tried (a camera whose times lumislab cannot set has no list to end).
constexpr int kMaxTestShots = 12;
constexpr int kMaxReshoots = 8;
constexpr double kShortestExposureS = 1e-6;

const char* Slide(bool positive) { return positive ? "p" : "n"; }

std::string Duration(double s) {
  const long t = std::lround(std::max(0.0, s));
  char buffer[32];
  if (t >= 3600)
    std::snprintf(buffer, sizeof buffer, "%ld:%02ld:%02ld", t / 3600, t / 60 % 60, t % 60);
  else
    std::snprintf(buffer, sizeof buffer, "%ld:%02ld", t / 60, t % 60);
  return buffer;
}

double Distance(const AxisTargets& a, const AxisTargets& b) {
  double sum = 0;
  for (size_t k = 0; k < a.size() && k < b.size(); ++k)
    sum += (a[k].second - b[k].second) * (a[k].second - b[k].second);
  return std::sqrt(sum);
}

using ShotKey = std::tuple<int, int, bool>;

// capture/shots.csv: what is finished. A shot's photos and its `done` line are appended in one
// write and synced once every photo of the shot is checked, so that after a kill the journal
// holds whole shots only. A write cut short (a crash, a full disk) is cut off again: by Append
// when it sees the short write, by Load when it finds a last line without its newline; photo
// lines without their `done` (an earlier attempt at the shot) are dropped when the shot's
// bracket starts again.
//   photo,<i>,<j>,<p|n>,<bracket>,<exposure time s>,<file>
//   done,<i>,<j>,<p|n>
//   board,<exposure time s>,<file>
class ShotJournal {
 public:
  struct JournalPhoto {
    int bracket = 0;
    double shutter_s = 0;
    std::string file;  // relative to photos/
  };

  explicit ShotJournal(std::string path) : path_(std::move(path)) {}

  void Load() {
    CutToLastLine();
    std::ifstream in(path_);
    if (!in) return;
    std::map<ShotKey, std::vector<JournalPhoto>> pending;
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      std::vector<std::string> f;
      std::stringstream ss(line);
      std::string field;
      while (std::getline(ss, field, ',')) f.push_back(field);
      const auto bad = [&] {
        return BadInput(path_ + ": line " + std::to_string(number) +
                        ": not a journal line (photo, done or board); remove the capture folder "
                        "or use --force");
      };
      try {
        if (f.size() == 7 && f[0] == "photo" && (f[3] == "p" || f[3] == "n")) {
          const ShotKey key{std::stoi(f[1]), std::stoi(f[2]), f[3] == "p"};
          const int bracket = std::stoi(f[4]);
          if (bracket == 0) pending[key].clear();
          pending[key].push_back({bracket, std::stod(f[5]), f[6]});
        } else if (f.size() == 4 && f[0] == "done" && (f[3] == "p" || f[3] == "n")) {
          const ShotKey key{std::stoi(f[1]), std::stoi(f[2]), f[3] == "p"};
          done_[key] = pending[key];
          pending.erase(key);
        } else if (f.size() == 3 && f[0] == "board") {
          board_ = JournalPhoto{0, std::stod(f[1]), f[2]};
        } else {
          throw bad();
        }
      } catch (const std::logic_error&) {
        throw bad();
      }
    }
  }

  const std::map<ShotKey, std::vector<JournalPhoto>>& done() const { return done_; }
  const std::optional<JournalPhoto>& board() const { return board_; }

  void FinishShot(const CaptureShot& s, const std::vector<JournalPhoto>& photos) {
    std::string text;
    for (const JournalPhoto& p : photos)
      text += "photo," + std::to_string(s.i) + "," + std::to_string(s.j) + "," + Slide(s.positive) +
              "," + std::to_string(p.bracket) + "," + Num(p.shutter_s, 6) + "," + p.file + "\n";
    text +=
        "done," + std::to_string(s.i) + "," + std::to_string(s.j) + "," + Slide(s.positive) + "\n";
    Append(text);
    done_[{s.i, s.j, s.positive}] = photos;
  }
  void FinishBoard(const JournalPhoto& photo) {
    Append("board," + Num(photo.shutter_s, 6) + "," + photo.file + "\n");
    board_ = photo;
  }

 private:
  void Append(const std::string& text) {
    const int fd = open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd < 0) throw IoError(path_, "cannot open the capture journal");
    const off_t before = lseek(fd, 0, SEEK_END);
    const ssize_t n = write(fd, text.data(), text.size());
    const bool synced = fsync(fd) == 0;
    if (n != ssize_t(text.size()) || !synced) {
      const int error = n < 0 ? errno : ENOSPC;
      if (before >= 0 && ftruncate(fd, before) == 0) fsync(fd);
      close(fd);
      throw IoError(path_,
                    std::string("cannot write the capture journal: ") + std::strerror(error));
    }
    close(fd);
  }
  // Cuts a last line without its newline (a write a crash cut short) off the file.
  void CutToLastLine() {
    std::error_code ec;
    if (!fs::exists(path_, ec)) return;
    const std::string text = ReadTextFile(path_);
    const size_t keep = text.rfind('\n') == std::string::npos ? 0 : text.rfind('\n') + 1;
    if (keep == text.size()) return;
    fs::resize_file(path_, keep, ec);
    if (ec) throw IoError(path_, "cannot cut off the journal's unfinished line: " + ec.message());
  }

  std::string path_;
  std::map<ShotKey, std::vector<JournalPhoto>> done_;
  std::optional<JournalPhoto> board_;
};

// The nearest of `speeds` (ascending) to `t`, at or below it when `at_most`.
double SnapSpeed(const std::vector<double>& speeds, double t, bool at_most) {
  if (speeds.empty()) return t;
  double best = speeds.front();
  for (double s : speeds) {
    if (at_most) {
      if (s <= t * 1.01) best = s;
    } else if (std::abs(std::log(s / t)) < std::abs(std::log(best / t))) {
      best = s;
    }
  }
  return best;
}

// The next of `speeds` at least `factor` times shorter than `t`; `t` itself when none is.
double ShorterSpeed(const std::vector<double>& speeds, double t, double factor) {
  if (speeds.empty()) return t / factor;
  double best = t;
  for (double s : speeds)
    if (s <= t / factor * 1.01) best = s;
  if (best == t)
    for (double s : speeds)
      if (s < t * 0.99) best = s;  // the shortest there is, when less than `factor` shorter
  return best;
}

// The whole capture in one object: the devices, the journal, the photo list and dataset.json.
class Capture {
 public:
  Capture(const CaptureOptions& o, Dataset setup, LabSetup lab, CapturePlan plan)
      : o_(o),
        setup_(std::move(setup)),
        lab_(std::move(lab)),
        plan_(std::move(plan)),
        photos_dir_(o.out_dir + "/photos"),
        capture_dir_(o.out_dir + "/capture"),
        journal_(capture_dir_ + "/shots.csv") {
    import_.photos_dir = photos_dir_;
    import_.setup_file = o.setup_file;
    import_.out_dir = o.out_dir;
  }
  ~Capture() {
    if (lock_fd_ >= 0) close(lock_fd_);
  }
  Capture(const Capture&) = delete;
  Capture& operator=(const Capture&) = delete;

  CaptureReport Run(CaptureDevices* devices) {
    devices_ = devices;
    stage_ = devices->stage.get();
    camera_ = devices->camera.get();
    log_ = devices->log.get();  // kept in memory until the folder exists
    operator_ = devices->op.get();
    log_->Note("capture", "started: " + o_.out_dir + ", stage " + stage_->uri() + ", camera " +
                              camera_->uri());
    // The devices first: one that cannot be used is refused before the folder is made.
    try {
      Connect();
      PrepareFolder();
      log_->Open(capture_dir_ + "/devices.log");
    } catch (...) {
      Close();
      throw;
    }
    CaptureReport report;
    report.shots_resumed = int(journal_.done().size());
    if (report.shots_resumed)
      LogInfo("going on after ", report.shots_resumed, " finished shots of ", plan_.shots.size(),
              " (", capture_dir_, "/shots.csv)");
    try {
      if (lab_.stage.home && !devices_->homed) {
        LogInfo("homing the stage");
        stage_->Home();
        devices_->homed = true;
      }
      ShootBoard();
      ChooseExposure();
      WriteDataset();
      const auto start = std::chrono::steady_clock::now();
      int shot_number = 0;
      for (const CaptureShot& shot : plan_.shots) {
        ++shot_number;
        if (journal_.done().count({shot.i, shot.j, shot.positive})) continue;
        Shoot(shot, &report);
        ++report.shots_done;
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const int left = int(plan_.shots.size()) - shot_number;
        LogInfo("shot ", shot_number, "/", plan_.shots.size(), ": position (", shot.i, ", ", shot.j,
                ") slide ", Slide(shot.positive), ", ", lab_.brackets, " photo(s); elapsed ",
                Duration(elapsed), ", ETA ", Duration(elapsed / report.shots_done * left), "; ",
                setup_.grid.count() - int(ds_.missing_positions.size()), "/", setup_.grid.count(),
                " positions complete");
      }
    } catch (const Error& e) {
      Close();
      log_->Note("capture", std::string("ended: ") + e.what());
      const std::string held =
          list_ ? o_.out_dir + "/dataset.json holds " +
                      std::to_string(setup_.grid.count() - int(ds_.missing_positions.size())) +
                      " complete positions"
                : "no position is complete yet";
      throw Error(e.code(),
                  std::string(e.what()) + " (" + held + "; " +
                      (o_.force ? "the same command without --force" : "the same command") +
                      " goes on from there)");
    } catch (...) {
      Close();
      throw;
    }
    log_->Note("capture", "complete: " + o_.out_dir);
    report.photos = int(ds_.photos.size());
    return report;
  }

 private:
  // Makes the folders, checks that a capture already there was started with this setup, reads
  // its journal and removes what an unfinished shot left behind.
  void PrepareFolder() {
    MakeDirectories(photos_dir_);
    MakeDirectories(capture_dir_ + "/test");
    // One capture at a time into a folder: a second one would take the first one's photos for
    // an unfinished shot's and remove them. The lock goes with the process, however it ends.
    const std::string lock = capture_dir_ + "/lock";
    lock_fd_ = open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (lock_fd_ < 0) throw IoError(lock, std::string("cannot open: ") + std::strerror(errno));
    if (flock(lock_fd_, LOCK_EX | LOCK_NB) != 0)
      throw BadInput(o_.out_dir + ": another lumislab-acquire capture is writing this folder (" +
                     lock + ")");
    const std::string setup_text = ReadTextFile(o_.setup_file);
    const std::string kept = capture_dir_ + "/setup.json";
    if (o_.force) {
      // dataset.json first: it must never name photos that are gone.
      std::error_code ec;
      fs::remove(o_.out_dir + "/dataset.json", ec);
      fs::remove(capture_dir_ + "/shots.csv", ec);
      fs::remove(capture_dir_ + "/exposure.json", ec);
    } else if (fs::exists(kept) && ReadTextFile(kept) != setup_text) {
      throw BadInput(o_.setup_file + ": differs from the setup the capture in " + o_.out_dir +
                     " was started with (" + kept +
                     "); use that one to go on, or --force to capture again");
    }
    WriteTextAtomically(kept, setup_text);
    journal_.Load();
    std::set<std::string> keep;
    for (const auto& [key, photos] : journal_.done())
      for (const auto& p : photos) keep.insert(p.file);
    if (journal_.board()) keep.insert(journal_.board()->file);
    RemoveOrphanedTemporaries(photos_dir_);
    int removed = 0;
    for (const std::string& name : FolderFiles(photos_dir_)) {
      if (keep.count(name)) continue;
      if (name.rfind("pos_", 0) != 0 && name.rfind("board.", 0) != 0) continue;
      std::error_code ec;
      if (fs::remove(photos_dir_ + "/" + name, ec)) ++removed;
    }
    if (removed) LogInfo("removed ", removed, " photo(s) of an unfinished shot; taken again");
  }

  void Connect() {
    if (!devices_->connected) devices_->Connect(lab_);
    // The exposure settings, refused before anything moves: times the setup gives must be the
    // camera's; a camera whose times lumislab cannot set needs them given; a bracket must fit
    // the camera's range even from its shortest time.
    const std::vector<double> speeds = camera_->ShutterSpeeds();
    std::vector<std::pair<std::string, double>> given;
    for (size_t k = 0; k < lab_.shutter_s.size(); ++k)
      given.emplace_back("lab.camera.shutter_s[" + std::to_string(k) + "]", lab_.shutter_s[k]);
    if (lab_.board_shutter_s > 0)
      given.emplace_back("lab.camera.board_shutter_s", lab_.board_shutter_s);
    for (const auto& [field, t] : given) {
      const double s = SnapSpeed(speeds, t, false);
      if (std::abs(s / t - 1) > 0.01)
        throw InputError(
            o_.setup_file, field,
            "an exposure time " + camera_->uri() + " offers (nearest " + Num(s, 6) + " s)",
            Num(t, 6) + " s");
    }
    if (speeds.empty() && (lab_.shutter_s.empty() || lab_.board_shutter_s <= 0))
      throw InputError(
          o_.setup_file,
          lab_.shutter_s.empty() ? "lab.camera.shutter_s" : "lab.camera.board_shutter_s",
          "the exposure times: " + camera_->uri() +
              " cannot be set by lumislab, so no test shot can choose them",
          "none");
    if (!speeds.empty() && lab_.shutter_s.empty() &&
        speeds.front() * std::pow(2.0, lab_.bracket_stops * (lab_.brackets - 1)) >
            speeds.back() * 1.01)
      throw InputError(o_.setup_file, "lab.camera.brackets",
                       "a bracket that fits " + camera_->uri() + "'s exposure times (" +
                           Num(speeds.front(), 6) + " to " + Num(speeds.back(), 6) + " s)",
                       std::to_string(lab_.brackets) + " exposures " + Num(lab_.bracket_stops, 6) +
                           " stops apart");
  }

  void Close() { devices_->Close(); }

  void MoveTo(int i, int j) {
    if (at_ && at_->first == i && at_->second == j) return;
    const AxisTargets targets = lab_.PositionTargets(setup_.grid, i, j);
    stage_->MoveTo(targets);
    at_ = std::make_pair(i, j);
    if (lab_.stage.settle_s > 0 && !PauseUnlessStopped(lab_.stage.settle_s))
      throw DeviceStopped(stage_->uri(), "settling");
  }

  void PutSlide(bool positive) {
    if (slide_ && *slide_ == positive) return;
    if (lab_.slide_axis) {
      stage_->MoveTo(lab_.SlideTargets(positive));
    } else {
      operator_->Ask("slide", Slide(positive),
                     std::string("Put slide T") + (positive ? "+" : "-") + " (" + Slide(positive) +
                         ") in the holder",
                     std::string("changing to slide ") + Slide(positive));
    }
    slide_ = positive;
  }

  // Takes one photo at `shutter_s` into photos/<stem>.<ext>; returns its name in photos/.
  std::string TakePhoto(const std::string& stem, double shutter_s) {
    camera_->SetShutterSpeed(shutter_s);
    const std::string path = camera_->Capture(photos_dir_ + "/" + stem);
    return fs::path(path).filename().string();
  }

  // The board photo, first: the screen calibration can run while the slides are photographed.
  void ShootBoard() {
    if (journal_.board()) return;
    if (!o_.board_photo.empty()) {
      // The camera and the screen stay where they were for an earlier orientation's board.
      const std::string file = "board" + fs::path(o_.board_photo).extension().string();
      WriteTextAtomically(photos_dir_ + "/" + file, ReadTextFile(o_.board_photo));
      CheckPhoto(file);
      log_->Note("capture", "board photo taken over from " + o_.board_photo);
      journal_.FinishBoard({0, o_.board_shutter_s, file});
      return;
    }
    operator_->Ask("board", "on",
                   "Put the calibration board on the screen (" +
                       std::to_string(setup_.calibration.squares_x) + " x " +
                       std::to_string(setup_.calibration.squares_y) + " squares of " +
                       Num(setup_.calibration.square_mm, 6) + " mm)",
                   "placing the board");
    double t = lab_.board_shutter_s;
    if (t <= 0) t = TestExposure("board", /*slide_photo=*/false);
    LogInfo("board photo at ", Num(t, 6), " s");
    const std::string file = TakePhoto("board", t);
    CheckPhoto(file);
    // Journaled once the board is off the screen: a capture stopped before that asks again
    // for the whole board step, not for slide photos with the board in them.
    operator_->Ask("board", "off", "Take the calibration board off the screen",
                   "removing the board");
    journal_.FinishBoard({0, t, file});
  }

  // Test shots until the brightest light sits near kTargetPeak: returns the exposure time.
  double TestExposure(const std::string& what, bool slide_photo) {
    const std::vector<double> speeds = camera_->ShutterSpeeds();
    if (speeds.empty())
      throw InputError(o_.setup_file,
                       slide_photo ? "lab.camera.shutter_s" : "lab.camera.board_shutter_s",
                       "the exposure time(s): " + camera_->uri() +
                           " cannot be set by lumislab, so no test shot can choose them",
                       "none");
    double t = speeds[speeds.size() / 2];
    const double sat = setup_.saturation_level;
    for (int shot = 0; shot < kMaxTestShots; ++shot) {
      camera_->SetShutterSpeed(t);
      const std::string path =
          camera_->Capture(capture_dir_ + "/test/" + what + "_" + std::to_string(shot));
      const PhotoLevels levels = MeasurePhotoLevels(setup_, path);
      log_->Note("capture", "test shot " + path + " at " + Num(t, 6) + " s: peak " +
                                Num(levels.peak, 6) + ", clipped " + Num(levels.clipped, 6));
      if (levels.clipped > kClippedFraction) {
        const double shorter = ShorterSpeed(speeds, t, 8);
        if (shorter == t)
          throw DeviceError(camera_->uri(), "choosing the exposure of the " + what,
                            "the photo clips even at the shortest exposure time " + Num(t, 6) +
                                " s: close the aperture or lower the ISO (lab.camera)");
        t = shorter;
        continue;
      }
      if (levels.peak <= 0) {
        if (t == speeds.back())
          throw DeviceError(camera_->uri(), "choosing the exposure of the " + what,
                            "no light in the photo even at the longest exposure time");
        t = SnapSpeed(speeds, t * 64, true);
        continue;
      }
      const double wanted = t * kTargetPeak * sat / levels.peak;
      const double chosen = SnapSpeed(speeds, wanted, true);
      if (chosen < speeds.back() * 0.99 || wanted <= speeds.back() * 1.01) return chosen;
      return speeds.back();
    }
    throw DeviceError(camera_->uri(), "choosing the exposure of the " + what,
                      "no exposure found in " + std::to_string(kMaxTestShots) + " test shots");
  }

  // The bracket: kept from an earlier run, given by the setup, or from a test shot at the
  // grid's centre through the first slide.
  void ChooseExposure() {
    const std::string path = capture_dir_ + "/exposure.json";
    if (fs::exists(path)) {
      const JsonDocument doc = JsonDocument::Load(path);
      brackets_ = doc.root()["shutter_s"].Numbers();
      exposure_from_exif_ = doc.root()["exposure_source"].OneOf({"exif", "shutter"}) == "exif";
      if (int(brackets_.size()) != lab_.brackets)
        throw BadInput(path + ": shutter_s: " + std::to_string(brackets_.size()) +
                       " exposure times, the setup's lab.camera.brackets is " +
                       std::to_string(lab_.brackets) + "; use --force to capture again");
      return;
    }
    const std::vector<double> speeds = camera_->ShutterSpeeds();
    if (!lab_.shutter_s.empty()) {
      brackets_ = lab_.shutter_s;  // checked against the camera's at Connect
    } else {
      const CaptureShot& first = plan_.shots.front();
      MoveTo((setup_.grid.nu - 1) / 2, (setup_.grid.nv - 1) / 2);
      PutSlide(first.positive);
      const double shortest = TestExposure("slides", true);
      double t = shortest;
      brackets_ = {shortest};
      for (int k = 1; k < lab_.brackets; ++k) {
        const double next = SnapSpeed(speeds, t * std::pow(2.0, lab_.bracket_stops), false);
        if (next <= t * 1.01)
          throw DeviceError(camera_->uri(), "choosing the bracket (lab.camera.brackets)",
                            std::to_string(lab_.brackets) + " exposures " +
                                Num(lab_.bracket_stops, 6) + " stops apart from " +
                                Num(shortest, 6) + " s go beyond the longest exposure time, " +
                                Num(speeds.back(), 6) + " s: fewer brackets or fewer stops");
        brackets_.push_back(next);
        t = next;
      }
    }
    // The exposure of each photo: from its EXIF when the camera writes it (the time actually
    // used), else the exposure time set (aperture and ISO then must stay as they are).
    exposure_from_exif_ = false;
    nlohmann::json json;
    json["schema_version"] = 1;
    json["shutter_s"] = brackets_;
    json["exposure_source"] = "shutter";
    if (journal_.board()) {
      const PhotoExif exif = ReadPhotoExif(photos_dir_ + "/" + journal_.board()->file);
      exposure_from_exif_ = exif.RelativeExposure().has_value();
      json["exposure_source"] = exposure_from_exif_ ? "exif" : "shutter";
    }
    WriteJsonAtomically(path, json);
    std::string list;
    for (double b : brackets_) list += (list.empty() ? "" : ", ") + Num(b, 6) + " s";
    LogInfo("bracket: ", list, " (each photo's exposure from ",
            exposure_from_exif_ ? "its EXIF" : "the time set", ")");
  }

  void Shoot(const CaptureShot& shot, CaptureReport* report) {
    MoveTo(shot.i, shot.j);
    PutSlide(shot.positive);
    std::vector<ShotJournal::JournalPhoto> photos;
    const std::vector<double> speeds = camera_->ShutterSpeeds();
    for (int k = 0; k < int(brackets_.size()); ++k) {
      char stem[64];
      std::snprintf(stem, sizeof stem, "pos_%d_%d_%s_%d", shot.i, shot.j, Slide(shot.positive), k);
      double t = brackets_[k];
      std::string file = TakePhoto(stem, t);
      Photo photo = CheckPhoto(file);
      // The shortest photo must hold the brightest light: taken again shorter while it clips.
      for (int again = 0; k == 0; ++again) {
        const std::string path = photos_dir_ + "/" + file;
        const PhotoLevels levels = MeasurePhotoLevels(photo);
        if (levels.clipped <= kClippedFraction) break;
        const double shorter = ShorterSpeed(speeds, t, std::pow(2.0, lab_.bracket_stops));
        if (shorter >= t * 0.99 || shorter < kShortestExposureS || again == kMaxReshoots) {
          LogWarning(path, ": ", Num(levels.clipped * 100, 6), " % of the pixels clip at ",
                     Num(t, 6),
                     " s, and no shorter time is left to try; the brightest light of this "
                     "position is lost");
          break;
        }
        LogWarning(path, ": ", Num(levels.clipped * 100, 6), " % of the pixels clip at ", Num(t, 6),
                   " s; taking it again at ", Num(shorter, 6), " s");
        t = shorter;
        ++report->reshots;
        fs::remove(path);
        file = TakePhoto(stem, t);
        photo = CheckPhoto(file);
      }
      photos.push_back({k, t, file});
    }
    // Into the photo list before the journal: a photo the list refuses (another camera, no
    // exposure, a slide's exposure twice) is taken again by the next run, not kept for ever.
    try {
      for (const auto& p : photos) AddToList(shot, p);
    } catch (const Error& e) {
      for (const auto& p : photos) fs::remove(photos_dir_ + "/" + p.file);
      throw DeviceError(camera_->uri(),
                        "checking the photos of (" + std::to_string(shot.i) + ", " +
                            std::to_string(shot.j) + ") slide " + Slide(shot.positive),
                        e.what());
    }
    journal_.FinishShot(shot, photos);
    if (list_->Complete(shot.i, shot.j, int(brackets_.size()))) WriteDataset();
  }

  // A photo just downloaded decodes whole and has the capture's image size (the board photo's:
  // the same camera); a DeviceError naming it otherwise (the camera sent a broken file). Returns
  // it decoded as MeasurePhotoLevels reads it, so that the clipping check decodes nothing again.
  Photo CheckPhoto(const std::string& file) {
    const std::string path = photos_dir_ + "/" + file;
    try {
      Photo photo = DecodeForLevels(setup_, path);
      if (!size_ && journal_.board() && journal_.board()->file != file) {
        const Photo board = DecodePhoto(photos_dir_ + "/" + journal_.board()->file);
        size_ = std::make_pair(board.pixels.cols, board.pixels.rows);
      }
      if (!size_) size_ = std::make_pair(photo.pixels.cols, photo.pixels.rows);
      if (size_->first != photo.pixels.cols || size_->second != photo.pixels.rows)
        throw Failure("a photo of " + std::to_string(photo.pixels.cols) + " x " +
                      std::to_string(photo.pixels.rows) + " px where the capture's are " +
                      std::to_string(size_->first) + " x " + std::to_string(size_->second) +
                      " (the camera's image size changed)");
      return photo;
    } catch (const Error& e) {
      throw DeviceError(camera_->uri(), "checking " + path, e.what());
    }
  }

  void AddToList(const CaptureShot& shot, const ShotJournal::JournalPhoto& p) {
    NamedPhoto n;
    n.i = shot.i;
    n.j = shot.j;
    n.positive = shot.positive;
    n.file = p.file;
    if (!exposure_from_exif_) n.exposure = p.shutter_s;
    n.where = photos_dir_ + "/" + p.file;
    list_->Add(n);
  }

  // dataset.json from the finished shots: the positions with both slides, the rest missing.
  void WriteDataset() {
    if (!list_) {
      ds_ = ImportSkeleton(import_);
      ds_.calibration.photo = journal_.board()->file;
      list_ = std::make_unique<CaptureList>(import_, ds_.grid, "acquire capture");
      for (const auto& [key, photos] : journal_.done())
        for (const auto& p : photos)
          AddToList({std::get<0>(key), std::get<1>(key), std::get<2>(key)}, p);
    }
    ds_.photos = list_->Entries(int(brackets_.size()), &ds_.missing_positions);
    WriteImportedDataset(ds_, o_.out_dir);
  }

  const CaptureOptions& o_;
  Dataset setup_;
  LabSetup lab_;
  CapturePlan plan_;
  std::string photos_dir_, capture_dir_;
  ShotJournal journal_;
  ImportOptions import_;
  CaptureDevices* devices_ = nullptr;
  Stage* stage_ = nullptr;
  Camera* camera_ = nullptr;
  DeviceLog* log_ = nullptr;
  Operator* operator_ = nullptr;
  std::optional<std::pair<int, int>> at_;
  std::optional<bool> slide_;
  std::vector<double> brackets_;
  bool exposure_from_exif_ = false;
  std::optional<std::pair<int, int>> size_;  // the capture's image size (px)
  int lock_fd_ = -1;                         // capture/lock, held while the capture runs
  Dataset ds_;
  std::unique_ptr<CaptureList> list_;
};

}  // namespace

void CaptureOptions::Check() const {
  if (order != "auto" && order != "slide-pass" && order != "position")
    throw InputError("--order", "", "auto, slide-pass or position", order);
  if (!operator_program.empty() && !ProgramFound(operator_program))
    throw InputError("--operator", "", "an executable program (a path or a name in PATH)",
                     operator_program);
}

CapturePlan PlanCapture(const SamplingGrid& grid, const LabSetup& lab, const std::string& order,
                        const LabModel& model) {
  CapturePlan plan;
  plan.order = order == "auto" ? (lab.slide_axis ? "position" : "slide-pass") : order;
  // Serpentine rows: j is the row, i runs forwards on even rows and backwards on odd ones.
  std::vector<std::pair<int, int>> path;
  for (int j = 0; j < grid.nv; ++j)
    for (int k = 0; k < grid.nu; ++k) path.emplace_back(j % 2 == 0 ? k : grid.nu - 1 - k, j);
  if (plan.order == "slide-pass") {
    for (const auto& [i, j] : path) plan.shots.push_back({i, j, true});
    for (auto it = path.rbegin(); it != path.rend(); ++it)
      plan.shots.push_back({it->first, it->second, false});
  } else {
    bool positive_first = true;
    for (const auto& [i, j] : path) {
      plan.shots.push_back({i, j, positive_first});
      plan.shots.push_back({i, j, !positive_first});
      positive_first = !positive_first;  // the slide in place stays for the next position
    }
  }
  std::optional<std::pair<int, int>> at;
  std::optional<bool> slide;
  for (const CaptureShot& s : plan.shots) {
    if (!at || *at != std::make_pair(s.i, s.j)) {
      if (at)
        plan.travel_mm += Distance(lab.PositionTargets(grid, at->first, at->second),
                                   lab.PositionTargets(grid, s.i, s.j));
      ++plan.moves;
      at = std::make_pair(s.i, s.j);
    }
    if (!slide || *slide != s.positive) {
      if (slide && lab.slide_axis)
        plan.travel_mm += std::abs(lab.slide_axis->p_mm - lab.slide_axis->n_mm);
      ++plan.slide_swaps;
      slide = s.positive;
    }
  }
  plan.photos = int(plan.shots.size()) * lab.brackets;
  plan.lab_s = plan.moves * model.move_s + plan.photos * model.exposure_s;
  return plan;
}

std::string DescribePlan(const SamplingGrid& grid, const LabSetup& lab, const CapturePlan& plan,
                         const LabModel& model) {
  std::ostringstream os;
  os << "order: " << plan.order << " ("
     << (plan.order == "slide-pass" ? "every position through T+, then through T-"
                                    : "both slides at each position")
     << "), serpentine rows\n";
  os << "grid: " << grid.nu << " x " << grid.nv << " positions, h = " << grid.spacing_mm
     << " mm; stage axes " << lab.axis_u << " " << lab.axis_v << ", centre at ("
     << lab.origin_mm.x() << ", " << lab.origin_mm.y() << ") mm\n";
  os << "shots: " << plan.shots.size() << " (position x slide), photos: " << plan.photos << " ("
     << lab.brackets << " per shot) + 1 board photo + test shots\n";
  os << "stage moves: " << plan.moves << ", travel " << Num(plan.travel_mm, 6) << " mm\n";
  os << "slide changes: " << plan.slide_swaps
     << (lab.slide_axis ? std::string(" (slide axis ") + lab.slide_axis->axis + ")"
                        : std::string(" (by the operator)"))
     << "\n";
  os << "predicted lab time: " << Duration(plan.lab_s) << " (" << plan.moves << " moves x "
     << Num(model.move_s, 6) << " s + " << plan.photos << " photos x " << Num(model.exposure_s, 6)
     << " s: lumislab-plan's lab model, --move-s and --exposure-s)\n";
  return os.str();
}

Photo DecodeForLevels(const Dataset& setup, const std::string& path) {
  PhotoEntry entry;
  entry.exposure = 1;
  return DecodePhoto(path, PhotoSpecOf(setup, entry));
}

PhotoLevels MeasurePhotoLevels(const Dataset& setup, const std::string& path) {
  return MeasurePhotoLevels(DecodeForLevels(setup, path));
}

PhotoLevels MeasurePhotoLevels(const Photo& photo) {
  const LinearReader reader(photo);
  const int w = photo.pixels.cols, h = photo.pixels.rows;
  // About a million samples: the levels of a 24-megapixel photo without reading all of it.
  const int stride = std::max(1, int(std::sqrt(double(w) * h / 1e6)));
  std::vector<float> values;
  values.reserve(size_t(w / stride + 1) * size_t(h / stride + 1));
  size_t clipped = 0;
  for (int y = 0; y < h; y += stride)
    for (int x = 0; x < w; x += stride) {
      float rgb[3];
      bool clip[3];
      reader.Read(y, x, rgb, clip);
      if (clip[0] || clip[1] || clip[2]) ++clipped;
      values.push_back(std::max({rgb[0], rgb[1], rgb[2]}));
    }
  PhotoLevels levels;
  if (values.empty()) return levels;
  levels.clipped = double(clipped) / double(values.size());
  const size_t k = std::min(values.size() - 1, size_t(double(values.size()) * 0.9999));
  std::nth_element(values.begin(), values.begin() + long(k), values.end());
  levels.peak = values[k];
  return levels;
}

CaptureReport RunCapture(const CaptureOptions& o) {
  o.Check();
  if (!o.orientations_file.empty()) return RunOrientationsCapture(o);
  // Everything that can be checked is checked before a device is opened or a file written.
  Dataset setup = Dataset::Parse(JsonDocument::Load(o.setup_file), o.out_dir, false);
  LabSetup lab = LoadLabSetup(o.setup_file);
  lab.CheckTravel(setup.grid, o.setup_file);
  CaptureDevices devices = CaptureDevices::Open(o);
  CaptureReport report;
  if (o.dry_run) {
    const CapturePlan plan = PlanCapture(setup.grid, lab, o.order, o.lab);
    std::fputs(DescribePlan(setup.grid, lab, plan, o.lab).c_str(), stdout);
    report.dry_run = true;
    return report;
  }
  const std::string out_json = o.out_dir + "/dataset.json";
  if (!o.force && fs::exists(out_json) && !Dataset::Load(o.out_dir).Partial()) {
    LogInfo(out_json, " is complete, skipping (use --force to capture again)");
    report.skipped = true;
    return report;
  }
  StopSignalScope stop_scope;
  report = CaptureDataset(o, std::move(setup), std::move(lab), &devices);
  devices.Close();
  return report;
}

CaptureReport CaptureDataset(const CaptureOptions& o, Dataset setup, LabSetup lab,
                             CaptureDevices* devices) {
  CapturePlan plan = PlanCapture(setup.grid, lab, o.order, o.lab);
  Capture capture(o, std::move(setup), std::move(lab), std::move(plan));
  return capture.Run(devices);
}

CaptureDevices CaptureDevices::Open(const CaptureOptions& o) {
  CaptureDevices devices;
  devices.stage = MakeStage(o.stage_uri);
  devices.camera = MakeCamera(o.camera_uri);
  devices.log = std::make_unique<DeviceLog>();
  devices.op = std::make_unique<Operator>(devices.log.get(), o.operator_program);
  return devices;
}

void CaptureDevices::Connect(const LabSetup& lab) {
  LogInfo("connecting to the camera ", camera->uri());
  camera->Connect(lab.camera, log.get());
  LogInfo("connecting to the stage ", stage->uri());
  stage->Connect(lab.stage, log.get());
  connected = true;
}

void CaptureDevices::Close() noexcept {
  if (stage) stage->Close();
  if (camera) camera->Close();
  connected = false;
  homed = false;
}

std::optional<JournalBoard> CapturedBoard(const std::string& dataset_dir) {
  ShotJournal journal(dataset_dir + "/capture/shots.csv");
  journal.Load();
  if (!journal.board()) return std::nullopt;
  return JournalBoard{dataset_dir + "/photos/" + journal.board()->file, journal.board()->shutter_s};
}

}  // namespace lumislab
