// Film files, as --resume reads a checkpoint (the fingerprint a render would expect is taken
// from the input's own header, else nothing past it is reached) and as fredholm merge reads
// a chunk: any file must load to a consistent film with a finite image, or throw fh::Error.
// Each input is read as it is (its checksums almost never hold, so that is the checksums'
// test) and resealed (render/checkpoint.h: its checksums made to hold, so that mutations
// reach the checks behind them).
#include <cmath>
#include <string>

#include "base/error.h"
#include "fuzz_support.h"
#include "render/checkpoint.h"

namespace {
// Each pixel's count: the film's pass count, or in an adaptive film (its round's pixels
// listed) a whole number up to it.
bool countsAddUp(const fh::Film& film) {
  for (size_t p = 0; p < film.pixels(); ++p) {
    const double n = film.count(p), passes = double(film.passes());
    if (film.roundPixels ? !(n >= 0 && n <= passes && n == double(uint64_t(n))) : n != passes) return false;
  }
  return true;
}

bool finite(const fh::Image& image) {
  for (float v : image.rgb)
    if (!std::isfinite(v)) return false;
  return true;
}

void readFilmFile(const std::string& bytes) {
  const size_t space = bytes.find(' ');
  const std::string fingerprint = space == std::string::npos ? "" : bytes.substr(space + 1, 16);
  const std::string path =
      fh::fuzz::writeScratch("checkpoint.fhc", reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  try {
    const fh::Film film = fh::loadCheckpoint(path, fingerprint, "--resume");
    if (film.sum.size() != 4 * film.pixels() || !countsAddUp(film)) __builtin_trap();
    if (!finite(film.image())) __builtin_trap();
    film.estimatedRelMse();
  } catch (const fh::Error&) {
  }
  try {
    const fh::SavedFilm saved = fh::readFilm(path, "merge");
    if (!countsAddUp(saved.film) || !finite(saved.film.image())) __builtin_trap();
    fh::Film twice = saved.film;
    bool refused = false;
    try {
      twice.merge(saved.film);  // a film shares every pass with itself
    } catch (const fh::Error&) {
      refused = true;
    }
    if (refused != (saved.film.passes() > 0)) __builtin_trap();
    twice.image();
  } catch (const fh::Error&) {
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  readFilmFile(bytes);
  const std::string resealed = fh::resealFilm(bytes);
  if (resealed != bytes) readFilmFile(resealed);
  return 0;
}
