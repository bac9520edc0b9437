// Counter-based random numbers: a hash of (pixel, sample, dimension) so any sample can
// be regenerated independently of execution order (deterministic for a given seed).
// Lane-wise (lanes.h): each lane hashes its own numbers.
#ifndef FH_RNG_H
#define FH_RNG_H

#include "lanes.h"

// PCG-style 32-bit hash (a good avalanche for small, structured inputs).
FH_INLINE luint hash_u32(luint x) {
  const luint state = x * 747796405u + 2891336453u;
  const luint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

FH_INLINE luint hash_combine(luint a, luint b) { return hash_u32(a ^ (b + 0x9e3779b9u + (a << 6) + (a >> 2))); }

// A float in [0, 1) from the top 24 bits.
FH_INLINE lfloat u32_to_unit_float(luint x) { return lconvert_float(x >> 8) * (1.0f / 16777216.0f); }

// Independent uniform numbers per (seed, stream, dimension), for the bench's ray batches
// and the debug views; the path tracer draws its decisions from sampler.h.
FH_INLINE lfloat random_float(luint seed, luint stream, luint dimension) {
  return u32_to_unit_float(hash_combine(hash_combine(seed, stream), dimension));
}

#endif
