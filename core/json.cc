#include "core/json.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"

namespace lumislab {
namespace {
// What a value is, for messages: scalars and small flat containers as written, anything else by
// size (dumping a nested container would recurse through whatever a hostile file holds).
std::string Got(const nlohmann::json* value) {
  if (value == nullptr) return "nothing (missing)";
  if (value->is_structured()) {
    bool flat = value->size() <= 8;
    for (const auto& element : *value) flat = flat && element.is_primitive();
    if (!flat)
      return (value->is_object() ? "an object of " : "an array of ") +
             std::to_string(value->size()) + " value(s)";
  }
  std::string text = value->dump();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

// Deepest nesting of arrays and objects in `text` (strings skipped), stopping once past `limit`.
int NestingDepth(const std::string& text, int limit) {
  int depth = 0, deepest = 0;
  bool in_string = false;
  for (size_t k = 0; k < text.size(); ++k) {
    const char c = text[k];
    if (in_string) {
      if (c == '\\')
        ++k;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > limit) break;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}
std::string FormatNumber(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}
}  // namespace

JsonView JsonView::operator[](const std::string& key) const {
  const std::string child = path_.empty() ? key : path_ + "." + key;
  if (value_ == nullptr || !value_->is_object()) Fail("an object with member \"" + key + "\"");
  auto it = value_->find(key);
  if (it == value_->end()) {
    throw InputError(*file_, child, "a value", "nothing (missing)");
  }
  return JsonView(&*it, file_, child);
}

JsonView JsonView::operator[](size_t index) const {
  if (value_ == nullptr || !value_->is_array()) Fail("an array");
  const std::string child = path_ + "[" + std::to_string(index) + "]";
  if (index >= value_->size()) throw InputError(*file_, child, "a value", "nothing (missing)");
  return JsonView(&(*value_)[index], file_, child);
}

bool JsonView::Has(const std::string& key) const {
  return value_ != nullptr && value_->is_object() && value_->contains(key) &&
         !(*value_)[key].is_null();
}

size_t JsonView::Size() const {
  if (value_ == nullptr || !value_->is_array()) Fail("an array");
  return value_->size();
}

std::vector<std::string> JsonView::Keys() const {
  if (value_ == nullptr || !value_->is_object()) Fail("an object");
  std::vector<std::string> keys;
  for (auto it = value_->begin(); it != value_->end(); ++it) keys.push_back(it.key());
  return keys;
}

double JsonView::Number() const {
  if (value_ == nullptr || !value_->is_number()) Fail("number");
  const double v = value_->get<double>();
  if (!std::isfinite(v)) Fail("finite number");
  return v;
}

double JsonView::NumberIn(double lo, double hi) const {
  const std::string expected = "number in [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]";
  if (value_ == nullptr || !value_->is_number()) Fail(expected);
  const double v = value_->get<double>();
  if (!std::isfinite(v) || v < lo || v > hi) Fail(expected);
  return v;
}

double JsonView::Positive() const {
  const double v = Number();
  if (!(v > 0)) Fail("number > 0");
  return v;
}

int JsonView::Int() const {
  if (value_ == nullptr || !value_->is_number_integer()) Fail("integer");
  const auto v = value_->get<long long>();
  if (v < -2147483647LL || v > 2147483647LL) Fail("integer of 32 bits");
  return int(v);
}

int JsonView::IntAtLeast(int lo) const {
  if (value_ == nullptr || !value_->is_number_integer()) Fail("integer >= " + std::to_string(lo));
  const auto v = value_->get<long long>();
  if (v < lo || v > 2147483647LL) Fail("integer >= " + std::to_string(lo));
  return int(v);
}

int JsonView::IntIn(int lo, int hi) const {
  const std::string range = "integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (value_ == nullptr || !value_->is_number_integer()) Fail(range);
  const auto v = value_->get<long long>();
  if (v < lo || v > hi) Fail(range);
  return int(v);
}

bool JsonView::Bool() const {
  if (value_ == nullptr || !value_->is_boolean()) Fail("true or false");
  return value_->get<bool>();
}

std::string JsonView::String() const {
  if (value_ == nullptr || !value_->is_string()) Fail("string");
  return value_->get<std::string>();
}

std::string JsonView::OneOf(const std::vector<std::string>& allowed) const {
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : "|") + a;
  if (value_ == nullptr || !value_->is_string()) Fail("one of " + list);
  const std::string v = value_->get<std::string>();
  for (const auto& a : allowed)
    if (a == v) return v;
  Fail("one of " + list);
}

std::vector<double> JsonView::Numbers(size_t expected_size) const {
  const std::string what = expected_size ? "array of " + std::to_string(expected_size) + " numbers"
                                         : "non-empty array of numbers";
  if (value_ == nullptr || !value_->is_array()) Fail(what);
  if (expected_size ? value_->size() != expected_size : value_->empty()) Fail(what);
  std::vector<double> out;
  for (size_t k = 0; k < value_->size(); ++k) out.push_back((*this)[k].Number());
  return out;
}

double JsonView::NumberOr(const std::string& key, double fallback) const {
  return Has(key) ? (*this)[key].Number() : fallback;
}
int JsonView::IntOr(const std::string& key, int fallback) const {
  return Has(key) ? (*this)[key].Int() : fallback;
}
std::string JsonView::StringOr(const std::string& key, const std::string& fallback) const {
  return Has(key) ? (*this)[key].String() : fallback;
}
bool JsonView::BoolOr(const std::string& key, bool fallback) const {
  return Has(key) ? (*this)[key].Bool() : fallback;
}

void JsonView::Fail(const std::string& expected) const {
  throw InputError(*file_, path_.empty() ? "(top level)" : path_, expected, Got(value_));
}

JsonDocument JsonDocument::Load(const std::string& path) {
  CheckInputFile(path, "JSON file");
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxJsonBytes)
    throw InputError(path, "", "a JSON file of at most " + std::to_string(kMaxJsonBytes) + " bytes",
                     std::to_string(size) + " bytes");
  return Parse(ReadTextFile(path), path);
}

JsonDocument JsonDocument::Parse(const std::string& text, const std::string& name) {
  if (text.size() > kMaxJsonBytes)
    throw InputError(name, "", "a JSON text of at most " + std::to_string(kMaxJsonBytes) + " bytes",
                     std::to_string(text.size()) + " bytes");
  if (NestingDepth(text, kMaxJsonDepth) > kMaxJsonDepth)
    throw InputError(name, "",
                     "arrays and objects nested at most " + std::to_string(kMaxJsonDepth) + " deep",
                     "deeper nesting");
  JsonDocument doc;
  doc.file_ = std::make_shared<const std::string>(name);
  try {
    doc.json_ = std::make_shared<nlohmann::json>(nlohmann::json::parse(text));
  } catch (const nlohmann::json::exception& e) {  // parse errors, number overflow (1e999)
    // e.what() is "[json.exception.parse_error.101] parse error at line L, column C: ...":
    // keep the part a person reads.
    std::string what = e.what();
    const size_t at = what.find("] ");
    if (what.rfind("[json.exception", 0) == 0 && at != std::string::npos)
      what = what.substr(at + 2);
    throw BadInput(name + ": not valid JSON: " + what);
  }
  return doc;
}

void JsonDocument::CheckSchemaVersion(int max_supported) const {
  const int v = root()["schema_version"].IntAtLeast(1);
  if (v > max_supported)
    throw InputError(
        *file_, "schema_version",
        "schema_version <= " + std::to_string(max_supported) + " (written by a newer lumislab?)",
        std::to_string(v));
}

namespace {
bool IsUtf8(const std::string& s) {
  try {
    (void)nlohmann::json(s).dump();
    return true;
  } catch (const nlohmann::json::type_error&) {
    return false;
  }
}

// The string with bytes outside printable ASCII as \xHH.
std::string Printable(const std::string& s) {
  std::string out;
  for (const unsigned char ch : s) {
    if (ch >= 0x20 && ch < 0x7f) {
      out += char(ch);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", ch);
      out += hex;
    }
  }
  return out;
}

// The first string (member name or value) under `value` that is not UTF-8: throws naming it.
void CheckUtf8(const nlohmann::json& value, const std::string& field, const std::string& file) {
  const auto fail = [&](const std::string& where, const std::string& text) {
    throw InputError(file, where.empty() ? "(the document)" : where,
                     "UTF-8 text (JSON holds nothing else: rename the file or folder, e.g. with "
                     "convmv -f latin1 -t utf8)",
                     "\"" + Printable(text) + "\"");
  };
  if (value.is_string()) {
    if (!IsUtf8(value.get_ref<const std::string&>())) fail(field, value.get<std::string>());
  } else if (value.is_object()) {
    for (auto it = value.begin(); it != value.end(); ++it) {
      const std::string member = field.empty() ? it.key() : field + "." + it.key();
      if (!IsUtf8(it.key())) fail(field.empty() ? "a member name" : field, it.key());
      CheckUtf8(it.value(), member, file);
    }
  } else if (value.is_array()) {
    for (size_t k = 0; k < value.size(); ++k)
      CheckUtf8(value[k], field + "[" + std::to_string(k) + "]", file);
  }
}
}  // namespace

std::string DumpJson(const nlohmann::json& value, const std::string& file) {
  try {
    return value.dump(2);
  } catch (const nlohmann::json::type_error& e) {
    if (e.id != 316) throw;
    CheckUtf8(value, "", file);
    throw;  // not found again: the library's own message
  }
}

void WriteJsonAtomically(const std::string& path, const nlohmann::json& value) {
  WriteTextAtomically(path, DumpJson(value, path) + "\n");
}

}  // namespace lumislab
