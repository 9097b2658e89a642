#pragma once
// Errors that cross a module boundary. Each kind maps to one exit code of the `blurcue` executable,
// so scripts can tell a typo in a command line from a bad file from a failed computation.
#include <stdexcept>
#include <string>

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
  ErrorKind kind() const { return kind_; }
  int exit_code() const { return static_cast<int>(kind_); }

 private:
  ErrorKind kind_;
};

// A bad file or value: message is "where: what, got what".
inline Error InputError(const std::string& where, const std::string& what) {
  return Error(ErrorKind::kInput, where + ": " + what);
}

}  // namespace blurcue
