#pragma once
// Errors that reach the user. Bad input (a file, a measurement, a pattern) is the user's: it is
// reported as an InputError naming the file and what is wrong, and the CLI exits with status 2.
#include <stdexcept>
#include <string>

namespace drape {

// Exit statuses of the command line (DESIGN.md contract).
enum ExitStatus : int {
  kExitOk = 0,
  kExitFailure = 1,       // a bug or an environment problem (disk full, ...)
  kExitBadInput = 2,      // bad input: one line on stderr naming the file, nothing written
  kExitQualityGate = 3,   // the simulation ran but failed its quality gates; outputs written
};

class InputError : public std::runtime_error {
 public:
  // `source` names the file (or the option, e.g. "--measurements") the problem is in.
  InputError(std::string source, const std::string& what)
      : std::runtime_error(source + ": " + what), source_(std::move(source)) {}
  const std::string& source() const noexcept { return source_; }

 private:
  std::string source_;
};

}  // namespace drape
