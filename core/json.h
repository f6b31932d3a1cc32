// The one JSON validator: typed access by field path, errors naming file, field, expected, got.
//   JsonDocument doc = JsonDocument::Load("ds/dataset.json");
//   int nu = doc.root()["setup"]["grid"]["nu"].IntAtLeast(1);
//   -> "ds/dataset.json: setup.grid.nu: expected integer >= 1, got -3" (exit 2)
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lumislab {

class JsonView {
 public:
  JsonView(const nlohmann::json* value, std::shared_ptr<const std::string> file, std::string path)
      : value_(value), file_(std::move(file)), path_(std::move(path)) {}

  JsonView operator[](const std::string& key) const;  // required member
  JsonView operator[](size_t index) const;            // required array element
  bool Has(const std::string& key) const;
  bool IsNull() const { return value_ == nullptr || value_->is_null(); }
  size_t Size() const;                    // array size (fails if not an array)
  std::vector<std::string> Keys() const;  // object keys (fails if not an object)

  double Number() const;  // finite number
  double NumberIn(double lo, double hi) const;
  double Positive() const;  // > 0
  int Int() const;
  int IntAtLeast(int lo) const;
  int IntIn(int lo, int hi) const;
  bool Bool() const;
  std::string String() const;
  std::string OneOf(const std::vector<std::string>& allowed) const;
  std::vector<double> Numbers(size_t expected_size = 0) const;  // 0: any length >= 1

  // Optional members with defaults.
  double NumberOr(const std::string& key, double fallback) const;
  int IntOr(const std::string& key, int fallback) const;
  std::string StringOr(const std::string& key, const std::string& fallback) const;
  bool BoolOr(const std::string& key, bool fallback) const;

  [[noreturn]] void Fail(const std::string& expected) const;  // throws InputError
  const std::string& path() const { return path_; }
  const std::string& file() const { return *file_; }
  const nlohmann::json& raw() const { return *value_; }

 private:
  const nlohmann::json* value_;
  std::shared_ptr<const std::string> file_;
  std::string path_;
};

// Every JSON input is refused (bad input naming the file) past these limits, before it is parsed:
// lumislab's files are a few KB and a few levels deep.
constexpr size_t kMaxJsonBytes = 16 << 20;
constexpr int kMaxJsonDepth = 64;

class JsonDocument {
 public:
  // A missing file, a folder, FIFO or device, too large or too deep: bad input (exit 2) naming
  // the file. Not valid JSON: bad input with the line and column.
  static JsonDocument Load(const std::string& path);
  static JsonDocument Parse(const std::string& text, const std::string& name);
  JsonView root() const { return JsonView(json_.get(), file_, ""); }
  const std::string& file() const { return *file_; }
  const nlohmann::json& raw() const { return *json_; }
  // Checks "schema_version" is present and <= max_supported.
  void CheckSchemaVersion(int max_supported) const;

 private:
  std::shared_ptr<nlohmann::json> json_;
  std::shared_ptr<const std::string> file_;
};

// value.dump(2) for `file`. JSON holds only UTF-8 text: a string that is not (a file name in
// Latin-1, say) is exit 2 naming `file`, the field and the value with its odd bytes as \xHH,
// rather than the JSON library's own exception (exit 1); it is not replaced, since a path with
// U+FFFD in it would name another file.
std::string DumpJson(const nlohmann::json& value, const std::string& file);
// Pretty JSON (DumpJson) written atomically.
void WriteJsonAtomically(const std::string& path, const nlohmann::json& value);

}  // namespace lumislab
