#include "core/checks.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <ctime>
#include <filesystem>
#include <map>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json.h"
#include "core/log.h"

namespace lumislab {

namespace {

constexpr int kChecksVersion = 1;
const char kChecksFile[] = "checks.json";

// An advisory lock on the dataset folder for one read-modify-write of checks.json.
class FolderLock {
 public:
  explicit FolderLock(const std::string& dir) : fd_(open(dir.c_str(), O_RDONLY | O_DIRECTORY)) {
    if (fd_ >= 0) flock(fd_, LOCK_EX);
  }
  ~FolderLock() {
    if (fd_ >= 0) close(fd_);  // closing releases the lock
  }
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_;
};

// The stages of an existing checks.json, or none when it is missing or not one of ours.
nlohmann::json ReadStages(const std::string& path, bool warn) {
  if (!std::filesystem::exists(path)) return nlohmann::json::object();
  try {
    const JsonDocument doc = JsonDocument::Load(path);
    const nlohmann::json& raw = doc.raw();
    if (raw.is_object() && raw.contains("schema_version") &&
        raw["schema_version"] == kChecksVersion && raw.contains("stages") &&
        raw["stages"].is_object())
      return raw["stages"];
    if (warn) LogWarning(path, ": not a checks.json of version ", kChecksVersion, "; replaced");
  } catch (const Error& e) {
    if (warn) LogWarning(e.what(), "; replaced");
  }
  return nlohmann::json::object();
}

// `object[key]` when it is a string, else "" (a hand-edited report is still printed).
std::string Text(const nlohmann::json& object, const char* key) {
  const auto it = object.find(key);
  return it != object.end() && it->is_string() ? it->get<std::string>() : "";
}

}  // namespace

const char* CheckOutcomeName(CheckOutcome outcome) {
  switch (outcome) {
    case CheckOutcome::kPassed:
      return "passed";
    case CheckOutcome::kWarning:
      return "warning";
    case CheckOutcome::kFailed:
      return "failed";
  }
  return "?";
}

CheckLog::CheckLog(std::string dataset_dir, std::string stage)
    : dir_(std::move(dataset_dir)), stage_(std::move(stage)) {
  // A stage killed while saving leaves its checks.json temporary in the dataset folder; a rerun
  // that has nothing to redo would not write checks.json again, so the orphan goes here (only
  // those of processes that no longer run).
  if (!dir_.empty() && std::filesystem::is_directory(dir_)) RemoveOrphanedTemporaries(dir_);
}

void CheckLog::Pass(const std::string& check, const std::string& message, nlohmann::json values) {
  LogDebug(check, ": ", message);
  records_.push_back({check, CheckOutcome::kPassed, message, std::move(values)});
}

void CheckLog::Warn(const std::string& check, const std::string& message, nlohmann::json values) {
  LogWarning(message, " [", check, "]");
  records_.push_back({check, CheckOutcome::kWarning, message, std::move(values)});
}

void CheckLog::Fail(const std::string& check, const std::string& message, nlohmann::json values) {
  records_.push_back({check, CheckOutcome::kFailed, message, std::move(values)});
  try {
    Save();
  } catch (const Error& e) {  // the failure itself is what the user must see
    LogWarning(e.what());
  }
  throw BadInput(message + " [" + check + "]");
}

int CheckLog::warnings() const {
  int n = 0;
  for (const auto& r : records_) n += r.outcome == CheckOutcome::kWarning;
  return n;
}

void CheckLog::Save() const {
  if (dir_.empty()) return;
  const std::string path = dir_ + "/" + kChecksFile;
  CheckOutputPath(path);
  const FolderLock lock(dir_);
  nlohmann::json stages = ReadStages(path, true);
  nlohmann::json list = nlohmann::json::array();
  for (const auto& r : records_)
    list.push_back({{"check", r.check},
                    {"outcome", CheckOutcomeName(r.outcome)},
                    {"message", r.message},
                    {"values", r.values}});
  stages[stage_] = {{"time", NowUtc("%Y-%m-%dT%H:%M:%SZ")}, {"checks", list}};
  WriteJsonAtomically(path, {{"schema_version", kChecksVersion}, {"stages", stages}});
}

std::string FormatCheckReport(const std::string& dataset_dir) {
  const std::string path = dataset_dir + "/" + kChecksFile;
  const nlohmann::json stages = ReadStages(path, false);
  if (stages.empty()) return "";
  std::ostringstream out;
  int passed = 0, warned = 0, failed = 0;
  for (const auto& [stage, entry] : stages.items()) {
    if (!entry.is_object() || !entry.contains("checks") || !entry["checks"].is_array()) continue;
    int stage_passed = 0;
    std::ostringstream lines;
    for (const auto& c : entry["checks"]) {
      if (!c.is_object()) continue;
      const std::string outcome = Text(c, "outcome");
      if (outcome == "passed") {
        ++stage_passed, ++passed;
        continue;
      }
      (outcome == "failed" ? failed : warned)++;
      lines << "  " << outcome << "  " << Text(c, "check") << ": " << Text(c, "message") << "\n";
    }
    out << stage << ": " << stage_passed << " passed\n" << lines.str();
  }
  out << "checks: " << passed << " passed, " << warned << " warnings, " << failed << " failed ("
      << path << ")\n";
  return out.str();
}

}  // namespace lumislab
