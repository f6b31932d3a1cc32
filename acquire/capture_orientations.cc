#include "acquire/capture_orientations.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/input_file.h"
#include "core/json.h"
#include "core/log.h"
#include "core/stop_signal.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

std::string Field(size_t k, const char* name) {
  return "orientations[" + std::to_string(k) + "]." + name;
}

std::string Vec(const Eigen::Vector3d& v) {
  return "[" + Num(v.x(), 6) + ", " + Num(v.y(), 6) + ", " + Num(v.z(), 6) + "]";
}

int MountOf(const Orientation& o) { return o.mount.value_or(0); }

bool AxisReaches(const Orientation& o, const LabSetup& lab) {
  return lab.rotation_axis && o.axis_deg;
}

// The folder's lock: one run at a time writes a luminaire folder (each dataset has its own too).
class FolderLock {
 public:
  explicit FolderLock(const std::string& path) {
    fd_ = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw IoError(path, std::string("cannot open: ") + std::strerror(errno));
    if (flock(fd_, LOCK_EX | LOCK_NB) != 0)
      throw BadInput(fs::path(path).parent_path().parent_path().string() +
                     ": another lumislab-acquire capture is writing this luminaire folder (" +
                     path + ")");
  }
  ~FolderLock() { close(fd_); }
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace

LuminaireSet LoadOrientationPlan(const std::string& plan_file) {
  const fs::path path(plan_file);
  return LoadLuminaireSetFile(plan_file,
                              path.has_parent_path() ? path.parent_path().string() : ".");
}

void CheckPlanAgainstLab(const LuminaireSet& plan, const std::string& plan_file,
                         const LabSetup& lab, const std::string& setup_file) {
  if (!lab.rotation_axis) return;
  const char axis = lab.rotation_axis->axis;
  const auto travel = std::find_if(lab.travel.begin(), lab.travel.end(),
                                   [&](const LabSetup::Travel& t) { return t.axis == axis; });
  std::map<int, size_t> first_of_mount;  // the mount's first orientation the axis reaches
  for (size_t k = 0; k < plan.orientations.size(); ++k) {
    const Orientation& o = plan.orientations[k];
    if (!o.axis_deg) continue;
    const std::string travel_field = std::string("lab.stage.travel_mm.") + axis;
    if (travel == lab.travel.end())
      throw InputError(
          setup_file, travel_field,
          "the travel of the rotation axis (degrees), which the plan " + plan_file + " turns",
          "none");
    if (*o.axis_deg < travel->min_mm - 1e-9 || *o.axis_deg > travel->max_mm + 1e-9)
      throw InputError(plan_file, Field(k, "axis_deg"),
                       "an angle within the rotation axis' travel [" + Num(travel->min_mm, 6) +
                           ", " + Num(travel->max_mm, 6) + "] deg (" + setup_file + ": " +
                           travel_field + ")",
                       Num(*o.axis_deg, 6) + " deg");
    const auto [it, first] = first_of_mount.emplace(MountOf(o), k);
    if (first) continue;
    // The axis turns the mounted luminaire in the capture frame: R_k = Rot(about, a_k - a_j) R_j.
    const Orientation& ref = plan.orientations[it->second];
    const double turn_deg = *o.axis_deg - *ref.axis_deg;
    const Eigen::Matrix3d expected =
        Eigen::AngleAxisd(turn_deg * kPi / 180, lab.rotation_axis->about).toRotationMatrix() *
        ref.NominalRotation();
    const Eigen::AngleAxisd off(o.NominalRotation() * expected.transpose());
    if (std::abs(off.angle()) * 180 / kPi > kPlanAxisToleranceDeg) {
      const Eigen::AngleAxisd actual(o.NominalRotation() * ref.NominalRotation().transpose());
      throw InputError(plan_file, Field(k, "rotation_deg"),
                       "orientations[" + std::to_string(it->second) +
                           "] turned by axis_deg's difference, " + Num(turn_deg, 6) +
                           " deg, about " + lab.rotation_axis->about_name + " (" + setup_file +
                           ": lab.rotation_axis.about; same mount " + std::to_string(MountOf(o)) +
                           ")",
                       Vec(o.rotation_deg) + ", a turn of " + Num(actual.angle() * 180 / kPi, 4) +
                           " deg about " + Vec(actual.axis()) + " from it");
    }
  }
}

OrientationStep StepTo(const LuminaireSet& plan, size_t k, int placed, const LabSetup& lab) {
  const Orientation& o = plan.orientations[k];
  OrientationStep step;
  const std::string pose =
      "rotation_deg " + Vec(o.rotation_deg) + ", centre_mm " + Vec(o.centre_mm);
  if (AxisReaches(o, lab)) {
    step.axis_deg = o.axis_deg;
    // Before the first orientation the operator mounted the luminaire as the plan begins.
    const int mounted = MountOf(plan.orientations[placed < 0 ? 0 : size_t(placed)]);
    if (placed >= 0 && size_t(placed) == k) return step;
    if (MountOf(o) != mounted) {
      step.ask = true;
      step.action = "mount";
      step.request = "Remount the luminaire: mount " + std::to_string(MountOf(o)) + " (" + o.name +
                     ": " + pose + ", with axis " + std::string(1, lab.rotation_axis->axis) +
                     " at " + Num(*o.axis_deg, 6) + " deg)";
    }
    return step;
  }
  if (placed >= 0 && size_t(placed) == k) return step;
  step.ask = true;
  step.action = "orientation";
  step.request = "Turn the luminaire to orientation " + o.name + " (" + pose +
                 (o.mount ? ", mount " + std::to_string(*o.mount) : "") + ")";
  return step;
}

namespace {

// The run: the plan's orientations in order, the complete ones skipped.
class OrientationsRun {
 public:
  OrientationsRun(const CaptureOptions& o, LuminaireSet plan, LabSetup lab)
      : o_(o), plan_(std::move(plan)), lab_(std::move(lab)), capture_dir_(o.out_dir + "/capture") {}

