// Progress on stderr: a redrawn bar (samples, elapsed, estimated remaining, Msamples/s)
// when stderr is a terminal, a plain line every 10 % when it is not. Rates are the devices'
// after their first pass (render/pass_pool.h), which builds the kernels: counted from program
// start, a small render's rate would mostly measure the compiler.
#pragma once
#include <cstdint>

namespace fh {

class Progress {
 public:
  explicit Progress(bool enabled);
  // total == 0: unknown (a time budget), then `fraction` of the budget is shown. rate:
  // samples a second after the first pass; 0: not known yet.
  void update(uint64_t samples, uint64_t total, double seconds, double fraction, double rate);
  // Ends the display without a total (a process whose share of a render is done while
  // others still render: the command's summary gives the whole render's).
  void end();
  // firstPass: seconds until the first pass finished; rate 0: no device finished two passes.
  void finish(uint64_t samples, double seconds, double rate, double firstPass);

 private:
  bool enabled_, terminal_;
  int lastDecile_ = -1;
};

}  // namespace fh
