#include "lib/photometry/ies.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/log.h"

namespace lumislab {

const char* const kIesRequiredKeywords[4] = {"TEST", "TESTLAB", "ISSUEDATE", "MANUFAC"};

namespace {

constexpr int kMaxIesAngles = 100000;  // far above any real file; bounds memory on hostile input
constexpr double kFeetToMm = 304.8;

std::vector<std::string> SplitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::string line;
  std::istringstream in(text);
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  return lines;
}

std::string Trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

// The numbers after the TILT line, each with its line number, read in order; errors name the
// file, the line and the field being read.
class Numbers {
 public:
  Numbers(const std::vector<std::string>& lines, size_t first_line, std::string name)
      : name_(std::move(name)) {
    for (size_t l = first_line; l < lines.size(); ++l) {
      std::string token;
      for (char ch : lines[l] + " ") {
        if (std::isspace(static_cast<unsigned char>(ch)) || ch == ',') {
          if (!token.empty()) tokens_.push_back({token, int(l + 1)});
          token.clear();
        } else {
          token += ch;
        }
      }
    }
  }
  double Next(const std::string& field) {
    if (next_ >= tokens_.size())
      throw BadInput(name_ + ": " + field + ": the file ends before it (truncated, or fewer " +
                     "values than the header's counts)");
    const Token& t = tokens_[next_++];
    char* end = nullptr;
    const double v = std::strtod(t.text.c_str(), &end);
    if (end == t.text.c_str() || *end != '\0' || !std::isfinite(v))
      throw BadInput(name_ + ": line " + std::to_string(t.line) + ": " + field +
                     ": expected a finite number, got \"" + t.text.substr(0, 40) + "\"");
    return v;
  }
  int NextInt(const std::string& field, int lo, int hi) {
    const int line = Line();
    const double v = Next(field);
    if (v != std::floor(v) || v < lo || v > hi)
      throw BadInput(name_ + ": line " + std::to_string(line) + ": " + field +
                     ": expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                     "], got " + Num(v, 8));
    return int(v);
  }
  double NextPositive(const std::string& field) {
    const int line = Line();
    const double v = Next(field);
    if (!(v > 0))
      throw BadInput(name_ + ": line " + std::to_string(line) + ": " + field +
                     ": expected a number > 0, got " + Num(v, 8));
    return v;
  }
  int Line() const { return next_ < tokens_.size() ? tokens_[next_].line : -1; }
  std::string Text() const { return next_ < tokens_.size() ? tokens_[next_].text : ""; }
  size_t Left() const { return tokens_.size() - next_; }

 private:
  struct Token {
    std::string text;
    int line;
  };
  std::vector<Token> tokens_;
  size_t next_ = 0;
  std::string name_;
};

}  // namespace