  CaptureReport Run() {
    MakeDirectories(capture_dir_);
    FolderLock lock(capture_dir_ + "/lock");
    PrepareFolder();
    CaptureReport report;
    report.orientations_resumed = int(done_.orientations.size());
    if (report.orientations_resumed == int(plan_.orientations.size())) {
      LogInfo(LuminaireJsonPath(o_.out_dir),
              " is complete, skipping (use --force to capture "
              "again)");
      report.skipped = true;
      return report;
    }
    if (report.orientations_resumed)
      LogInfo("going on after ", report.orientations_resumed, " complete orientation(s) of ",
              plan_.orientations.size(), " (", LuminaireJsonPath(o_.out_dir), ")");
    devices_ = CaptureDevices::Open(o_);
    devices_.log->Open(capture_dir_ + "/devices.log");
    try {
      for (size_t k = done_.orientations.size(); k < plan_.orientations.size(); ++k) {
        Reach(k);
        const CaptureReport r = CaptureOrientation(k);
        report.shots_done += r.shots_done;
        report.shots_resumed += r.shots_resumed;
        report.photos += r.photos;
        report.reshots += r.reshots;
        ++report.orientations_done;
        done_.orientations.push_back(plan_.orientations[k]);
        WriteLuminaireSet(done_);
        devices_.log->Open(capture_dir_ + "/devices.log");
        LogInfo("orientation ", plan_.orientations[k].name, " complete (", k + 1, "/",
                plan_.orientations.size(), "): ", LuminaireJsonPath(o_.out_dir));
      }
    } catch (const Error& e) {
      devices_.Close();
      throw Error(e.code(), std::string(e.what()) + "; " + LuminaireJsonPath(o_.out_dir) +
                                " lists " + std::to_string(done_.orientations.size()) + " of " +
                                std::to_string(plan_.orientations.size()) +
                                " orientations (the same command goes on from there)");
    } catch (...) {
      devices_.Close();
      throw;
    }
    devices_.Close();
    return report;
  }

 private:
  // The plan kept (a resumed run must give the same one), the orientations complete so far: the
  // leading ones of the plan that luminaire.json lists.
  void PrepareFolder() {
    const std::string plan_text = ReadTextFile(o_.orientations_file);
    const std::string kept = capture_dir_ + "/plan.json";
    std::error_code ec;
    if (o_.force) {
      fs::remove(LuminaireJsonPath(o_.out_dir), ec);
      fs::remove(capture_dir_ + "/placed", ec);
    } else if (fs::exists(kept) && ReadTextFile(kept) != plan_text) {
      throw BadInput(o_.orientations_file + ": differs from the plan the capture in " + o_.out_dir +
                     " was started with (" + kept +
                     "); use that one to go on, or --force to capture again");
    }
    WriteTextAtomically(kept, plan_text);
    done_ = plan_;
    done_.folder = o_.out_dir;
    done_.orientations.clear();
    if (IsLuminaireFolder(o_.out_dir)) {
      const LuminaireSet listed = LoadLuminaireSet(o_.out_dir);
      for (const Orientation& o : listed.orientations) {
        const size_t k = done_.orientations.size();
        if (k >= plan_.orientations.size() || plan_.orientations[k].name != o.name ||
            plan_.orientations[k].dataset != o.dataset)
          throw InputError(LuminaireJsonPath(o_.out_dir), Field(k, "name"),
                           "the plan's orientations in its order (" + o_.orientations_file + ")",
                           "'" + o.name + "' in " + o.dataset);
        done_.orientations.push_back(plan_.orientations[k]);
      }
    }
    placed_ = -1;
    const std::string placed_path = capture_dir_ + "/placed";
    if (fs::exists(placed_path)) {
      std::istringstream in(ReadTextFile(placed_path));
      std::string name;
      in >> name;
      for (size_t k = 0; k < plan_.orientations.size(); ++k)
        if (plan_.orientations[k].name == name) placed_ = int(k);
    }
  }

