// The one exception type fredholm throws for user-facing failures: its message is a
// complete, one-line explanation (file/line/flag where there is one).
#pragma once
#include <stdexcept>
#include <string>

namespace fh {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// A failure whose cause lies in an OpenCL call; carries the CL error code so callers
// can tell "out of memory" from the rest.
class ClError : public Error {
 public:
  ClError(const std::string& message, int code) : Error(message), code_(code) {}
  int code() const { return code_; }

 private:
  int code_;
};

// A kernel program that failed to compile; the message holds the device's build log.
class BuildError : public Error {
 public:
  using Error::Error;
};

// The user stopped the program (SIGINT, SIGTERM): main reports it and exits with
// 128 + the signal's number, as a shell does for a process the signal killed.
class Interrupted : public Error {
 public:
  Interrupted(const std::string& what, int signal) : Error(what), signal_(signal) {}
  int exitCode() const { return 128 + signal_; }

 private:
  int signal_;
};

}  // namespace fh
