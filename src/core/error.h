#pragma once
// Errors that cross a module boundary. Each kind maps to one exit code of the `blurcue` executable,
// so scripts can tell a typo in a command line from a bad file from a failed computation.
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace blurcue {

enum class ErrorKind {
  kUsage = 2,     // bad command line
  kInput = 3,     // a file that cannot be read, parsed or validated
  kNotFound = 4,  // the data holds no answer (no board in the photo, too few usable sections)
  kDomain = 5,    // a model asked outside where it holds (u <= f, point nearer than focus in eq. 3.7)
  kInternal = 10, // a bug or an unexpected library failure
};

class Error : public std::runtime_error {
 public:
  Error(ErrorKind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  // Several problems at once (a protocol's, a display profile's), one line each; what() joins them with newlines.
  Error(ErrorKind kind, std::vector<std::string> lines)
      : std::runtime_error(Join(lines)), kind_(kind), lines_(std::move(lines)) {}
  ErrorKind kind() const { return kind_; }
  int exit_code() const { return static_cast<int>(kind_); }
  // The lines to print: what() for an ordinary error, each problem's own for a list. A newline inside one of them
  // came from a value it echoes, not from the list (main prints each line escaped, core/typed.h OneLine).
  std::vector<std::string> lines() const { return lines_.empty() ? std::vector<std::string>{what()} : lines_; }
  // The same error of `kind` with `prefix` before its first line and `after` (when not empty) as a last line: how a
  // caller says where it came from, or what to do, without joining a list into one line.
  Error Wrapped(ErrorKind kind, const std::string& prefix, const std::string& after = "") const {
    std::vector<std::string> all = lines();
    all.front() = prefix + all.front();
    if (!after.empty()) all.push_back(after);
    return Error(kind, std::move(all));
  }

 private:
  static std::string Join(const std::vector<std::string>& lines) {
    std::string text;
    for (const auto& line : lines) text += (text.empty() ? "" : "\n") + line;
    return text;
  }
  ErrorKind kind_;
  std::vector<std::string> lines_;
};

// A bad file or value: message is "where: what, got what".
inline Error InputError(const std::string& where, const std::string& what) {
  return Error(ErrorKind::kInput, where + ": " + what);
}

// A number as a message shows it: at most 6 significant digits, as printf's %g (2, 0.35, 1.5e+06, inf, nan).
inline std::string Num(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

}  // namespace blurcue
