// The signal handlers: async-signal-safe, they only store a number, or remove the temporary
// files and exit.
#include "cli/interrupt.h"

#include <csignal>
#include <unistd.h>

#include "base/atomic_file.h"

namespace fh {
namespace {

std::atomic<int> stopSignal{0};
static_assert(std::atomic<int>::is_always_lock_free, "the flag is set from a signal handler");

extern "C" void onSignal(int signal) {
  if (stopSignal.exchange(signal) != 0 && signal == SIGINT) {  // the second Ctrl-C
    removeTemporariesNow();
    _exit(128 + SIGINT);
  }
}

}  // namespace

const std::atomic<int>& installInterruptHandlers() {
  struct sigaction action = {};
  action.sa_handler = onSignal;
  sigemptyset(&action.sa_mask);
  // SIGHUP: the terminal went away (a dropped SSH session); the render is kept as for SIGTERM.
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) sigaction(signal, &action, nullptr);
  return stopSignal;
}

}  // namespace fh
