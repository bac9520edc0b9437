// Progress on stderr: a redrawn bar (samples, elapsed, estimated remaining, Msamples/s)
// when stderr is a terminal, a plain line every 10 % when it is not.
#pragma once
#include <cstdint>

namespace fh {

class Progress {
 public:
  explicit Progress(bool enabled);
  // total == 0: unknown (a time budget), then `fraction` of the budget is shown.
  void update(uint64_t samples, uint64_t total, double seconds, double fraction);
  // Ends the display without a total (a process whose share of a render is done while
  // others still render: the command's summary gives the whole render's).
  void end();
  void finish(uint64_t samples, double seconds);

 private:
  bool enabled_, terminal_;
  int lastDecile_ = -1;
};

}  // namespace fh
