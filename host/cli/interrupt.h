// Ctrl-C, kill and a dropped terminal during a render: the first SIGINT, SIGTERM or SIGHUP
// asks the render to stop (it keeps the passes finished so far, which are written); a second
// SIGINT exits at once, removing the temporary files of writes in flight.
#pragma once
#include <atomic>

namespace fh {

// Installs the handlers; returns the flag they set to the signal's number.
const std::atomic<int>& installInterruptHandlers();

}  // namespace fh
