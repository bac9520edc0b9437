// Masks of eight lanes (0 or -1 per lane, what vector comparisons return) as bits.
#ifndef FH_MASKS_H
#define FH_MASKS_H

#include "types.h"

// The eight lanes OR-ed together.
FH_INLINE int or_lanes(int8 x) {
  const int4 a = x.lo | x.hi;
  const int2 b = a.lo | a.hi;
  return b.x | b.y;
}

#ifdef __AVX__
// Clang's x86 vector types, which the x86 built-ins take (OpenCL's float8 and int8 convert
// to them by a cast of the same bits).
typedef float fh_v8sf __attribute__((vector_size(32)));
typedef int fh_v8si __attribute__((vector_size(32)));
#endif

// Bit i set where lane i of `lanes` has its sign bit set (as any() and all() read masks).
// On x86 this is one instruction (vmovmskps, or a move of the comparison's mask register)
// where the portable OR of the lanes is a chain of shuffles in front of every branch on a mask.
FH_INLINE uint lane_bits(int8 lanes) {
#ifdef __AVX__
  return (uint)__builtin_ia32_movmskps256((fh_v8sf)as_float8(lanes));
#else
  return (uint)or_lanes((lanes >> 31) & (int8)(1, 2, 4, 8, 16, 32, 64, 128));
#endif
}

// any() and all() for masks. PoCL's built-ins test the lanes one by one, each with a branch.
FH_INLINE bool any_lane(int8 lanes) { return lane_bits(lanes) != 0u; }
FH_INLINE bool all_lanes(int8 lanes) { return lane_bits(lanes) == 0xffu; }

#endif
