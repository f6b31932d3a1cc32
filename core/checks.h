// The consistency checks a stage makes of its inputs, and the dataset's record of them,
// <dataset>/checks.json (docs/formats.md, "checks.json"; the list a lab reads is docs/verifies.md).
//
// A check that passes is recorded; one that finds something a lab could legitimately mean is a
// warning (on stderr and recorded); one that finds an inconsistency no capture can mean is a
// failure: recorded, then thrown as bad input (exit 2). Each stage's records replace that stage's
// previous ones, so the file holds the outcome of the latest run of every stage.
//
//   CheckLog checks(dataset.dir, "calibrate dark");
//   if (level > 0.25) checks.Fail("dark.is_dark", file, "a dark level ...", values);
//   checks.Pass("dark.is_dark", "mean level 0.2 % of full scale", values);
//   checks.Save();  // at the end of the stage (Fail saves before it throws)
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lumislab {

enum class CheckOutcome { kPassed, kWarning, kFailed };
const char* CheckOutcomeName(CheckOutcome outcome);  // "passed", "warning", "failed"

struct CheckRecord {
  std::string check;  // a stable id, "<area>.<what>", e.g. "response.exposure_order"
  CheckOutcome outcome = CheckOutcome::kPassed;
  std::string message;    // what was found, naming the files concerned
  nlohmann::json values;  // the numbers measured and the limits they were held to
};

class CheckLog {
 public:
  // `dataset_dir` empty: the checks are logged, not recorded (a stage run on a bare slab).
  CheckLog(std::string dataset_dir, std::string stage);

  void Pass(const std::string& check, const std::string& message,
            nlohmann::json values = nlohmann::json::object());
  // Logged as a warning (prefixed with the check's id) and recorded.
  void Warn(const std::string& check, const std::string& message,
            nlohmann::json values = nlohmann::json::object());
  // Recorded and saved, then thrown as BadInput (exit 2) with `message`, which must name the file
  // and field (docs/architecture.md §7).
  [[noreturn]] void Fail(const std::string& check, const std::string& message,
                         nlohmann::json values = nlohmann::json::object());

  const std::vector<CheckRecord>& records() const { return records_; }
  int warnings() const;
  // Replaces this stage's records in <dataset_dir>/checks.json (atomically, under an advisory
  // lock on the folder, so stages running side by side keep each other's records). An unreadable
  // or foreign checks.json is replaced, with a warning: the record is a report, not an input.
  void Save() const;

 private:
  std::string dir_, stage_;
  std::vector<CheckRecord> records_;
};

// <dataset_dir>/checks.json as a short table for a person, one line per check that did not pass
// and a count of those that did, per stage; "" when the file does not exist.
std::string FormatCheckReport(const std::string& dataset_dir);

}  // namespace lumislab
