// The signal handlers: async-signal-safe, they only store a number or exit.
#include "cli/interrupt.h"

#include <csignal>
#include <unistd.h>

namespace fh {
namespace {

std::atomic<int> stopSignal{0};
static_assert(std::atomic<int>::is_always_lock_free, "the flag is set from a signal handler");

extern "C" void onSignal(int signal) {
  if (stopSignal.exchange(signal) != 0 && signal == SIGINT) _exit(128 + SIGINT);  // the second Ctrl-C
}

}  // namespace

const std::atomic<int>& installInterruptHandlers() {
  struct sigaction action = {};
  action.sa_handler = onSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  return stopSignal;
}

}  // namespace fh
