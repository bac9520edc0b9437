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
};

}  // namespace fh
