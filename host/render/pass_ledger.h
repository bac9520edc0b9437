// The render's pass numbers when several processes share one render (host/distributed):
// each process's pool takes new passes from the ledger instead of counting them itself,
// so every pass is handed out once over all processes.
#pragma once
#include <cstdint>

namespace fh {

class PassLedger {
 public:
  virtual ~PassLedger() = default;
  // The next pass for this process; false once none is left for it (all handed out, or
  // the time budget spent). Called under the pool's lock, one call at a time.
  virtual bool next(uint32_t& pass) = 0;
  // This process merged a pass into its film (for the progress shown where the render
  // started). Called by the pool's merger thread, one call at a time.
  virtual void finished(uint32_t pass) { (void)pass; }
  // Passes other processes have finished so far, as far as this one knows.
  virtual uint64_t finishedElsewhere() const { return 0; }
};

}  // namespace fh
