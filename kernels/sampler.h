// Per-pixel low-discrepancy samples for the path's random decisions.
//
// The samples of one pixel (its passes 0, 1, 2, ...) take their 2D decisions (sub-pixel
// position, BSDF direction, point on a light and the light's pick) from the Sobol' (0,2)-sequence in base 2 and
// their 1D ones (lobe, roulette) from the van der Corput sequence, so that any
// 2^k of them stratify their square or interval. Each pixel and each dimension pair gets its own random
// Owen scrambling (every point still uniform: the estimator stays unbiased) and its own
// shuffle of the sample order (so pairs of dimensions are not correlated with each other):
// Burley, "Practical Hash-based Owen Scrambling", JCGT 2020, with its Laine-Karras style
// hash (owen_hash below). Lane-wise (lanes.h): each lane is its own sample.
#ifndef FH_SAMPLER_H
#define FH_SAMPLER_H

#include "rng.h"

FH_INLINE luint reverse_bits_u32(luint x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}

// A keyed hash in which bit k of the result depends only on bits 0..k of x (additions and
// multiplications carry upward only). Applied to a number whose bits are digits in reverse
// order, it flips each digit by a function of the more significant digits: an Owen
// scrambling. (The Laine-Karras construction, with the constants of Burley 2020.)
FH_INLINE luint owen_hash(luint x, luint seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

// The second Sobol' dimension (primitive polynomial x + 1) with its digits in reverse
// order, i.e. reverse_bits(sobol(j)): its direction numbers are the rows of Pascal's
// triangle mod 2, so digit k is the XOR of the index bits m whose bit pattern contains k's
// (Lucas), a superset sum computed in five steps. (The first dimension, van der Corput,
// reversed, is the index itself.)
FH_INLINE luint sobol_second_dimension_reversed(luint j) {
  j ^= (j >> 1) & 0x55555555u;
  j ^= (j >> 2) & 0x33333333u;
  j ^= (j >> 4) & 0x0f0f0f0fu;
  j ^= (j >> 8) & 0x00ff00ffu;
  j ^= (j >> 16) & 0x0000ffffu;
  return j;
}

// One sample of one pixel: the pixel's scrambling seed and the sample's index in the pixel's
// sequence (its point) with the bits reversed, as the index shuffle takes it.
typedef struct {
  luint pixel_seed;
  luint index_reversed;
} PixelSampler;

// Point `point` of pixel `pixel`'s sequence. With replicates == 2 (a noise target:
// host/render/film.h), a pixel's even and odd points are two sequences under independent
// scramblings, each a net in its own right: the difference of their means is an unbiased
// estimate of the image's error, which the correlated points of one sequence do not give.
// replicates == 1: one sequence. (A point's parity is its pass's, by which the film sorts:
// sequence offsets are even.) The point and the pixel are taken apart, never as one sample
// number (point * pixels + pixel), so an image of any size has 2^32 points per pixel.
FH_INLINE PixelSampler pixel_sampler_at(uint seed, luint point, luint pixel, uint replicates) {
  PixelSampler s;
  const luint shift = (luint)(replicates - 1u);
  const luint replicate = point & shift;
  s.pixel_seed = hash_combine((luint)(seed) + replicate * 0x9e3779b9u, pixel);
  s.index_reversed = reverse_bits_u32(point >> shift);
  return s;
}

// The same for sample `sample_id` = point * pixel_count + pixel (below 2^32 samples: the
// sampler's tests number them so).
FH_INLINE PixelSampler pixel_sampler(uint seed, luint sample_id, uint pixel_count, uint replicates) {
  return pixel_sampler_at(seed, sample_id / pixel_count, sample_id % pixel_count, replicates);
}

// The index of this sample in dimension `dimension`'s own order: an Owen scrambling of the
// index, which maps every aligned block of 2^k indices onto another such block, so the first
// 2^k samples of a pixel stay a net in every dimension while the dimensions are decorrelated.
FH_INLINE luint shuffled_index(const PixelSampler* s, luint seed) {
  return reverse_bits_u32(owen_hash(s->index_reversed, seed));
}

// A digit-reversed coordinate, Owen-scrambled and put back in order, as a float in [0, 1).
FH_INLINE lfloat scrambled_unit(luint digits_reversed, luint seed) {
  return u32_to_unit_float(reverse_bits_u32(owen_hash(digits_reversed, seed)));
}

FH_INLINE lfloat sample_1d(const PixelSampler* s, luint dimension) {
  const luint seed = hash_combine(s->pixel_seed, dimension);
  return scrambled_unit(shuffled_index(s, seed), hash_u32(seed));
}

// Dimensions `dimension` and `dimension + 1` together.
FH_INLINE lvec2 sample_2d(const PixelSampler* s, luint dimension) {
  const luint seed = hash_combine(s->pixel_seed, dimension);
  const luint j = shuffled_index(s, seed);
  return lv2(scrambled_unit(j, hash_u32(seed)), scrambled_unit(sobol_second_dimension_reversed(j), hash_u32(seed + 1u)));
}

#endif