IntensityDistribution ParseIes(const std::string& text, const std::string& name) {
  if (text.find('\0') != std::string::npos)
    throw BadInput(name + ": not an IES file (binary content)");
  const std::vector<std::string> lines = SplitLines(text);
  IntensityDistribution d;
  // Edition: the first line names it from 1991 on; a 1986 file starts with its text lines.
  size_t l = 0;
  bool old_factor = true;  // 1995 and older: line 11's second value is a photometric factor
  d.format = "IES LM-63-1986";
  if (!lines.empty()) {
    const std::string first = Trim(lines[0]);
    if (first.rfind("IES", 0) == 0) {
      const size_t colon = first.find(':');
      d.format = first == "IESNA91"           ? "IES LM-63-1991"
                 : colon == std::string::npos ? "IES " + first
                                              : "IES " + first.substr(colon + 1);
      old_factor =
          first.find("2002") == std::string::npos && first.find("2019") == std::string::npos;
      l = 1;
    }
  }
  // Keywords up to the TILT line; [MORE] continues the keyword before it.
  for (; l < lines.size(); ++l) {
    const std::string line = Trim(lines[l]);
    if (line.rfind("TILT", 0) == 0) break;
    if (line.empty()) continue;
    if (line[0] == '[' && line.find(']') != std::string::npos) {
      const size_t close = line.find(']');
      const std::string key = line.substr(1, close - 1);
      const std::string value = Trim(line.substr(close + 1));
      if (key == "MORE" && !d.keywords.empty())
        d.keywords.back().second += "\n" + value;
      else
        d.keywords.push_back({key, value});
    } else {
      d.keywords.push_back({"", line});  // 1986 files: free text
    }
  }
  if (l >= lines.size())
    throw BadInput(name + ": no TILT= line (not an IES LM-63 file, or cut short before its data)");
  const std::string tilt_line = Trim(lines[l]);
  const size_t eq = tilt_line.find('=');
  const std::string tilt = eq == std::string::npos ? "" : Trim(tilt_line.substr(eq + 1));
  if (tilt != "NONE" && tilt != "INCLUDE")
    throw BadInput(name + ": line " + std::to_string(l + 1) + ": TILT=" + tilt.substr(0, 60) +
                   ": tilt data in another file is not read (TILT=NONE or TILT=INCLUDE only)");
  Numbers in(lines, l + 1, name);
  if (tilt == "INCLUDE") {
    // Lamp-to-luminaire geometry, then the pairs of tilt angle and multiplying factor. Read and
    // recorded; not applied, since they describe the lamp at other mounting tilts.
    const int geometry = in.NextInt("TILT=INCLUDE lamp-to-luminaire geometry", 1, 3);
    const int pairs = in.NextInt("TILT=INCLUDE number of angle/factor pairs", 1, kMaxIesAngles);
    std::ostringstream os;
    os << "INCLUDE geometry " << geometry << ", " << pairs << " pairs:";
    std::vector<double> angles(pairs);
    for (int k = 0; k < pairs; ++k)
      angles[k] = in.Next("TILT=INCLUDE angle " + std::to_string(k + 1));
    for (int k = 0; k < pairs; ++k) {
      const double f = in.Next("TILT=INCLUDE factor " + std::to_string(k + 1));
      os << " " << Num(angles[k], 6) << ":" << Num(f, 6);
    }
    d.keywords.push_back({"TILT", os.str()});
  }
  const int lamps = in.NextInt("number of lamps", 1, 1000000);
  const double lumens = in.Next("lumens per lamp");
  const double multiplier = in.NextPositive("candela multiplier");
  const int n_vertical = in.NextInt("number of vertical angles", 1, kMaxIesAngles);
  const int n_horizontal = in.NextInt("number of horizontal angles", 1, kMaxIesAngles);
  const int line_type = in.Line();
  const int type = in.NextInt("photometric type", 1, 3);
  if (type != 1)
    throw BadInput(name + ": line " + std::to_string(line_type) + ": photometric type " +
                   (type == 2 ? "B" : "A") + " is not read (type C only)");
  const int units = in.NextInt("units type (1 feet, 2 metres)", 1, 2);
  const double to_mm = units == 1 ? kFeetToMm : 1000.0;
  d.opening.width_mm = in.Next("luminous width") * to_mm;
  d.opening.length_mm = in.Next("luminous length") * to_mm;
  d.opening.height_mm = in.Next("luminous height") * to_mm;
  const double ballast = in.NextPositive("ballast factor");
  // 2002's "future use" and 2019's file generation type: kept as written (2019's is a code).
  if (!old_factor) d.file_generation_type = in.Text();
  const double second =
      in.Next(old_factor ? "ballast-lamp photometric factor" : "future use / file generation type");
  d.input_watts = in.Next("input watts");
  const double factor = multiplier * ballast * (old_factor && second > 0 ? second : 1.0);
  // The counts must fit the numbers the file holds before anything is sized by them.
  const size_t needed = size_t(n_vertical) + n_horizontal + size_t(n_vertical) * n_horizontal;
  if (needed > in.Left())
    throw BadInput(name + ": line " + std::to_string(line_type) + ": " +
                   std::to_string(n_vertical) + " vertical x " + std::to_string(n_horizontal) +
                   " horizontal angles need " + std::to_string(needed) +
                   " numbers after this line, the file has " + std::to_string(in.Left()) +
                   " (truncated, or wrong counts)");
  d.gamma_deg.resize(n_vertical);
  for (int k = 0; k < n_vertical; ++k)
    d.gamma_deg[k] = in.Next("vertical angle " + std::to_string(k + 1));
  d.c_deg.resize(n_horizontal);
  for (int k = 0; k < n_horizontal; ++k)
    d.c_deg[k] = in.Next("horizontal angle " + std::to_string(k + 1));
  d.values.resize(size_t(n_vertical) * n_horizontal);
  for (int h = 0; h < n_horizontal; ++h)
    for (int v = 0; v < n_vertical; ++v)
      d.values[size_t(h) * n_vertical + v] =
          in.Next("candela value " + std::to_string(v + 1) + " of horizontal angle " +
                  std::to_string(h + 1)) *
          factor;
  if (in.Left() > 0)
    throw BadInput(name + ": line " + std::to_string(in.Line()) + ": " + std::to_string(in.Left()) +
                   " number(s) after the last candela value (the " +
                   "counts on the line of the number of angles do not match the data)");
  const std::string units_keyword = d.Keyword("_UNITS");
  d.photometric = units_keyword.rfind("W/sr", 0) != 0;
  d.lamps = std::to_string(lamps) + " x " +
            (lumens < 0 ? std::string("absolute photometry") : Num(lumens, 8) + " lm");
  d.Check(name);
  return d;
}

IntensityDistribution ReadIes(const std::string& path) {
  CheckInputFile(path, "IES file");
  return ParseIes(ReadTextFile(path), path);
}

