// The sensor side of the measurement equation: the pixel filter. Filters are
// importance-sampled (not splatted): a separable filter's 1D inverse CDF is tabulated on
// the host, so each sample lands in its pixel with weight one. The sub-pixel position that
// picks the offset is the pixel sampler's dimension FH_DIM_PIXEL (sampler.h).
#ifndef FH_FILM_H
#define FH_FILM_H

#include "lanes.h"

// Offset from the pixel centre for u in [0,1), from the filter's inverse CDF table.
FH_INLINE lfloat filter_offset(__global const float* table, uint size, lfloat u) {
  const lfloat x = u * (float)(size - 1);
  const luint i = min(lconvert_uint(x), (luint)(size - 2));
  return mix(gather_float(table, i), gather_float(table, i + 1), x - lconvert_float(i));
}

#endif
