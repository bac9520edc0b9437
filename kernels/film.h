// The sensor side of the measurement equation: sub-pixel sample positions and the pixel
// filter. Filters are importance-sampled (not splatted): a separable filter's 1D inverse
// CDF is tabulated on the host, so each sample lands in its pixel with weight one.
#ifndef FH_FILM_H
#define FH_FILM_H

#include "types.h"

#include "rng.h"

// The R2 low-discrepancy sequence (Roberts 2018), rotated per pixel (Cranley-Patterson),
// so a pixel's successive samples cover its footprint evenly.
FH_INLINE float2 pixel_sample_2d(uint seed, uint pixel, uint pass) {
  const float2 rotation = (float2)(random_float(seed, pixel, 0xF11E0u), random_float(seed, pixel, 0xF11E1u));
  const float2 alpha = (float2)(0.75487766624669276f, 0.56984029099805327f);
  const float2 x = rotation + (float)(pass + 1) * alpha;
  return x - floor(x);
}

// Offset from the pixel centre for u in [0,1), from the filter's inverse CDF table.
FH_INLINE float filter_offset(__global const float* table, uint size, float u) {
  const float x = u * (float)(size - 1);
  const uint i = min((uint)x, size - 2);
  return mix(table[i], table[i + 1], x - (float)i);
}

#endif
