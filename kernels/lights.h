// Light sampling for next-event estimation: an emissive triangle chosen in proportion
// to its power (a CDF over the light list), then a uniform point on it. The area
// formulation: the estimate Le f G V / p_area, with p_area = P(triangle) / area.
#ifndef FH_LIGHTS_H
#define FH_LIGHTS_H

#include "types.h"

// The first light whose CDF value exceeds u (binary search).
FH_INLINE uint pick_light(__global const float* cdf, uint count, float u) {
  uint lo = 0, hi = count - 1;
  while (lo < hi) {
    const uint mid = (lo + hi) / 2;
    if (cdf[mid] > u) hi = mid;
    else lo = mid + 1;
  }
  return lo;
}

// Converts an area density at a point seen at distance^2 `dist2` under cosine `cos_light`
// to a solid-angle density at the receiver.
FH_INLINE float area_to_solid_angle(float pdf_area, float dist2, float cos_light) {
  return cos_light > 0.0f ? pdf_area * dist2 / cos_light : 0.0f;
}

// The power heuristic (beta = 2) weight of a sample drawn with density `a` against `b`.
FH_INLINE float power_heuristic(float a, float b) {
  const float a2 = a * a, b2 = b * b;
  return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

#endif
