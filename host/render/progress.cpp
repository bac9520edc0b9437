// The progress display.
#include "render/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace fh {

Progress::Progress(bool enabled) : enabled_(enabled), terminal_(isatty(STDERR_FILENO) != 0) {}

void Progress::update(uint64_t samples, uint64_t total, double seconds, double fraction, double samplesPerSecond) {
  if (!enabled_) return;
  if (total > 0) fraction = double(samples) / double(total);
  const double rate = samplesPerSecond * 1e-6;
  const double remaining = total > 0 && samplesPerSecond > 0.0 ? double(total - std::min(total, samples)) / samplesPerSecond
                           : fraction > 0.0                     ? seconds * (1.0 - fraction) / fraction
                                                                : 0.0;
  if (terminal_) {
    const int width = 30, filled = int(fraction * width + 0.5);
    std::fprintf(stderr, "\r[%s%s] %5.1f%%  %llu samples  %.1fs elapsed  %.1fs left  %.2f Msamples/s ",
                 std::string(size_t(filled), '#').c_str(), std::string(size_t(width - filled), '.').c_str(),
                 100.0 * fraction, static_cast<unsigned long long>(samples), seconds, remaining, rate);
    std::fflush(stderr);
    return;
  }
  const int decile = int(fraction * 10.0);
  if (decile == lastDecile_) return;
  lastDecile_ = decile;
  std::fprintf(stderr, "fredholm: %3d%%  %llu samples  %.1fs elapsed  %.1fs left  %.2f Msamples/s\n", decile * 10,
               static_cast<unsigned long long>(samples), seconds, remaining, rate);
}

void Progress::end() {
  if (enabled_ && terminal_) std::fputc('\n', stderr);
}

void Progress::finish(uint64_t samples, double seconds, double rate, double firstPass) {
  if (!enabled_) return;
  if (terminal_) std::fputc('\n', stderr);
  const auto n = static_cast<unsigned long long>(samples);
  if (n == 0)
    std::fprintf(stderr, "fredholm: no samples rendered\n");
  else if (rate > 0.0)
    std::fprintf(stderr, "fredholm: %llu samples in %.2fs: %.2f Msamples/s after the first pass (the first, with any "
                 "kernel builds, took %.2fs)\n", n, seconds, rate * 1e-6, firstPass);
  else
    std::fprintf(stderr, "fredholm: %llu samples in %.2fs (one pass a device: no rate "
                 "apart from the first pass's kernel builds)\n", n, seconds);
}

}  // namespace fh
