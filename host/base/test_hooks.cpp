// The test hooks' parsing: each variable once, from the environment, checked whole.
#include "base/test_hooks.h"

#include <cerrno>
#include <cstdlib>

#include "base/error.h"

namespace fh {
namespace {

// Where an unset or empty variable leaves its hook as it is.
const char* variable(const char* name) {
  const char* value = std::getenv(name);
  return value && *value ? value : nullptr;
}

[[noreturn]] void malformed(const char* name, const std::string& value, const char* expected) {
  throw Error(std::string(name) + "='" + value + "': expected " + expected + " (a test hook, base/test_hooks.h)");
}

// A whole number >= 0 that is all of `text`, else -1.
long wholeNumber(const std::string& text) {
  if (text.empty() || text[0] < '0' || text[0] > '9') return -1;
  char* end = nullptr;
  errno = 0;
  const long n = std::strtol(text.c_str(), &end, 10);
  return *end == '\0' && errno == 0 ? n : -1;
}

TestHooks fromEnvironment() {
  TestHooks hooks;
  if (const char* kill = variable("FREDHOLM_KILL_AFTER_PASSES")) {
    hooks.killAfterPasses = wholeNumber(kill);
    if (hooks.killAfterPasses < 0) malformed("FREDHOLM_KILL_AFTER_PASSES", kill, "a pass count N");
  }
  if (const char* fail = variable("FREDHOLM_FAIL_DEVICE")) {
    const std::string spec(fail);
    const auto colon = spec.find(':');
    const long device = colon == std::string::npos ? -1 : wholeNumber(spec.substr(0, colon));
    const long after = colon == std::string::npos ? -1 : wholeNumber(spec.substr(colon + 1));
    if (device < 0 || device > 1 << 20 || after < 0)
      malformed("FREDHOLM_FAIL_DEVICE", spec, "I:N, a device index and the passes it finishes");
    hooks.failDevice = {int(device), after};
  }
  if (const char* slow = variable("FREDHOLM_SLOW_RANK")) {
    const long rank = wholeNumber(slow);
    if (rank < 0 || rank > 1 << 20) malformed("FREDHOLM_SLOW_RANK", slow, "an MPI rank R");
    hooks.slowRank = int(rank);
  }
  if (const char* strategy = variable("FREDHOLM_TEST_STRATEGY")) hooks.testStrategy = strategy;
  return hooks;
}

TestHooks& hooks() {
  static TestHooks current = fromEnvironment();
  return current;
}

}  // namespace

const TestHooks& testHooks() { return hooks(); }

ScopedTestHooks::ScopedTestHooks(const TestHooks& replacement) : saved_(hooks()) { hooks() = replacement; }

ScopedTestHooks::~ScopedTestHooks() { hooks() = saved_; }

}  // namespace fh