  void Connect() {
    if (devices_.connected) return;
    devices_.Connect(lab_);
    if (lab_.stage.home && !devices_.homed) {
      LogInfo("homing the stage");
      devices_.stage->Home();
      devices_.homed = true;
    }
  }

  // Brings the luminaire to orientation k: the axis turned, the operator asked when needed.
  void Reach(size_t k) {
    const OrientationStep step = StepTo(plan_, k, placed_, lab_);
    const Orientation& o = plan_.orientations[k];
    if (step.axis_deg) {
      Connect();
      const char axis = lab_.rotation_axis->axis;
      LogInfo("orientation ", o.name, ": turning axis ", axis, " to ", Num(*step.axis_deg, 6),
              " deg");
      devices_.log->Note("capture", "orientation " + o.name + ": axis " + std::string(1, axis) +
                                        " to " + Num(*step.axis_deg, 6) + " deg");
      devices_.stage->MoveTo({{axis, *step.axis_deg}});
    }
    if (step.ask) {
      devices_.log->Note("capture", "orientation " + o.name + ": asking the operator");
      devices_.op->Ask(step.action, step.action == "mount" ? std::to_string(MountOf(o)) : o.name,
                       step.request, "bringing the luminaire to orientation " + o.name);
    }
    placed_ = int(k);
    WriteTextAtomically(capture_dir_ + "/placed", o.name + "\n");
  }

  CaptureReport CaptureOrientation(size_t k) {
    const Orientation& o = plan_.orientations[k];
    CaptureOptions one = o_;
    one.orientations_file.clear();
    one.out_dir = o_.out_dir + "/" + o.dataset;
    // The board photo of the first orientation serves them all: camera and screen stay put.
    for (size_t j = 0; j < k && one.board_photo.empty(); ++j) {
      if (const auto board = CapturedBoard(o_.out_dir + "/" + plan_.orientations[j].dataset)) {
        one.board_photo = board->path;
        one.board_shutter_s = board->shutter_s;
      }
    }
    Dataset setup = Dataset::Parse(JsonDocument::Load(o_.setup_file), one.out_dir, false);
    if (!o_.force && fs::exists(one.out_dir + "/dataset.json") &&
        !Dataset::Load(one.out_dir).Partial()) {
      CaptureReport complete;  // captured, but stopped before luminaire.json listed it
      complete.skipped = true;
      return complete;
    }
    LogInfo("orientation ", o.name, " (", k + 1, "/", plan_.orientations.size(), ") into ",
            one.out_dir);
    return CaptureDataset(one, std::move(setup), lab_, &devices_);
  }

  const CaptureOptions& o_;
  LuminaireSet plan_;
  LabSetup lab_;
  std::string capture_dir_;
  LuminaireSet done_;  // luminaire.json: the complete orientations
  int placed_ = -1;    // capture/placed, as a plan index
  CaptureDevices devices_;
};

}  // namespace

CaptureReport RunOrientationsCapture(const CaptureOptions& o) {
  // Everything that can be checked is checked before a device is opened or a file written.
  const Dataset setup = Dataset::Parse(JsonDocument::Load(o.setup_file), o.out_dir, false);
  const LabSetup lab = LoadLabSetup(o.setup_file);
  lab.CheckTravel(setup.grid, o.setup_file);
  LuminaireSet plan = LoadOrientationPlan(o.orientations_file);
  plan.folder = o.out_dir;
  CheckPlanAgainstLab(plan, o.orientations_file, lab, o.setup_file);
  CaptureDevices::Open(o);  // the URIs, refused before anything is written
  CaptureReport report;
  if (o.dry_run) {
    const CapturePlan one = PlanCapture(setup.grid, lab, o.order, o.lab);
    std::printf("orientations: %zu (%s)\n", plan.orientations.size(), plan.coverage.c_str());
    int placed = -1;
    for (size_t k = 0; k < plan.orientations.size(); ++k) {
      const OrientationStep step = StepTo(plan, k, placed, lab);
      std::string how;
      if (step.axis_deg)
        how = std::string("axis ") + lab.rotation_axis->axis + " to " + Num(*step.axis_deg, 6) +
              " deg";
      if (step.ask)
        how += (how.empty() ? "" : ", then ") + std::string("the operator: ") + step.request;
      std::printf("  %s -> %s/%s: %s\n", plan.orientations[k].name.c_str(), o.out_dir.c_str(),
                  plan.orientations[k].dataset.c_str(), how.c_str());
      placed = int(k);
    }
    std::printf("each orientation:\n%s", DescribePlan(setup.grid, lab, one, o.lab).c_str());
    report.dry_run = true;
    return report;
  }
  StopSignalScope stop_scope;
  OrientationsRun run(o, std::move(plan), lab);
  return run.Run();
}

}  // namespace lumislab