namespace {

// Numbers on lines of at most 10 values (LM-63-2019 limits lines to 256 characters).
void WriteNumbers(std::ostringstream& os, const std::vector<double>& v, int digits) {
  for (size_t k = 0; k < v.size(); ++k) {
    os << Num(v[k], digits) << ((k + 1) % 10 == 0 || k + 1 == v.size() ? "\n" : " ");
  }
}

bool IsKeywordName(const std::string& key) {
  if (key.empty()) return false;
  for (char ch : key)
    if (!(std::isupper(static_cast<unsigned char>(ch)) ||
          std::isdigit(static_cast<unsigned char>(ch)) || ch == '_'))
      return false;
  return true;
}

// Bytes of `s` from `at` to take for a line of at most `max` bytes: up to and with the last
// space when there is one in its second half (a reader joining the lines with a line break, as
// ParseIes does, keeps words whole), else ending before a UTF-8 continuation byte (10xxxxxx) so
// that no character is split; at least one character.
size_t Utf8Prefix(const std::string& s, size_t at, size_t max) {
  if (s.size() - at <= max) return s.size() - at;
  const size_t space = s.rfind(' ', at + max - 1);
  if (space != std::string::npos && space >= at + max / 2) return space + 1 - at;
  size_t n = max;
  while (n > 1 && (static_cast<unsigned char>(s[at + n]) & 0xC0) == 0x80) --n;
  return n;
}

}  // namespace

void CheckIesRequiredKeywords(const std::vector<std::pair<std::string, std::string>>& keywords,
                              const std::string& name) {
  for (const char* key : kIesRequiredKeywords) {
    bool found = false;
    for (const auto& [k, value] : keywords) found = found || (k == key && !Trim(value).empty());
    if (!found)
      throw InputError(name, std::string("[") + key + "]",
                       "a value (LM-63-2019 requires it: give it as a flag or in the metadata)",
                       "nothing (missing)");
  }
}

std::string FileGenerationType::Code() const {
  if (simulation) return "1.00010";
  std::string code = "1.";
  for (bool digit : {accredited, interpolated, lumen_scaled, false, false})
    code += digit ? '1' : '0';
  return code;
}

std::string FileGenerationTypeName(const std::string& code) {
  if (code == "1.00001") return "undefined";
  if (code == "1.00010") return "computer simulation";
  const bool table = code.size() == 7 && code.compare(0, 2, "1.") == 0 &&
                     code.find_first_not_of("01", 2) == std::string::npos &&
                     code.compare(5, 2, "00") == 0;
  if (!table) return "not in LM-63-2019's table";
  std::string name = code[2] == '1' ? "test at an accredited lab" : "test at an unaccredited lab";
  if (code[3] == '1') name += ", interpolated angle set";
  if (code[4] == '1') name += ", lumen scaled";
  return name;
}

std::string FormatIes(const IntensityDistribution& d, const IesWriteOptions& options,
                      const std::string& name) {
  d.Check(name);
  std::ostringstream os;
  os << "IES:LM-63-2019\n";
  // A keyword's lines of over 240 bytes go on in [MORE] lines (LM-63-2019 limits a line to 256
  // characters), cut between UTF-8 characters: no text is lost and no character is split.
  auto write_keyword = [&](const std::string& key, const std::string& value) {
    std::istringstream lines(value);
    std::string line;
    bool first = true;
    while (std::getline(lines, line)) {
      size_t at = 0;
      do {
        const size_t n = Utf8Prefix(line, at, 240);
        os << "[" << (first ? key : "MORE") << "] " << line.substr(at, n) << "\n";
        first = false;
        at += n;
      } while (at < line.size());
    }
  };
  CheckIesRequiredKeywords(d.keywords, name);
  for (const char* key : kIesRequiredKeywords) write_keyword(key, d.Keyword(key));
  for (const auto& [key, value] : d.keywords) {
    bool required = false;
    for (const char* r : kIesRequiredKeywords) required = required || key == r;
    if (required || key == "_UNITS" || key == "TILT" || !IsKeywordName(key) || Trim(value).empty())
      continue;
    write_keyword(key, value);
  }
  if (!d.photometric) write_keyword("_UNITS", "W/sr (radiometric: the values are W/sr, not cd)");
  os << "TILT=NONE\n";
  os << "1 -1 1 " << d.gamma_deg.size() << " " << d.c_deg.size() << " 1 2 "
     << Num(d.opening.width_mm / 1000, 6) << " " << Num(d.opening.length_mm / 1000, 6) << " "
     << Num(d.opening.height_mm / 1000, 6) << "\n";
  os << "1 " << options.file_generation_type << " " << Num(d.input_watts, 6) << "\n";
  // Angles with 15 digits: what was read is written back (Check wants them 1e-6 deg apart).
  WriteNumbers(os, d.gamma_deg, 15);
  WriteNumbers(os, d.c_deg, 15);
  for (size_t ic = 0; ic < d.c_deg.size(); ++ic)
    WriteNumbers(os,
                 std::vector<double>(d.values.begin() + ic * d.gamma_deg.size(),
                                     d.values.begin() + (ic + 1) * d.gamma_deg.size()),
                 7);
  // Lines end in CR LF, as LM-63 asks of every line (ParseIes reads LF and CR LF alike).
  std::string text;
  for (char ch : os.str()) {
    if (ch == '\r') continue;  // a keyword value's own CR: the line ends below
    if (ch == '\n') text += '\r';
    text += ch;
  }
  return text;
}

void WriteIes(const IntensityDistribution& d, const std::string& path,
              const IesWriteOptions& options) {
  WriteTextAtomically(path, FormatIes(d, options, path));
}

}  // namespace lumislab
