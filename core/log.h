// Minimal leveled logging to stderr, thread-safe, with the tool name as prefix.
#pragma once

#include <sstream>
#include <string>

namespace lumislab {

enum class LogLevel { kDebug = 0, kInfo = 1, kWarning = 2, kError = 3 };

void SetLogLevel(LogLevel level);
void SetLogTool(const std::string& tool);  // prefix, e.g. "reconstruct"
LogLevel GetLogLevel();
void LogMessage(LogLevel level, const std::string& message);

namespace internal {
inline void Append(std::ostringstream&) {}
template <typename T, typename... Rest>
void Append(std::ostringstream& os, const T& v, const Rest&... rest) {
  os << v;
  Append(os, rest...);
}
}  // namespace internal

// A number for a message: %g with `digits` significant digits ("0.0123", "1.5e+04").
std::string Num(double v, int digits = 4);

// The longest head of `text` of at most `max_bytes` bytes that ends before a UTF-8 continuation
// byte (10xxxxxx), so that a field cut to a width splits no character.
std::string Utf8Head(const std::string& text, size_t max_bytes);

// The current time in UTC through strftime's `format` ("%Y-%m-%dT%H:%M:%SZ").
std::string NowUtc(const char* format);

template <typename... Args>
void Log(LogLevel level, const Args&... args) {
  if (level < GetLogLevel()) return;
  std::ostringstream os;
  internal::Append(os, args...);
  LogMessage(level, os.str());
}
template <typename... Args>
void LogInfo(const Args&... args) {
  Log(LogLevel::kInfo, args...);
}
template <typename... Args>
void LogWarning(const Args&... args) {
  Log(LogLevel::kWarning, args...);
}
template <typename... Args>
void LogDebug(const Args&... args) {
  Log(LogLevel::kDebug, args...);
}

}  // namespace lumislab
