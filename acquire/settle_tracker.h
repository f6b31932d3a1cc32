// Which files of a folder have finished arriving: a file is taken once its size and
// modification time have not changed for the settle time (`acquire watch`, and the folder:
// camera of `acquire capture`, which wait for what a tethering program writes).
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/input_file.h"

namespace lumislab {

// The folder's files (temporary names left out) and since when each has had its present size
// and modification time: a file whose copy is in progress keeps changing, so it settles only
// once the copy is done (or stalled for the settle time, when it is read and refused).
class SettleTracker {
 public:
  explicit SettleTracker(double settle_s) : settle_s_(settle_s) {}

  // Looks at the folder once; true when a file appeared, changed or went away.
  bool Scan(const std::string& dir) {
    const std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now();
    bool changed = false;
    std::map<std::string, State, NameOrder> seen;
    for (const std::string& name : FolderFiles(dir)) {
      std::error_code size_ec, time_ec;
      const auto size = std::filesystem::file_size(dir + "/" + name, size_ec);
      const auto time = std::filesystem::last_write_time(dir + "/" + name, time_ec);
      if (size_ec || time_ec) continue;  // gone since the listing: the next look tells
      State state{size, time, now};
      const auto it = files_.find(name);
      if (it != files_.end() && it->second.size == size && it->second.time == time)
        state.since = it->second.since;
      else
        changed = true;
      seen.emplace(name, state);
    }
    changed = changed || seen.size() != files_.size();
    files_ = std::move(seen);
    return changed;
  }
  // Whether the last look saw the file.
  bool Has(const std::string& name) const { return files_.count(name) > 0; }
  // Files in name order (NameOrderLess), with whether each has settled.
  std::vector<std::pair<std::string, bool>> Files() const {
    const std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now();
    std::vector<std::pair<std::string, bool>> out;
    for (const auto& [name, state] : files_)
      out.emplace_back(name, std::chrono::duration<double>(now - state.since).count() >= settle_s_);
    return out;
  }

 private:
  struct State {
    uintmax_t size;
    std::filesystem::file_time_type time;
    std::chrono::steady_clock::time_point since;  // when this size and time were first seen
  };
  double settle_s_;
  std::map<std::string, State, NameOrder> files_;
};

}  // namespace lumislab
